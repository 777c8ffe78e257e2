"""Preprocessing that returns new records with units, quantities and history updated.

detrend, zero-phase Butterworth filters (second-order sections), decimate and resample, and
integration/differentiation between displacement, velocity and acceleration, in the frequency
domain (with a high-pass corner) or in the time domain (high-pass, trapezoid, drift removal).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import scipy.fft as _fft
from scipy import signal as _sig

from ..core import units as _units
from ..core._validate import as_record, check_band, memory_guard, positive
from ..core.errors import ParameterError
from ..core.record import Channel, Record

__all__ = ["detrend", "filter", "decimate", "resample", "integrate", "differentiate", "DEFAULT_HIGHPASS_HZ"]

DEFAULT_HIGHPASS_HZ = 2.0  # integration corner: below it a 1/f^k gain would turn noise and drift into blow-up


def _finite(rec: Record, what: str):
    if not np.isfinite(rec.data).all():
        ch, i = np.argwhere(~np.isfinite(rec.data))[0]
        raise ParameterError(f"{what}: channel {rec.channels[ch].name!r} has NaN/inf at sample {i}; "
                             "the rule is finite data")


def detrend(rec, *, type: str = "linear", fs: float | None = None) -> Record:
    """Remove the mean ("constant") or the least-squares line ("linear") of every channel.

    Parameters
    ----------
    rec : Record or array_like
        The record.
    type : {"linear", "constant"}
        What to remove.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For an unknown type.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> rec = vm.Record.from_array(np.arange(100.0), fs=10.0)
    >>> float(np.abs(vm.detrend(rec).data).max()) < 1e-9
    True
    """
    rec = as_record(rec, fs=fs)
    if type not in ("constant", "linear"):
        raise ParameterError(f"type={type!r} must be 'constant' or 'linear'")
    _finite(rec, "detrend")
    return rec.replace(data=_sig.detrend(rec.data, axis=-1, type=type), note=f"detrend({type!r})")


def filter(rec, *, kind: str, cutoff, order: int = 4, zero_phase: bool = True, fs: float | None = None) -> Record:
    """Butterworth filter in second-order sections, zero-phase (forward-backward) by default.

    Parameters
    ----------
    rec : Record or array_like
        The record.
    kind : {"lowpass", "highpass", "bandpass", "bandstop"}
        The filter.
    cutoff : float or tuple of float
        Hz; (lo, hi) for "bandpass" and "bandstop".
    order : int
        Butterworth order.
    zero_phase : bool
        Forward-backward (no phase shift, order doubled) or causal.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For an unknown kind or a cutoff outside (0, fs/2).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(4000) / 1000.0
    >>> rec = vm.Record.from_array(np.sin(2 * np.pi * 5 * t) + np.sin(2 * np.pi * 200 * t), fs=1000.0)
    >>> low = vm.filter(rec, kind="lowpass", cutoff=50.0)
    >>> round(float(low.data[0, 1000:3000].std() * np.sqrt(2)), 2)
    1.0
    """
    rec = as_record(rec, fs=fs)
    if kind not in ("lowpass", "highpass", "bandpass", "bandstop"):
        raise ParameterError(f"kind={kind!r} must be 'lowpass', 'highpass', 'bandpass' or 'bandstop'")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order <= 12:
        raise ParameterError(f"order={order!r} must be an integer from 1 to 12")
    nyq = rec.fs / 2
    if kind in ("bandpass", "bandstop"):
        lo, hi = check_band(cutoff, rec.fs, name="cutoff")
        if lo <= 0 or hi >= nyq:
            raise ParameterError(f"cutoff={cutoff!r} must lie strictly inside 0..fs/2 = {nyq:g} Hz")
        wn = (lo, hi)
    else:
        wn = positive(cutoff, "cutoff")
        if wn >= nyq:
            raise ParameterError(f"cutoff={cutoff!r} must be below fs/2 = {nyq:g} Hz")
    _finite(rec, "filter")
    sos = _sig.butter(order, wn, btype=kind, fs=rec.fs, output="sos")
    y = _sig.sosfiltfilt(sos, rec.data, axis=-1) if zero_phase else _sig.sosfilt(sos, rec.data, axis=-1)
    return rec.replace(data=y, note=f"filter({kind}, {cutoff}, order={order}, zero_phase={zero_phase})")


def decimate(rec, factor: int, *, fs: float | None = None) -> Record:
    """Low-pass (zero-phase, order-8 Chebyshev I at 0.8 of the new Nyquist) and keep every factor-th sample.

    Parameters
    ----------
    rec : Record or array_like
        The record.
    factor : int
        Decimation factor (2 or more).
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record
        At fs / factor.

    Raises
    ------
    ParameterError
        For a factor below 2 or too short a record.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.decimate(vm.Record.from_array(np.zeros(1000), fs=1000.0), 4).fs
    250.0
    """
    rec = as_record(rec, fs=fs)
    if isinstance(factor, bool) or not isinstance(factor, (int, np.integer)) or factor < 1:
        raise ParameterError(f"factor={factor!r} must be an integer >= 1")
    if factor == 1:
        return rec
    if rec.n_samples < 27 * factor:
        raise ParameterError(f"factor={factor} needs at least {27 * factor} samples; the record has {rec.n_samples}")
    _finite(rec, "decimate")
    y = _sig.decimate(rec.data, int(factor), ftype="iir", zero_phase=True, axis=-1)
    return rec.replace(data=y, fs=rec.fs / factor, note=f"decimate({factor})")


def resample(rec, fs_new: float, *, fs: float | None = None) -> Record:
    """Polyphase resampling to a new rate (rational ratio, Kaiser-windowed anti-alias filter).

    Parameters
    ----------
    rec : Record or array_like
        The record.
    fs_new : float
        The new sampling rate in Hz.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For a rate that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.resample(vm.Record.from_array(np.zeros(1000), fs=1000.0), 2048.0).fs
    2048.0
    """
    rec = as_record(rec, fs=fs)
    fs_new = positive(fs_new, "fs_new")
    ratio = Fraction(fs_new / rec.fs).limit_denominator(1000)
    if abs(float(ratio) * rec.fs - fs_new) > 1e-9 * fs_new:
        raise ParameterError(f"fs_new={fs_new:g} / fs={rec.fs:g} is not a ratio of integers up to 1000")
    _finite(rec, "resample")
    y = _sig.resample_poly(rec.data, ratio.numerator, ratio.denominator, axis=-1)
    return rec.replace(data=y, fs=rec.fs * float(ratio), note=f"resample({fs_new:g})")


def _si(rec: Record, i: int) -> tuple[np.ndarray, Channel]:
    c = rec.channels[i]
    if c.quantity not in ("displacement", "velocity", "acceleration"):
        raise ParameterError(f"channel {c.name!r} has quantity {c.quantity!r}; integration and differentiation "
                             "need displacement, velocity or acceleration (give quantity= when reading)")
    x = rec.data[i]
    if c.unit:
        x = _units.convert(x, c.unit, _units.SI_UNIT[c.quantity])
    return x, c


@memory_guard
def integrate(rec, *, method: str = "frequency", highpass: float = DEFAULT_HIGHPASS_HZ, channels=None,
              fs: float | None = None) -> Record:
    """Acceleration -> velocity, velocity -> displacement, in SI units (g becomes m/s^2 first).

    Both methods remove the mean and continue the record past both ends by linear prediction (Burg
    AR), so the transform's wrap-around and the filters' start-up fall outside the record.
    "frequency": X(f) / (i 2 pi f) with every line below ``highpass`` set to zero (a sine at f above
    1.25 x the corner integrates within 0.1 %); "time": zero-phase Butterworth high-pass, trapezoid,
    then the drift removed (its RMS agrees with the frequency method within 1 % away from the ends).

    Parameters
    ----------
    rec : Record or array_like
        Acceleration or velocity with a known unit.
    method : {"frequency", "time"}
        How to integrate.
    highpass : float
        Corner in Hz: keeps low-frequency noise and offsets from blowing up; set it below the lowest
        frequency of interest.
    channels : str, int or list, optional
        Channels to integrate (default all).
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record
        Velocity in m/s or displacement in m.

    Raises
    ------
    ParameterError
        For displacement, an unknown unit or a corner outside (0, fs/2).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(20000) / 1000.0
    >>> acc = vm.Record.from_array(np.sin(2 * np.pi * 10 * t), fs=1000.0, unit="m/s^2")
    >>> v = vm.integrate(acc)
    >>> round(float(np.abs(v.data[0, 5000:15000]).max() * 2 * np.pi * 10), 2)
    1.0
    """
    return _calculus(rec, +1, method, highpass, channels, fs)


@memory_guard
def differentiate(rec, *, method: str = "frequency", channels=None, fs: float | None = None) -> Record:
    """Displacement -> velocity, velocity -> acceleration, in SI units.

    Parameters
    ----------
    rec : Record or array_like
        Displacement or velocity with a known unit.
    method : {"frequency", "time"}
        X(f) i 2 pi f, or central differences.
    channels : str, int or list, optional
        Channels to differentiate (default all).
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record
        Velocity in m/s or acceleration in m/s^2.

    Raises
    ------
    ParameterError
        For acceleration or an unknown unit.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(2000) / 1000.0
    >>> x = vm.Record.from_array(np.sin(2 * np.pi * 10 * t), fs=1000.0, unit="m")
    >>> vm.differentiate(x).channels[0].unit
    'm/s'
    """
    return _calculus(rec, -1, method, 0.0, channels, fs)


EXTEND_ORDER = 32        # AR order of the linear-prediction extension: 16 sinusoids continued across the ends
EXTEND_CORNER_PERIODS = 32  # extension length in periods of the high-pass corner: the taper's spread stays below it


def burg(x: np.ndarray, order: int) -> np.ndarray:
    """AR coefficients a (a[0] = 1; x[n] = -sum a[k] x[n-k] + e[n]) by Burg's method: the reflection
    coefficients minimise the forward and backward prediction errors together, so |k| < 1 and the
    model is stable (its extrapolation never grows)."""
    f = np.array(x, float)
    b = f.copy()
    a = np.array([1.0])
    for m in range(min(order, f.size - 2)):
        ff, bb = f[m + 1:], b[m:-1]
        den = ff @ ff + bb @ bb
        if not den > 0:
            break
        k = -2.0 * (ff @ bb) / den
        a = np.r_[a, 0.0]
        a = a + k * a[::-1]
        f[m + 1:], b[m + 1:] = ff + k * bb, bb + k * ff
    return a


def extend(x: np.ndarray, n_ext: int, *, order: int = EXTEND_ORDER) -> np.ndarray:
    """x with n_ext samples added before and after: the AR (Burg) prediction continues it backwards
    and forwards (tones go on with their phase), then a Planck taper (smooth to all orders, so its
    spectrum falls faster than any power) brings it to zero.
    Transforms and filters of the extended signal have their wrap-around and start-up at its far
    ends, not in the record."""
    x = np.asarray(x, float)
    if isinstance(n_ext, bool) or not isinstance(n_ext, (int, np.integer)) or n_ext < 0:
        raise ParameterError(f"n_ext={n_ext!r} must be an integer >= 0 (samples added at each end)")
    if x.ndim != 1 or not np.isfinite(x).all():
        raise ParameterError("x must be a 1-D array of finite samples: the prediction would carry a NaN/inf forward")
    if n_ext == 0 or x.size < 4:
        return x.copy()
    a = burg(x, order)

    def forward(y):
        zi = _sig.lfiltic([1.0], a, y[::-1][:a.size - 1])
        return _sig.lfilter([1.0], a, np.zeros(n_ext), zi=zi)[0]
    u = np.arange(1, n_ext + 1) / n_ext   # Planck taper: 1 at the record, 0 at the far end, smooth to all orders
    with np.errstate(over="ignore", divide="ignore"):
        taper = np.where(u < 1, 1.0 / (1.0 + np.exp(np.clip(1.0 / np.maximum(1 - u, 1e-300) - 1.0 / u, -700, 700))),
                         0.0)
    return np.concatenate([(forward(x[::-1]) * taper)[::-1], x, forward(x) * taper])


def _extension_length(n: int, fs: float, highpass: float) -> int:
    """Samples added at each end: 32 periods of the corner (so a tone just above it keeps 0.1 %), at
    least a quarter of the record, at most four records."""
    want = EXTEND_CORNER_PERIODS * fs / highpass if highpass > 0 else 0
    return int(min(4 * n, max(n // 4, want)))


def _calculus(rec, direction, method, highpass, channels, fs):
    rec = as_record(rec, fs=fs)
    from ..core._validate import check_range
    check_range(rec.data)
    if method not in ("frequency", "time"):
        raise ParameterError(f"method={method!r} must be 'frequency' or 'time'")
    hp = positive(highpass, "highpass", allow_zero=True)
    if direction > 0 and hp >= rec.fs / 2:
        raise ParameterError(f"highpass={highpass} must be below fs/2 = {rec.fs / 2:g} Hz")
    idx = range(rec.n_channels) if channels is None else [rec.index(c) for c in (
        [channels] if isinstance(channels, (str, int)) else channels)]
    _finite(rec, "integrate" if direction > 0 else "differentiate")
    if rec.n_samples < 16:
        raise ParameterError(f"the record has {rec.n_samples} samples; {'integration' if direction > 0 else 'differentiation'} "
                             "needs at least 16 (the high-pass and the extension past the ends need a few cycles)")
    data = np.array(rec.data)
    chans = list(rec.channels)
    n = rec.n_samples
    # both ways the record is continued past its ends: the transform's wrap-around (a jump between the
    # last and first sample) would otherwise ring through the derivative as a sinc at both ends
    L = _extension_length(n, rec.fs, hp)
    for i in idx:
        x, c = _si(rec, i)
        q_new = _units.integral_quantity(c.quantity) if direction > 0 else _units.derivative_quantity(c.quantity)
        if direction < 0:
            y = derivative(x, rec.fs, 1, extension=L) if method == "frequency" else np.gradient(x, 1 / rec.fs)
        else:   # the offset first (integrated, it is a ramp); then the record continued past its ends
            y = _integral(extend(x - x.mean(), L), rec.fs, hp, method)[L:L + n]
        data[i] = y
        chans[i] = Channel(c.name, q_new, _units.SI_UNIT[q_new], c.location)
    verb = "integrate" if direction > 0 else "differentiate"
    note = f"{verb}(method={method!r}" + (f", highpass={hp:g} Hz)" if direction > 0 else ")")
    return rec.replace(data=data, channels=tuple(chans), note=note)


def _integral(x: np.ndarray, fs: float, hp: float, method: str) -> np.ndarray:
    """The integral of the (extended) samples x, nothing kept below ``hp``: X / (i 2 pi f) over the
    transform, or the trapezoid rule between zero-phase high-passes."""
    if method == "frequency":
        N = _fft.next_fast_len(x.size, real=True)
        f = np.fft.rfftfreq(N, 1 / fs)
        with np.errstate(divide="ignore", invalid="ignore"):
            Y = np.where(f >= max(hp, f[1] if f.size > 1 else 0.0), _fft.rfft(x, N) / (2j * np.pi * f), 0.0)
        return _fft.irfft(Y, N)[:x.size]
    from scipy.integrate import cumulative_trapezoid
    sos = _sig.butter(4, hp, btype="highpass", fs=fs, output="sos") if hp > 0 else None
    xx = _sig.sosfiltfilt(sos, x) if sos is not None else x
    y = _sig.detrend(cumulative_trapezoid(xx, dx=1 / fs, initial=0.0), type="linear")
    return _sig.sosfiltfilt(sos, y) if sos is not None else y   # what it made of the residual low frequencies


def derivative(x, fs: float, order: int = 1, *, extension: int | None = None) -> np.ndarray:
    """The ``order``-th time derivative of samples, over the transform of the record continued past
    both ends.

    X(f) (i 2 pi f)^order over the samples continued by AR prediction (``extend``; default a quarter
    of the record each side): without the continuation the jump between the last and the first sample
    rings through the derivative. ``vm.differentiate`` and the diagnosis's unit conversion use it.

    Parameters
    ----------
    x : array_like
        1-D finite samples.
    fs : float
        Sampling rate in Hz.
    order : int
        1 (velocity from displacement, acceleration from velocity) or more.
    extension : int, optional
        Samples added at each end (default ``len(x) // 4``).

    Returns
    -------
    numpy.ndarray
        The derivative, as many samples as ``x``.

    Raises
    ------
    ParameterError
        For a non-positive fs, an order that is not a whole number >= 1, or samples that are not 1-D
        and finite.

    Examples
    --------
    >>> import numpy as np
    >>> from vibmeasure.signal.preprocess import derivative
    >>> t = np.arange(4000) / 1000.0
    >>> v = derivative(np.sin(2 * np.pi * 5 * t), 1000.0)
    >>> bool(abs(v[2000] - 2 * np.pi * 5 * np.cos(2 * np.pi * 5 * t[2000])) < 1e-3)
    True
    """
    fs = positive(fs, "fs")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 1:
        raise ParameterError(f"order={order!r} must be a whole number >= 1 (1: one derivative)")
    x = np.asarray(x, float)
    n = x.size
    L = n // 4 if extension is None else int(extension)
    if x.ndim != 1 or not np.isfinite(x).all():
        raise ParameterError("x must be a 1-D array of finite samples: the transform would spread a NaN/inf everywhere")
    xe = extend(x - x.mean(), L)   # the offset has no derivative; the taper would make one of it
    N = _fft.next_fast_len(xe.size, real=True)
    f = np.fft.rfftfreq(N, 1 / fs)
    return _fft.irfft(_fft.rfft(xe, N) * (2j * np.pi * f) ** order, N)[L:L + n]
