"""Helpers shared by the file formats: atomic writes, time columns, channel assembly."""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Channel, Record
from ..core import units as _units

# relative spread of time steps accepted as uniform sampling
TIME_STEP_RTOL = 1e-3
# the most samples (channels x samples) a file may declare before anything is allocated: 2 GB of
# float64; larger recordings are read with vm.open (streamed) or with a larger max_samples=
DEFAULT_MAX_SAMPLES = 250_000_000
MAX_CHANNELS = 10_000


def check_max_samples(max_samples) -> int:
    if isinstance(max_samples, bool) or not isinstance(max_samples, (int, np.integer)) or max_samples < 1:
        raise ParameterError(f"max_samples={max_samples!r} must be a positive integer")
    return int(max_samples)


def check_size(n_values, *, source: str, max_samples: int, what: str = "data"):
    """Refuse a declared size above the limit before it is allocated."""
    if n_values > max_samples:
        raise ParameterError(f"{source}: {what} declares {n_values:,} samples, above max_samples={max_samples:,} "
                             "(about 8 bytes each in memory); raise max_samples= if the machine has the memory, "
                             "or stream it with vm.open")


def real_samples(x, *, source: str):
    """Samples stored as complex with a zero imaginary part are real; any other complex data is refused
    (a time record cannot hold its imaginary part, and dropping it would be a silent wrong number)."""
    x = np.asarray(x)
    if np.iscomplexobj(x):
        if np.any(x.imag != 0):
            raise ParameterError(f"{source}: the samples are complex with a non-zero imaginary part; a record holds "
                                 "real samples (for FRFs use vm.read_frf)")
        return x.real
    return x


def parse_number(value, *, source: str, key: str) -> float:
    """A number stated in a file header ("10000", "1e4 Hz", "2048,5"), refusing what is ambiguous
    ("1,000": thousands separator or decimal comma?), booleans and text."""
    import re
    if isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{source}: {key} = {value!r} is a boolean, not a number")
    if isinstance(value, (int, float, np.integer, np.floating)):
        v = float(value)
    else:
        txt = str(value).strip().strip('"').strip("'")
        m = re.fullmatch(r"([-+]?[0-9][0-9.,]*(?:[eE][-+]?\d+)?)\s*(hz|s)?", txt, re.I)
        if not m:
            raise ParameterError(f"{source}: {key} = {value!r} is not a number")
        num = m.group(1)
        if "," in num:
            if "." in num or re.fullmatch(r"[-+]?\d{1,3}(,\d{3})+", num):
                raise ParameterError(f"{source}: {key} = {value!r} is ambiguous (thousands separator or decimal "
                                     "comma?): write it without separators, e.g. 1000 or 1000.5")
            num = num.replace(",", ".")
        try:
            v = float(num)
        except ValueError:
            raise ParameterError(f"{source}: {key} = {value!r} is not a number") from None
    if not np.isfinite(v):
        raise ParameterError(f"{source}: {key} = {value!r} is not finite")
    return v


def _check_target(path: Path) -> int | None:
    """The mode of the regular file the write will replace (None for a new file); refuses a folder,
    FIFO, device or socket at the output path, which a rename would silently replace."""
    import stat
    if not path.parent.exists():
        raise ParameterError(f"path={str(path)!r}: folder {str(path.parent)!r} does not exist")
    try:
        st = path.stat()
    except FileNotFoundError:
        return None
    if not stat.S_ISREG(st.st_mode):
        from ..core._validate import file_kind
        raise ParameterError(f"path={str(path)!r} is {file_kind(st.st_mode)}; the rule is: output goes to a regular "
                             "file (it is never replaced by one)")
    return stat.S_IMODE(st.st_mode)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _clean_stale(path: Path):
    """Remove the temporary files of writers of this path that were killed (their process is gone)."""
    for tmp in path.parent.glob(f".{path.name}.*.part"):
        parts = tmp.name[len(path.name) + 2:].split(".")
        if parts and parts[0].isdigit() and int(parts[0]) != os.getpid() and not _pid_alive(int(parts[0])):
            with contextlib.suppress(OSError):
                tmp.unlink()


