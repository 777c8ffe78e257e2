"""Helpers shared by the file formats: atomic writes, time columns, channel assembly."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Channel, Record
from ..core import units as _units

# relative spread of time steps accepted as uniform sampling
TIME_STEP_RTOL = 1e-3


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path``; it replaces ``path`` only if the block succeeds.

    Nothing is half-written: on any error the temporary file is removed and ``path`` is untouched.
    """
    path = Path(path)
    if not path.parent.exists():
        raise ParameterError(f"path={str(path)!r}: folder {str(path.parent)!r} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; a finished file gets the usual mode
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


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
    data = np.asarray(data, dtype=np.float64)
    if data.ndim == 1:
        data = data[np.newaxis]
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
