"""Files in and out: ``read`` and ``write`` choose the format by the file's ending (``read``, when the
ending names no format, by the file's content)."""

from __future__ import annotations

import os
import re
from pathlib import Path

from ..core._validate import regular_input
from ..core.errors import ParameterError, UnitError
from ..core.record import Record
from ._common import DEFAULT_MAX_SAMPLES, check_max_samples
from .csvfile import read_csv, write_csv
from .hdf5 import read_hdf5, write_hdf5
from .lazy import LazyRecord, open_record
from .lvm import read_lvm
from .mat import read_mat
from .uff import read_frf_uff, read_uff
from .wav import read_wav, write_wav

__all__ = ["read", "write", "open_record", "LazyRecord", "FORMATS", "read_frf", "read_spectrum"]

_READERS = {".csv": read_csv, ".txt": read_csv, ".tsv": read_csv, ".asc": read_csv, ".h5": read_hdf5, ".hdf5": read_hdf5,
            ".wav": read_wav, ".mat": read_mat, ".lvm": read_lvm, ".uff": read_uff, ".unv": read_uff}
_WRITERS = {".csv": write_csv, ".h5": write_hdf5, ".hdf5": write_hdf5, ".wav": write_wav}
FORMATS = tuple(sorted(_READERS))


def read(path: str | os.PathLike, *, fs: float | None = None, channels=None, quantity: str | None = None,
         unit: str | None = None, dataset: str | None = None, max_samples: int = DEFAULT_MAX_SAMPLES,
         allow_external: bool = False, delimiter: str | None = None) -> Record:
    """Read a measurement file into a :class:`Record`.

    The format follows the ending: .csv/.txt/.tsv/.asc, .h5/.hdf5, .wav, .mat (v5 and v7.3), .lvm, .uff/.unv;
    a file whose ending names none of them (the IMS rig's 2004.02.12.10.32.39) is recognised by its
    content (signature, or lines of delimited numbers). A damaged, truncated or contradictory file
    raises ParameterError naming the file and the rule (a CSV whose last line has no end of line drops
    that line with a QualityWarning); NaN, inf and complex data are refused.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    fs : float, optional
        Sampling rate in Hz: required when the file holds no timing, and must agree with it otherwise.
    channels : str, int or list, optional
        Columns or variables to read, by name (dotted paths for MATLAB structs, ``"name[i]"`` for one row
        of a matrix) or position; default all.
    quantity : str, optional
        "displacement", "velocity", "acceleration" or "force" when the file does not say.
    unit : str, optional
        The data's unit when the file does not say ("g", "m/s^2", "mm/s", "N", ...).
    dataset : str, optional
        A bare dataset in a foreign HDF5 file.
    max_samples : int
        Files declaring more values are refused before anything is allocated.
    allow_external : bool
        Accept HDF5 external storage and links that leave the file (refused by default: they can read
        any local file as samples).
    delimiter : {",", ";", "tab", "whitespace"}, optional
        The field separator of a text file (default: found from its lines: a tab, a semicolon or a
        comma where the lines hold one, else runs of whitespace, as loggers write .asc and .txt).

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For a missing, damaged, truncated, contradictory or oversized file, or a missing ``fs``.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.read("sample_data/ringdown_beam.csv")  # doctest: +SKIP
    >>> rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=2.0)
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "decay.csv"
    >>> _ = vm.write(path, rec)
    >>> vm.read(path).fs
    500.0
    """
    p = regular_input(path)
    ext = p.suffix.lower()
    if p.stat().st_size == 0:
        raise ParameterError(f"path={str(path)!r} is empty (0 bytes)")
    if ext not in _READERS:
        ext = _sniff(p)
        if ext is None:
            raise ParameterError(f"path={str(path)!r}: unknown file type {p.suffix.lower()!r} and its content is "
                                 f"none of the readable formats {FORMATS}")
    kw = dict(fs=fs, channels=channels, quantity=quantity, unit=unit, max_samples=check_max_samples(max_samples))
    if ext in (".h5", ".hdf5"):
        kw.update(dataset=dataset, allow_external=bool(allow_external))
    elif dataset is not None:
        raise ParameterError(f"dataset={dataset!r} applies to HDF5 files only, not {ext!r}")
    if delimiter is not None:
        from .csvfile import DELIMITERS
        if _READERS[ext] is not read_csv:
            raise ParameterError(f"delimiter={delimiter!r} applies to text files (.csv .txt .tsv .asc), not {ext!r}")
        if delimiter not in DELIMITERS:
            raise ParameterError(f"delimiter={delimiter!r} must be one of ',', ';', 'tab' or 'whitespace'")
        kw.update(delimiter=delimiter)
    return guarded(_READERS[ext], p, kind=ext, **kw)