def _fsync_dir(folder: Path):
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes, read in 4 MiB blocks (a regular file only: a FIFO or device never ends)."""
    import hashlib

    from ..core._validate import regular_input
    h = hashlib.sha256()
    with open(regular_input(path), "rb") as fh:
        for block in iter(lambda: fh.read(1 << 22), b""):
            h.update(block)
    return h.hexdigest()


@contextlib.contextmanager
def write_errors_not_signals():
    """While writing, a file-size limit makes write() fail with EFBIG (an OSError the caller names) instead
    of the default SIGXFSZ, which kills the process. Only the main thread may change a signal's handler."""
    import signal
    import threading
    if not hasattr(signal, "SIGXFSZ") or threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGXFSZ, old)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path``; it replaces ``path`` only if the block succeeds.

    Nothing is half-written: on any error the temporary file is removed and ``path`` is untouched.
    The data is flushed to disk (fsync) before the rename; a replaced file keeps its mode, a new one
    gets the process's usual mode (no process-wide umask change); temporary files left by a killed
    writer of the same path are removed. A folder, FIFO or device at ``path`` is refused.
    """
    path = Path(path)
    mode = _check_target(path)
    _clean_stale(path)
    fd, tmp = -1, ""
    for _ in range(100):
        tmp = str(path.parent / f".{path.name}.{os.getpid()}.{os.urandom(4).hex()}.part")
        try:  # the kernel applies the umask to 0o666, as for any new file
            fd = os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666 if mode is None else mode)
            break
        except FileExistsError:
            continue
        except OSError as exc:
            raise ParameterError(f"path={str(path)!r}: cannot write in {str(path.parent)!r} ({exc.strerror})") from None
    else:
        raise ParameterError(f"path={str(path)!r}: no free temporary name beside it")
    os.close(fd)
    try:
        yield Path(tmp)
        if mode is not None:
            os.chmod(tmp, mode)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
        _fsync_dir(path.parent)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def write_table(df, path: str | os.PathLike, units: dict) -> Path:
    """Write a results table as CSV whose header carries every column's unit: ``name [unit]``
    (``[-]`` for a ratio), text columns and counts (unit None) by name alone. ``units`` maps a column to its unit; a
    ``_hz``/``_deg``/``_s`` suffix is turned into the bracket (``freq_hz`` -> ``freq [Hz]``).
    Written atomically: never a half-written table."""
    suffix = {"_hz": "Hz", "_deg": "deg", "_s": "s"}
    names = {}
    for c in df.columns:
        if c in units:  # None: a count or label, no unit
            names[c] = c if units[c] is None else f"{c} [{units[c] or '-'}]"
            continue
        for end, u in suffix.items():
            if str(c).endswith(end):
                names[c] = f"{str(c)[:-len(end)]} [{u}]"
                break
        else:
            if df[c].dtype.kind in "fiuc":
                raise ParameterError(f"write_table: numeric column {c!r} has no unit; give it in units=")
            names[c] = c
    with atomic_path(path) as tmp:
        df.rename(columns=names).to_csv(tmp, index=False, float_format="%.10g")
    return Path(path)


def fs_from_time(t, *, source: str) -> tuple[float, float]:
    """Sampling rate and start time from a time column, refusing non-uniform sampling."""
    t = np.asarray(t, dtype=float).ravel()
    if t.size < 2:
        raise ParameterError(f"{source}: time column has {t.size} value(s); at least 2 are needed for fs")
    if not np.all(np.isfinite(t)):
        raise ParameterError(f"{source}: time column has NaN/inf values")
    d = np.diff(t)
    step = float(np.median(d))
    if step <= 0:
        raise ParameterError(f"{source}: time column does not increase (median step {step:g} s)")
    dev = float(np.max(np.abs(d - step)) / step)
    if dev > TIME_STEP_RTOL:
        i = int(np.argmax(np.abs(d - step)))
        raise ParameterError(
            f"{source}: time column is not uniformly sampled: step {d[i]:g} s at row {i + 1} differs from the "
            f"median step {step:g} s by {dev:.1%} (rule: within {TIME_STEP_RTOL:.1%}); resample it first")
    # least-squares step over the whole column: exact for a rounded but uniform time base
    n = np.arange(t.size)
    slope, icpt = np.polyfit(n, t, 1)
    return 1.0 / slope, float(icpt)


def require_fs(fs, *, source: str) -> float:
    if fs is None:
        raise ParameterError(f"{source} holds no timing information: fs (sampling rate in Hz) is required, "
                             f"e.g. vm.read(path, fs=10000) or --fs 10000")
    try:
        v = float(fs)
    except (TypeError, ValueError):
        raise ParameterError(f"fs={fs!r} must be a number in Hz") from None
    if not np.isfinite(v) or v <= 0:
        raise ParameterError(f"fs={fs!r} must be a finite sampling rate > 0 Hz")
    return v


def make_record(data, fs, names, *, quantity=None, unit=None, quantities=None, units=None, t0=0.0,
                meta=None, source="") -> Record:
    """Assemble a record; user-given quantity/unit override what the file says."""
    data = np.asarray(data)
    if np.iscomplexobj(data):
        raise ParameterError(f"{source}: the data are complex; a record holds real samples (the imaginary part "
                             "would be lost): read FRFs with vm.read_frf")
    data = np.asarray(data, dtype=np.float64)
    if data.ndim == 1:
        data = data[np.newaxis]
    if data.ndim != 2 or data.shape[1] < 2:
        raise ParameterError(f"{source}: holds {data.shape[-1] if data.ndim else 0} sample(s) per channel; a record "
                             "needs at least 2 (an empty or cut data block)")
    bad = ~np.isfinite(data)
    if bad.any():
        ch, i = np.unravel_index(int(np.argmax(bad)), data.shape)
        raise ParameterError(f"{source}: channel {str(names[ch])!r} has {int(bad.sum())} NaN/inf value(s) (first at "
                             f"sample {i}: {data[ch, i]!r}); the rule is finite samples (inf or overflowing numbers "
                             "such as 1e999 too): repair the file or cut the record")
    n = data.shape[0]
    quantities = list(quantities or ["unknown"] * n)
    units = list(units or [""] * n)
    chans = []
    for i, nm in enumerate(names):
        q, u = quantities[i], units[i]
        if unit is not None:
            u = unit
            if quantity is None and _units.normalize_unit(unit) != "":
                q = _units.quantity_of(unit)
        if quantity is not None:
            q = quantity
            if unit is None and u and _units.quantity_of(u) != quantity:
                u = ""
        if u and q == "unknown":
            q = _units.quantity_of(u)
        chans.append(Channel(str(nm), q, u))
    return Record(data, fs, tuple(chans), t0=t0, meta=meta or {}, history=(f"read {source}",))
