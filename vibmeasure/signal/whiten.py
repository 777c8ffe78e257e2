"""Pre-whitening before demodulation: cepstral pre-whitening, AR (linear-prediction) whitening and
removal of the shaft-synchronous (discrete) part by a phase-binned time-synchronous average.

Bearing faults show as a weak train of impacts under much stronger deterministic lines (shaft
harmonics, gear mesh) and structural resonances. Whitening flattens the spectrum so the impacts'
broadband, repetitive energy dominates the envelope (Sawalhi & Randall 2007; Borghesani et al. 2013).
The array functions (leading underscore) work on float64 arrays; the public ones take a Record.
"""

from __future__ import annotations

import numpy as np
from scipy import fft as _fft

from ..core._validate import as_record, clean_signal, positive, response_channel
from ..core.errors import ParameterError
from ..core.record import Channel, Record

__all__ = ["whitened", "tapered_spectrum", "prewhiten", "remove_synchronous", "measured_top", "cepstral_spectrum", "edit_lines", "ar_residual", "ar_order", "synchronous_part"]

_METHODS = ("cepstral", "ar")
WHITEN_TAPER = 0.05   # share of a record tapered before it is whitened to be judged (monitor.bearing.spectra.TAPER)
MIN_WHITENED = 16     # samples: fewer hold no spectrum to flatten


def whitened(x) -> tuple[np.ndarray, int]:
    """(x cepstrally whitened after a Tukey taper of WHITEN_TAPER: every bin of its spectrum at magnitude
    1, none above the band it measures; the samples at each end the taper touches): what
    ``quality.transients(whiten=True)`` and ``quality.isolated_events`` judge, computed once by a caller
    asking both (``whitened_x=``).

    Raises
    ------
    ParameterError
        For x not 1-D, not finite, shorter than MIN_WHITENED samples or constant.

    Examples
    --------
    >>> import numpy as np
    >>> from vibmeasure.signal.whiten import whitened
    >>> whitened(np.random.default_rng(0).normal(size=4096))[1]
    103
    """
    try:
        x = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError("x must be an array of numbers (one channel's samples)") from None
    if x.ndim != 1 or x.size < MIN_WHITENED or not np.isfinite(x).all() or not np.ptp(x) > 0:
        raise ParameterError(f"x (shape {x.shape}) must be one channel's finite samples, at least {MIN_WHITENED} "
                             "of them and not constant: there is no spectrum to whiten")
    n = x.size
    X = tapered_spectrum(x, WHITEN_TAPER)
    k_hi = int(np.floor(measured_top(X, 1.0, n) * n))
    return _fft.irfft(cepstral_spectrum(X, k_hi), n), int(np.ceil(WHITEN_TAPER * n / 2))


def _whitened_or(x: np.ndarray, given) -> tuple[np.ndarray, int]:
    """``whitened(x)``, or ``given`` (a caller's ``whitened_x=``) once it is checked to be x's shape."""
    if given is None:
        return whitened(x)
    ok = isinstance(given, tuple) and len(given) == 2 and isinstance(given[1], (int, np.integer))
    if not ok or np.shape(given[0]) != x.shape or not 0 <= given[1] < x.size // 2:
        raise ParameterError(f"whitened_x must be whitened(x) of these {x.size} samples: (array of {x.size}, "
                             "samples the taper touches)")
    return given


def _cepstral(x: np.ndarray) -> np.ndarray:
    """Cepstral pre-whitening: the spectrum divided by its magnitude (the real cepstrum set to zero
    except at quefrency 0), so every line and resonance gets the same height and only the phase,
    which carries the impacts' timing, is left."""
    return _fft.irfft(cepstral_spectrum(_fft.rfft(x - x.mean())), n=x.size)


DEAD_DB = 25.0   # a top band this far below the typical level under it holds no measurement
QUIET_DB = 15.0  # ... and this far below the quiet tenth of the bands under it (their noise floor)