def _sniff(p: Path) -> str | None:
    """The format of a file whose name does not say it (the IMS rig's files are named by their time
    stamp, 2004.02.12.10.32.39), from its first bytes: HDF5 (also MATLAB v7.3), MATLAB v5, WAV, LabVIEW
    text, Universal File Format, or delimited numbers as text."""
    with open(p, "rb") as fh:
        head = fh.read(4096)
    if head.startswith(b"MATLAB"):         # v5, and v7.3 (an HDF5 file behind a 512-byte MATLAB header)
        return ".mat"
    if any(head[k: k + 8] == b"\x89HDF\r\n\x1a\n" for k in (0, 512, 1024, 2048)):   # after a user block
        return ".h5"
    if head[:4] == b"RIFF" and head[8:12] == b"WAVE":
        return ".wav"
    if b"\x00" in head:
        return None
    text = head.decode("latin-1")
    if text.startswith("LabVIEW Measurement"):
        return ".lvm"
    lines = text.splitlines()
    if len(head) == 4096:
        lines = lines[:-1]   # the last may be cut by the 4 kB read
    lines = [ln for ln in lines if ln.strip()]
    if lines and lines[0].strip() == "-1" and any(ln.strip() in _UFF_SETS for ln in lines[1:3]):
        return ".uff"
    body = lines[1:] if lines and not _NUMBERS.match(lines[0]) else lines   # a header line is allowed
    if len(body) >= 2 and all(_NUMBERS.match(ln) for ln in body):
        return ".csv"
    return None


_UFF_SETS = ("58", "58b", "55", "151", "164")   # dataset numbers a Universal File opens with
_NUMBER = r"([-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?|[-+]?(nan|inf|infinity))"   # NaN: the reader names it
_NUMBERS = re.compile(rf"^[\s,;]*{_NUMBER}([\s,;]+{_NUMBER})*[\s,;]*$", re.I)   # a line of delimited numbers


def guarded(reader, path, kind=None, **kw):
    """Run a reader; any failure inside h5py, scipy.io, pyuff, pandas or numpy parsing becomes a
    ParameterError naming the file (a library's raw exception is never what the user sees)."""
    try:
        return reader(path, **kw)
    except (ParameterError, UnitError):
        raise
    except MemoryError:
        raise ParameterError(f"path={str(path)!r}: reading it needs more memory than is free; lower the data "
                             "(channels=...) or stream it with vm.open") from None
    except (ValueError, TypeError, KeyError, IndexError, ZeroDivisionError, UnboundLocalError, RecursionError,
            OSError, EOFError, AttributeError, OverflowError, UnicodeError, LookupError, RuntimeError) as exc:
        raise ParameterError(f"path={str(path)!r} is damaged or not a valid {kind or Path(path).suffix} file "
                             f"({type(exc).__name__}: {str(exc)[:200]})") from None


def write(path: str | os.PathLike, obj) -> Path:
    """Write a :class:`Record` to .csv, .h5/.hdf5 or .wav, atomically (never half-written).

    The file carries a SHA-256 of its content, so a later change of any byte is found when it is read.

    Parameters
    ----------
    path : str or os.PathLike
        The file; its ending chooses the format.
    obj : Record
        The record.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    ParameterError
        For an unknown ending, a folder that does not exist, or a folder, FIFO or device at the path.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=1.0)
    >>> vm.write(pathlib.Path(tempfile.mkdtemp()) / "decay.h5", rec).suffix
    '.h5'
    """
    if not isinstance(path, (str, os.PathLike)):
        hint = " (the order is vm.write(path, record))" if isinstance(obj, (str, os.PathLike)) else ""
        raise ParameterError(f"path must be a file name, got {type(path).__name__}{hint}")
    p = Path(path)
    ext = p.suffix.lower()
    if not isinstance(obj, Record):
        raise ParameterError(f"obj must be a vm.Record to write {ext!r}, got {type(obj).__name__}")
    if ext not in _WRITERS:
        raise ParameterError(f"path={str(path)!r}: cannot write {ext!r}; writable: {tuple(sorted(_WRITERS))}")
    _WRITERS[ext](p, obj)
    return p


def read_frf(path: str | os.PathLike, *, variable: str | None = None, fs: float | None = None):
    """Read frequency response functions from a file.

    UFF dataset 58 function type 4 (.uff/.unv), or a MATLAB variable holding a complex FRF with its
    frequency vector (the axis from a "Freq_domain"-like vector, or from ``fs`` and the line count).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    variable : str, optional
        The MATLAB variable holding the complex FRF (e.g. "Hf_chan_2").
    fs : float, optional
        Sampling rate in Hz, when a MATLAB file holds no frequency vector.

    Returns
    -------
    FRF

    Raises
    ------
    ParameterError
        For a file without FRFs, a damaged file or a missing frequency axis.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> frf = vm.read_frf("../shared/data/impact/case1.mat", variable="Hf_chan_2")  # doctest: +SKIP
    """
    p = regular_input(path)
    ext = p.suffix.lower()
    if ext in (".uff", ".unv"):
        return guarded(read_frf_uff, p)
    if ext == ".mat":
        from .mat import read_frf_mat
        return read_frf_mat(p, variable)
    raise ParameterError(f"path={str(path)!r}: FRFs are read from .uff/.unv or .mat, not {ext!r}")


def read_spectrum(path: str | os.PathLike):
    """Read a spectrum stored as text by LabVIEW (.lvm, X column in Hz).

    dB values (re 1 unit) become linear amplitudes.

    Parameters
    ----------
    path : str or os.PathLike
        The .lvm file of an FFT export.

    Returns
    -------
    Spectrum
        Of kind "amplitude".

    Raises
    ------
    ParameterError
        For a file that holds no spectrum, or a damaged one.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> spec = vm.read_spectrum("fft_export.lvm")  # doctest: +SKIP
    """
    from .lvm import read_lvm_spectrum
    p = regular_input(path)
    if p.suffix.lower() != ".lvm":
        raise ParameterError(f"path={str(path)!r}: spectra are read from LabVIEW .lvm exports, not {p.suffix!r}")
    return guarded(read_lvm_spectrum, p)
