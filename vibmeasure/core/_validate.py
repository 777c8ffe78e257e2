"""Boundary checks shared by the public functions (each error names the argument and the rule)."""

from __future__ import annotations

import numpy as np

from .errors import ParameterError
from .record import Record

__all__ = ["as_record", "response_channel", "clean_signal", "check_band", "positive", "name_index",
           "select_names", "check_range", "memory_guard", "check_memory", "as_seconds"]


def as_seconds(time, what: str = "time") -> float:
    """A time stamp as Unix seconds: a number, an ISO 8601 string, a datetime (naive = UTC) or a
    pandas/numpy time stamp."""
    import datetime as _dt
    if isinstance(time, (bool, np.bool_)):
        raise ParameterError(f"{what}={time!r} must be seconds or a datetime, not a boolean")
    if isinstance(time, str):
        try:
            time = _dt.datetime.fromisoformat(time.strip().replace("Z", "+00:00"))
        except ValueError:
            raise ParameterError(f"{what}={time!r} is not an ISO 8601 time") from None
    if isinstance(time, np.datetime64):
        time = time.astype("datetime64[ns]").astype("int64") / 1e9
    elif isinstance(time, _dt.datetime):  # pandas.Timestamp is a datetime too
        if time.tzinfo is None:
            time = time.replace(tzinfo=_dt.timezone.utc)
        time = time.timestamp()
    try:
        t = float(time)
    except (TypeError, ValueError):
        raise ParameterError(f"{what}={time!r} must be seconds, an ISO 8601 string or a datetime") from None
    if not np.isfinite(t):
        raise ParameterError(f"{what}={time!r} must be finite")
    return t


def available_memory() -> float:
    """Bytes this process can still allocate: the smaller of the system's available memory
    (MemAvailable) and the address-space limit (ulimit -v) less what is mapped already; inf
    when neither is known."""
    avail = np.inf
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    avail = float(line.split()[1]) * 1024
                    break
    except OSError:
        pass
    try:
        import resource
        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft not in (resource.RLIM_INFINITY, -1):
            with open("/proc/self/statm") as fh:
                mapped = float(fh.read().split()[0]) * resource.getpagesize()
            avail = min(avail, soft - mapped)
    except (OSError, ValueError, ImportError, IndexError):
        pass
    return avail


SMALL_WORK = 16 * 2 ** 20   # bytes


def check_memory(nbytes: float, what: str, n_samples: int) -> None:
    """Refuse, before allocating, work that needs more memory than the process can get, with the
    size needed and what to do. Below SMALL_WORK bytes the system is not asked: reading it costs more
    than such work, and an allocation that small failing is a MemoryError memory_guard names."""
    if nbytes < SMALL_WORK:
        return
    avail = available_memory()
    if nbytes > 0.9 * avail:
        raise ParameterError(f"{what}: {n_samples:,} samples need about {nbytes / 2**30:.1f} GiB of working memory, "
                             f"{max(avail, 0) / 2**30:.1f} GiB is available; cut the record (rec.slice_time) or "
                             "decimate it (vm.decimate) first")


def memory_guard(func):
    """A public function that runs out of memory says so, with the record's size, instead of a raw
    MemoryError from deep inside numpy."""
    import functools

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        try:
            return func(*args, **kwargs)
        except MemoryError:
            rec = args[0] if args else None
            n = getattr(rec, "n_samples", None)
            size = f" for {n:,} samples x {getattr(rec, 'n_channels', 1)} channel(s)" if n else ""
            raise ParameterError(f"{func.__name__}: not enough memory{size}; cut the record (slice_time, "
                                 "channels=...), decimate it, or stream it with vm.open and nperseg") from None
    return wrapper


# amplitudes whose squares (powers, spectra, likelihoods) stay inside double precision
RANGE = (1e-150, 1e150)