def measured_top(X: np.ndarray, fs: float, n: int) -> float:
    """Upper edge (Hz) of the band a record measures, from its rfft X (record length n).

    The spectrum is cut into 512 equal bands (each level the median of 5 neighbours, so a lone tone
    does not count); the measured band ends where every band above stays more than DEAD_DB below the
    median level of the bands under it and more than QUIET_DB below their quiet tenth: the stop band
    of an anti-alias or resampling filter, or the converter's floor. Whitening would lift that band to
    full height, and with it filter images and converter artefacts. A filter cuts the sensor's own
    noise with the rest, so its stop band lies under the quiet gaps of the pass band too (CWRU's
    drive-end records: 23-46 dB under their quiet tenth); a machine whose vibration ends low (a
    gearbox's mesh harmonics to 1.5 kHz) leaves that noise standing above as high as in the gaps
    below (synthetic gearboxes at 30 dB: at most 11 dB under the quiet tenth, 28 dB under the median),
    and the band is measured. A record with content up to Nyquist keeps its whole band."""
    P = np.abs(X[1:]) ** 2
    nb = min(512, P.size // 8)
    if nb < 64:
        return fs / 2
    from scipy.ndimage import median_filter
    edges = np.linspace(0, P.size, nb + 1).astype(int)
    level = np.add.reduceat(P, edges[:-1]) / np.diff(edges)
    L = median_filter(10 * np.log10(np.maximum(level, 1e-300)), size=5, mode="nearest")
    top_max = np.maximum.accumulate(L[::-1])[::-1]          # loudest band from j up
    # the typical and the quiet level under j: the median and the 10th percentile of the bands below
    # (the pass band, as long as it is the larger part), on every 4th band
    js = np.arange(8, nb, 4)
    median, quiet = _prefix_quantiles(L, js, (0.5, 0.1))
    dead = np.flatnonzero((top_max[js] < median - DEAD_DB) & (top_max[js] < quiet - QUIET_DB))
    return fs / 2 if not dead.size else float(edges[js[dead[0]]]) * fs / n


def _prefix_quantiles(L: np.ndarray, js: np.ndarray, qs: tuple) -> list:
    """For each q in qs, the q-quantile of L[:j] (linear between order statistics, as np.quantile) for
    each rising j in js: the prefix kept sorted as it grows (one insertion per value, not a partition
    of the whole prefix for every j)."""
    from bisect import insort
    vals, out, n = [], [[] for _ in qs], 0
    for j in js.tolist():
        for v in L[n:j].tolist():
            insort(vals, v)
        n = j
        for o, q in zip(out, qs):
            pos = q * (j - 1)
            i = int(pos)
            o.append(vals[i] + (pos - i) * (vals[min(i + 1, j - 1)] - vals[i]))
    return [np.array(o) for o in out]


def tapered_spectrum(x: np.ndarray, taper: float) -> np.ndarray:
    """rfft of x less its mean under a Tukey window of ``taper`` (read-only).

    The transient check and the bearing spectra both whiten each channel from this spectrum: the
    last four (of up to CACHED_SAMPLES samples) are kept, keyed on their samples' BLAKE2 digest (1.4 ms
    for 121,168 samples, against 8 ms for an FFT of such an awkward length as CWRU's), so a
    channel is transformed once and an array changed in place is transformed again.

    Examples
    --------
    >>> import numpy as np
    >>> from vibmeasure.signal.whiten import tapered_spectrum
    >>> x = np.sin(2 * np.pi * 8 * np.arange(256) / 256)
    >>> X = tapered_spectrum(x, 0.1)
    >>> int(np.argmax(np.abs(X))), tapered_spectrum(x.copy(), 0.1) is X
    (8, True)
    """
    key = None
    if x.size <= CACHED_SAMPLES:   # a long record's spectra are not held after the analysis
        from hashlib import blake2b
        key = (x.size, x.dtype.str, float(taper), blake2b(np.ascontiguousarray(x)).digest())
        for k, X in _TAPERED["last"]:      # one snapshot: another thread may replace it meanwhile
            if k == key:
                return X
    from .spectral import symmetric_window
    X = _fft.rfft((x - x.mean()) * symmetric_window(("tukey", float(taper)), x.size))
    X.flags.writeable = False
    if key is not None:
        _TAPERED["last"] = ((key, X),) + _TAPERED["last"][:3]
    return X


CACHED_SAMPLES = 2 ** 21   # the last four channels' spectra kept: at most 64 MiB


_TAPERED: dict = {"last": ()}


def cepstral_spectrum(X: np.ndarray, k_top: int | None = None) -> np.ndarray:
    """The spectrum of the cepstrally whitened signal (X over its magnitude), zero above bin k_top."""
    mag = np.abs(X)
    Xw = X / np.maximum(mag, 1e-12 * max(float(mag.max()), 1e-300))
    if k_top is not None:
        Xw[k_top + 1:] = 0
    return Xw


def edit_lines(x: np.ndarray, *, width: int = 33, ratio: float = 3.0) -> np.ndarray:
    """Discrete lines cut to the local level of the spectrum (a frequency-domain discrete/random
    separation): every bin whose magnitude exceeds ``ratio`` x the running median of ``width`` bins
    keeps its phase and gets the median magnitude. Random (bearing) content passes unchanged."""
    from scipy.ndimage import median_filter
    X = _fft.rfft(x - x.mean())
    mag = np.abs(X)
    med = median_filter(mag, size=width, mode="reflect")
    line = mag > ratio * med
    X[line] *= med[line] / mag[line]
    return _fft.irfft(X, n=x.size)


def _ar_coefficients(x: np.ndarray, order: int) -> np.ndarray:
    """Linear-prediction (Yule-Walker) coefficients a[1..p] of x, from the biased autocorrelation."""
    from scipy.linalg import solve_toeplitz
    n = x.size
    nfft = _fft.next_fast_len(2 * n)
    X = _fft.rfft(x - x.mean(), nfft)
    r = _fft.irfft(np.abs(X) ** 2, nfft)[: order + 1] / n
    r[0] *= 1 + 1e-9  # tiny ridge: a pure tone makes the Toeplitz matrix singular
    return solve_toeplitz(r[:order], r[1: order + 1])


def ar_residual(x: np.ndarray, order: int) -> np.ndarray:
    """Prediction error of an AR(order) model: what the signal's past cannot predict (impacts)."""
    from scipy.signal import oaconvolve
    a = _ar_coefficients(x, order)
    e = oaconvolve(x - x.mean(), np.concatenate(([1.0], -a)))[: x.size]
    e[:order] = 0.0  # the filter's start-up transient
    return e


def ar_order(x: np.ndarray, fs: float, f_fault: float) -> int:
    """An AR order long enough to model the resonances but shorter than a fault period (so the
    impacts stay unpredictable): between 16 and 200 taps, a tenth of the fault period."""
    return int(np.clip(0.1 * fs / f_fault, 16, 200))


def synchronous_part(x: np.ndarray, fs: float, f1: float, per_rev: int | None = None) -> np.ndarray:
    """The shaft-synchronous part at a constant speed f1: samples binned by shaft phase, averaged
    over all revolutions and interpolated back (a time-synchronous average without a tachometer)."""
    per_rev = int(per_rev or max(8, min(1024, round(fs / f1))))
    phase = (np.arange(x.size) * (f1 / fs)) % 1.0
    pos = phase * per_rev
    j = np.minimum(pos.astype(np.int64), per_rev - 1)
    counts = np.bincount(j, minlength=per_rev)
    if counts.min() == 0:
        return np.zeros_like(x)
    avg = np.bincount(j, weights=x, minlength=per_rev) / counts
    centres = np.arange(per_rev) + 0.5
    return np.interp(pos, np.concatenate(([centres[-1] - per_rev], centres, [centres[0] + per_rev])),
                     np.concatenate(([avg[-1]], avg, [avg[0]])))


def _pick(rec, channel, fs):
    rec = as_record(rec, fs=fs)
    i = response_channel(rec, channel)
    return rec, i, clean_signal(rec, i, min_samples=64)


def prewhiten(rec, *, method: str = "cepstral", order: int | None = None, channel=None,
              fs: float | None = None) -> Record:
    """One channel whitened before envelope analysis.

    The result keeps the channel's name with a suffix; its amplitude scale is arbitrary (unit "").

    Parameters
    ----------
    rec : Record or array_like
        The record.
    method : {"cepstral", "ar"}
        Cepstral pre-whitening (the spectrum divided by its magnitude), or the prediction error of a
        Yule-Walker AR model.
    order : int, optional
        AR order (default fs / 100, between 16 and 200).
    channel : str or int, optional
        The channel.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For an unknown method or bad data.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
    >>> vm.prewhiten(rec).channels[0].unit
    ''
    """
    rec, i, x = _pick(rec, channel, fs)
    if method not in _METHODS:
        raise ParameterError(f"method={method!r} must be one of {_METHODS}")
    if method == "cepstral":
        y = _cepstral(x)
    else:
        p = ar_order(x, rec.fs, 100.0) if order is None else order
        if isinstance(p, bool) or not isinstance(p, (int, np.integer)) or not 1 <= p < x.size // 4:
            raise ParameterError(f"order={order!r} must be an integer from 1 to a quarter of the record ({x.size // 4})")
        y = ar_residual(x, int(p))
    c = rec.channels[i]
    return Record(y, rec.fs, (Channel(f"{c.name}.white", c.quantity, "", c.location),), t0=rec.t0, meta=rec.meta,
                  history=rec.history + (f"prewhiten(method={method!r})",))


def remove_synchronous(rec, *, shaft_hz: float, channel=None, fs: float | None = None) -> Record:
    """The channel with its shaft-synchronous part (1X, its harmonics, a mesh on that shaft) removed.

    A time-synchronous average at the constant speed ``shaft_hz`` is subtracted sample by sample; what
    is left is the random and non-synchronous part, where bearing impacts live (they slip).

    Parameters
    ----------
    rec : Record or array_like
        The record.
    shaft_hz : float
        The shaft speed in Hz.
    channel : str or int, optional
        The channel.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For a speed outside (0, fs/2) or too short a record.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="unbalance", rpm=1800, duration=2.0, seed=1)
    >>> rest = vm.remove_synchronous(rec, shaft_hz=30.0)
    >>> bool(rest.data.std() < rec.data.std())
    True
    """
    rec, i, x = _pick(rec, channel, fs)
    f1 = positive(shaft_hz, "shaft_hz")
    if x.size / rec.fs * f1 < 10:
        raise ParameterError(f"the record spans {x.size / rec.fs * f1:.1f} revolutions at {f1:g} Hz; at least 10 "
                             "are needed to average the synchronous part")
    if f1 >= rec.fs / 4:
        raise ParameterError(f"shaft_hz={f1:g} must be below fs/4 = {rec.fs / 4:g} Hz")
    y = x - synchronous_part(x, rec.fs, f1)
    return rec.replace(data=np.vstack([y if k == i else rec.data[k] for k in range(rec.n_channels)]),
                       note=f"remove_synchronous(shaft_hz={f1:g}, channel={rec.channels[i].name!r})")
