"""Out-of-core records: a lazy view of an HDF5 dataset, read block by block.

``vm.open(path)`` returns a :class:`LazyRecord` over vibmeasure's own record schema, or over any
1-D or (n_channels, n_samples) dataset when ``dataset`` and ``fs`` are given. Spectral functions
stream it in blocks, so memory stays bounded however long the recording is.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..core._validate import regular_input
from ..core.errors import ParameterError
from ..core.record import Channel, Record
from ._common import parse_number, require_fs

__all__ = ["LazyRecord", "open_record"]


class LazyRecord:
    """A record whose samples stay on disk until a block of them is asked for (``vm.open``).

    It has what a :class:`~vibmeasure.Record` has except ``data``: fs, channels, t0, n_channels,
    n_samples, duration, names.

    Parameters
    ----------
    path : str or os.PathLike
        The HDF5 file.
    dataset : str
        The dataset holding the samples.
    fs : float
        Sampling rate in Hz.
    channels : tuple of Channel
        One per row.
    t0 : float
        Time of the first sample in s.
    meta : dict, optional
        What the file states besides.

    Raises
    ------
    ParameterError
        For a dataset that does not match the channels.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.h5"
    >>> _ = vm.write(path, vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=2.0))
    >>> lazy = vm.open(path)
    >>> lazy.n_samples, lazy.fs
    (1000, 500.0)
    """

    def __init__(self, path, dataset: str, fs: float, channels: tuple[Channel, ...], t0: float = 0.0,
                 meta: dict | None = None):
        self.path = Path(path)
        self.dataset = dataset
        self.fs = float(fs)
        self.channels = tuple(channels)
        self.t0 = float(t0)
        self.meta = dict(meta or {})
        with self._file() as f:
            d = f[dataset]
            self._shape = d.shape
            self.dtype = d.dtype
        self._one_d = len(self._shape) == 1

    def _file(self):
        import h5py
        try:
            return h5py.File(self.path, "r")
        except (OSError, ValueError) as exc:
            raise ParameterError(f"HDF5 file {str(self.path)!r} is unreadable: {exc}") from None

    @property
    def n_channels(self) -> int:
        return 1 if self._one_d else self._shape[0]

    @property
    def n_samples(self) -> int:
        return self._shape[-1]

    @property
    def duration(self) -> float:
        return self.n_samples / self.fs

    @property
    def names(self) -> list[str]:
        return [c.name for c in self.channels]

    def index(self, channel) -> int:
        """Index of a channel given by name or position.

        Parameters
        ----------
        channel : str or int
            Name or position.

        Returns
        -------
        int

        Raises
        ------
        ParameterError
            For an unknown channel.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.h5"
        >>> _ = vm.write(path, vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=2.0))
        >>> lazy = vm.open(path)
        >>> lazy.index(0)
        0
        """
        if isinstance(channel, (int, np.integer)) and not isinstance(channel, bool):
            if not -self.n_channels <= channel < self.n_channels:
                raise ParameterError(f"channel={channel} is out of range for {self.n_channels} channels")
            return int(channel) % self.n_channels
        if channel not in self.names:
            raise ParameterError(f"channel={channel!r} is not in this record; channels are {self.names}")
        return self.names.index(channel)

    def read(self, start: int, stop: int, out: np.ndarray | None = None) -> np.ndarray:
        """Samples start..stop of every channel as float64, shape (n_channels, stop - start).

        Parameters
        ----------
        start, stop : int
            Sample range.
        out : numpy.ndarray, optional
            A C-contiguous float64 array of exactly that shape, filled instead of a new one (no second
            copy, no fresh pages to fault in).

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For a range outside the record or an ``out`` of the wrong shape.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.h5"
        >>> _ = vm.write(path, vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=2.0))
        >>> lazy = vm.open(path)
        >>> lazy.read(0, 10).shape
        (1, 10)
        """
        start, stop = max(0, int(start)), min(self.n_samples, int(stop))
        shape = (self.n_channels, stop - start)
        if out is not None and (out.shape != shape or out.dtype != np.float64 or not out.flags.c_contiguous):
            raise ParameterError(f"out must be a C-contiguous float64 array of shape {shape}")
        with self._file() as f:
            d = f[self.dataset]
            try:
                if out is not None:
                    d.read_direct(out[0] if self._one_d else out, np.s_[start:stop] if self._one_d
                                  else np.s_[:, start:stop])
                    return out
                a = d[start:stop] if self._one_d else d[:, start:stop]
            except (OSError, ValueError, TypeError) as exc:
                raise ParameterError(f"{str(self.path)!r}: samples {start}..{stop} are unreadable "
                                     f"(truncated file?): {exc}") from None
        a = np.asarray(a, dtype=np.float64)
        return a[np.newaxis] if self._one_d else a

    def load(self) -> Record:
        """Read everything into an in-memory Record.

        Returns
        -------
        Record

        Raises
        ------
        ParameterError
            For a file changed or damaged since it was opened.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.h5"
        >>> _ = vm.write(path, vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=2.0))
        >>> lazy = vm.open(path)
        >>> lazy.load().data.shape
        (1, 1000)
        """
        return Record(self.read(0, self.n_samples), self.fs, self.channels, t0=self.t0, meta=self.meta,
                      history=(f"read {self.path} [{self.dataset}]",))

    def __repr__(self) -> str:
        return (f"LazyRecord({self.n_channels} ch x {self.n_samples} samples, fs={self.fs:g} Hz, "
                f"{self.dtype}, {str(self.path)!r}:{self.dataset})")


MAX_RATIO = 1000   # declared bytes over stored bytes: vibration data never compresses this far


def _check_stored(d, path):
    """A dataset must store what it declares: unwritten chunks read as zeros, forever, and a
    compression ratio beyond MAX_RATIO is a bomb, not a measurement."""
    declared = int(np.prod(d.shape, dtype=np.float64)) * d.dtype.itemsize
    stored = d.id.get_storage_size()
    if declared > (1 << 20) and stored * MAX_RATIO < declared:
        raise ParameterError(f"HDF5 file {str(path)!r}: dataset {d.name!r} declares {declared:,} bytes but stores "
                             f"{stored:,} (unwritten, or compressed more than {MAX_RATIO}x): refused")


def open_record(path: str | os.PathLike, *, dataset: str | None = None, fs: float | None = None,
                quantity: str | None = None, unit: str | None = None, progress=None) -> LazyRecord:
    """Open an HDF5 record lazily (out-of-core): samples are read block by block when analysed.

    A file in vibmeasure's schema needs nothing more; any other HDF5 file needs ``dataset`` (a 1-D or
    (n_channels, n_samples) dataset) and ``fs`` unless the dataset has an ``fs`` attribute. A file
    vibmeasure wrote is verified against its SHA-256 first (one streamed pass, about 1 s per GB).

    Parameters
    ----------
    path : str or os.PathLike
        The HDF5 file.
    dataset : str, optional
        The dataset of a foreign file.
    fs : float, optional
        Sampling rate in Hz when the file does not state it.
    quantity, unit : str, optional
        Labels for the data when the file does not give them.
    progress : callable, optional
        ``progress(fraction)`` follows the checksum pass.

    Returns
    -------
    LazyRecord

    Raises
    ------
    ParameterError
        For a missing, damaged or unreadable file, or a missing ``dataset`` or ``fs``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.h5"
    >>> _ = vm.write(path, vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=2.0))
    >>> vm.open(path).n_samples
    1000
    """
    from .hdf5 import SCHEMA, schema_header
    p = regular_input(path)
    src = f"HDF5 file {str(path)!r}"
    if p.suffix.lower() not in (".h5", ".hdf5"):
        raise ParameterError(f"path={str(path)!r}: vm.open reads HDF5 (.h5, .hdf5); use vm.read for {p.suffix!r}")
    import h5py
    from .hdf5 import check_seal
    check_seal(p, f"HDF5 file {str(path)!r}", progress)
    try:
        f = h5py.File(p, "r")
    except (OSError, ValueError) as exc:
        raise ParameterError(f"HDF5 file {str(path)!r} is unreadable (truncated or not HDF5): {exc}") from None
    with f:
        schema = f.attrs.get("vibmeasure_schema")
        schema = schema.decode() if isinstance(schema, bytes) else schema
        if dataset is None and schema == SCHEMA:
            d, chans, rfs, t0, meta, _ = schema_header(f, src, allow_external=False, max_samples=2 ** 62)
            _check_stored(d, p)
            if d.dtype.kind not in "fiu":
                raise ParameterError(f"{src}: data are {d.dtype}; a record streamed by vm.open holds real numbers "
                                     "(vm.read takes complex data whose imaginary part is zero)")
            if fs is not None and float(fs) != rfs:
                raise ParameterError(f"fs={fs} contradicts {str(path)!r}, which stores fs={rfs}")
            return LazyRecord(p, "data", rfs, chans, t0=t0, meta=meta)
        if dataset is None:
            raise ParameterError(f"{str(path)!r} is not a vibmeasure record file: name the dataset (dataset=...)")
        if dataset not in f:
            raise ParameterError(f"dataset={dataset!r} is not in {str(path)!r}")
        from .hdf5 import _dataset
        d = _dataset(f, dataset, f"HDF5 file {str(path)!r}", allow_external=False, max_samples=2 ** 62)
        _check_stored(d, p)
        if d.ndim not in (1, 2) or d.dtype.kind not in "fiu":
            raise ParameterError(f"dataset={dataset!r} must be 1-D or (n_channels, n_samples) numbers, "
                                 f"got shape {d.shape} dtype {d.dtype}")
        if (d.shape[-1] if d.ndim else 0) < 2:
            raise ParameterError(f"dataset={dataset!r} holds {d.shape[-1] if d.ndim else 0} samples; a record needs "
                                 "at least 2")
        attrs = [k for k in ("fs", "sampling_rate", "fs_hz") if k in d.attrs]
        attr_fs = parse_number(d.attrs[attrs[0]], source=src, key=f"attribute {attrs[0]}") if attrs else None
        fs = attr_fs if fs is None and attr_fs is not None else require_fs(fs, source=f"{str(path)!r}:{dataset}")
        n_ch = 1 if d.ndim == 1 else d.shape[0]
    from ..core import units as _units
    q = quantity or (_units.quantity_of(unit) if unit else "unknown")
    base = dataset.strip("/").replace("/", ".")
    names = [base] if n_ch == 1 else [f"{base}[{i}]" for i in range(n_ch)]
    chans = tuple(Channel(n, q, unit or "") for n in names)
    return LazyRecord(p, dataset, fs, chans, meta={"source": str(p), "dataset": dataset})