def check_range(data, *, what: str = "rec") -> None:
    """Refuse amplitudes whose powers overflow or underflow double precision (|x| above 1e150 or, when
    not all zero, below 1e-150): a spectrum of inf or 0 would be a silent wrong answer."""
    a = np.asarray(data)
    if a.size == 0 or a.dtype.kind not in "fc":
        return
    m = max(float(np.max(a.real)), -float(np.min(a.real))) if a.dtype.kind == "f" else float(np.max(np.abs(a)))
    if m > RANGE[1] or 0 < m < RANGE[0]:
        raise ParameterError(f"{what} peaks at {m:.3g}: outside {RANGE[0]:g}..{RANGE[1]:g}, where its power would "
                             "overflow or underflow double precision; rescale it (choose another unit)")


def as_record(obj, *, fs: float | None = None, name: str = "rec") -> Record:
    """Accept a Record, or an array together with ``fs``."""
    if isinstance(obj, Record):
        if fs is not None and float(fs) != obj.fs:
            raise ParameterError(f"{fs=} contradicts the record's fs={obj.fs}; drop fs or resample")
        return obj
    if isinstance(obj, (np.ndarray, list, tuple)):
        if fs is None:
            raise ParameterError(f"{name} is a bare array: fs (Hz) is required; or pass a vm.Record")
        return Record.from_array(np.asarray(obj), fs=fs)
    raise ParameterError(f"{name} must be a vm.Record or an array with fs, got {type(obj).__name__}")


def _looks_like(x: np.ndarray) -> str | None:
    """"time" for a uniform increasing ramp (a time column read as data), "impulse" for short one-sided
    pulses (a hammer force: the samples above half the peak are few and all of one sign, where a
    ring-down swings both ways), else None."""
    x = np.asarray(x, float)
    if x.size < 16 or not np.all(np.isfinite(x)):
        return None
    d = np.diff(x)
    if np.all(d > 0) and np.ptp(d) <= 1e-6 * abs(float(np.mean(d))):
        return "time"
    y = x - np.median(x)
    big = np.abs(y) > 0.5 * float(np.max(np.abs(y)))
    if big.sum() <= max(4, x.size // 200) and (np.all(y[big] > 0) or np.all(y[big] < 0)):
        return "impulse"
    return None


def time_like_channels(rec) -> list[str]:
    """Names of the channels of unknown quantity that are a uniform increasing ramp: a time column read as
    data (a headerless two-column file). The same rule ``response_channel`` passes them over by."""
    if not hasattr(rec, "data"):
        return []
    return [c.name for c, x in zip(rec.channels, rec.data)
            if c.quantity in ("unknown", "") and _looks_like(x) == "time"]


def response_channel(rec: Record, channel) -> int:
    """The channel to analyse: the one named, the only one, or the first that is not a force. Channels
    of unknown quantity that look like a time column or a hammer pulse are passed over when another is
    left, with a QualityWarning naming both (name the channel to override)."""
    if channel is not None:
        return rec.index(channel)
    if rec.n_channels == 1:
        return 0
    cands = [i for i, c in enumerate(rec.channels) if c.quantity != "force"]
    if not cands:
        raise ParameterError(f"channel=None but every channel of {rec.names} is a force; name the response channel")
    skipped = []
    for i in cands:
        kind = _looks_like(rec.data[i]) if rec.channels[i].quantity in ("unknown", "") else None
        if kind is None:
            if skipped:
                from .errors import warn_quality
                warn_quality(f"channel=None: {', '.join(f'{n!r} looks like a {k}' for n, k in skipped)}; analysing "
                             f"{rec.channels[i].name!r} (name the channel to choose another)", stacklevel=4)
            return i
        skipped.append((rec.channels[i].name, "time column" if kind == "time" else "force pulse"))
    return cands[0]


def clean_signal(rec: Record, idx: int, *, min_samples: int = 16, what: str = "rec") -> np.ndarray:
    """One channel as float64, refusing empty, too short, non-finite and constant data."""
    x = np.asarray(rec.data[idx], dtype=np.float64)
    name = rec.channels[idx].name
    if x.size == 0:
        raise ParameterError(f"{what} channel {name!r} is empty (0 samples)")
    if x.size < min_samples:
        raise ParameterError(f"{what} channel {name!r} has {x.size} samples; at least {min_samples} are needed")
    bad = ~np.isfinite(x)
    if bad.any():
        i = int(np.argmax(bad))
        raise ParameterError(f"{what} channel {name!r} has {int(bad.sum())} NaN/inf samples (first at index {i}, "
                             f"t={i / rec.fs:g} s); the rule is finite data: repair or cut the record first")
    if np.ptp(x) == 0:
        raise ParameterError(f"{what} channel {name!r} is constant (every sample {float(x[0]):g}): there is no "
                             "vibration to analyse")
    return x


def check_band(band, fs: float, *, name: str = "band") -> tuple[float, float] | None:
    """Validate a (lo, hi) band in Hz inside 0..fs/2."""
    if band is None:
        return None
    try:
        lo, hi = (float(b) for b in band)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}={band!r} must be a pair (lo, hi) in Hz") from None
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo < 0 or hi <= lo or hi > fs / 2:
        raise ParameterError(f"{name}={band!r} must satisfy 0 <= lo < hi <= fs/2 = {fs / 2:g} Hz")
    return lo, hi


def file_kind(mode: int) -> str:
    """What a path that is not a regular file is, in words."""
    import stat
    return ("a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode)
            else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "a special file")


def regular_input(path, name: str = "path", *, max_bytes: int | None = None):
    """``path`` as a Path to an existing regular file of at most ``max_bytes``: a folder, FIFO, device or
    socket is refused by name before it is opened (reading /dev/zero or a FIFO never ends)."""
    import stat
    from pathlib import Path
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise ParameterError(f"{name}={str(path)!r} does not exist") from None
    except OSError as exc:
        raise ParameterError(f"{name}={str(path)!r} cannot be inspected: {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ParameterError(f"{name}={str(path)!r} is {file_kind(st.st_mode)}, not a file: the rule is, inputs are "
                             "regular files")
    if max_bytes is not None and st.st_size > max_bytes:
        raise ParameterError(f"{name}={str(path)!r} is {st.st_size:,} bytes, above the {max_bytes:,} this input "
                             "takes")
    return p


def _number(value, name: str) -> float:
    """``value`` as a float; a bool or text is refused by name."""
    if isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{name}={value!r} must be a number, not a truth value")
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{name}={value!r} must be a number") from None


def finite_number(value, name: str) -> float:
    """``value`` as a finite float; a bool, text or NaN is refused by name."""
    v = _number(value, name)
    if not np.isfinite(v):
        raise ParameterError(f"{name}={value!r} must be finite")
    return v


def positive(value, name: str, *, allow_zero: bool = False) -> float:
    v = _number(value, name)
    if not np.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise ParameterError(f"{name}={value!r} must be finite and {'>= 0' if allow_zero else '> 0'}")
    return v


def name_index(names, which, *, what: str = "channel") -> int:
    """Position of ``which`` (a name or an index) among ``names``; anything else is a ParameterError."""
    names = list(names)
    if isinstance(which, (int, np.integer)) and not isinstance(which, bool):
        if not -len(names) <= which < len(names):
            raise ParameterError(f"{what}={which} is out of range: there are {len(names)} ({names})")
        return int(which) % len(names)
    if which not in names:
        raise ParameterError(f"{what}={which!r} is not one of {names}")
    return names.index(which)


def select_names(available, wanted, *, source: str) -> list[int]:
    """Positions of the wanted channels (names or indices; None for all) among ``available``."""
    available = list(available)
    if wanted is None:
        return list(range(len(available)))
    if isinstance(wanted, (str, int, np.integer)):
        wanted = [wanted]
    out = []
    for w in wanted:
        if isinstance(w, (int, np.integer)) and not isinstance(w, bool):
            if not 0 <= w < len(available):
                raise ParameterError(f"channels={wanted!r}: index {w} out of range for {len(available)} channels")
            out.append(int(w))
        elif w in available:
            out.append(available.index(w))
        else:
            raise ParameterError(f"channels={wanted!r}: {w!r} is not in {source}; it has {available}")
    return out


def check_flag(value, name: str) -> bool:
    """A yes/no option: True or False (numpy's bool too), never a truthy string or number that would
    mean what the caller did not say."""
    if not isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{name}={value!r} must be True or False")
    return bool(value)
