"""Band selection for envelope analysis: Antoni's fast kurtogram and the infogram (spectral
negentropy), and the squared-envelope spectrum (SES) of one band, all from one FFT of the record.

Bands follow the 1/3-binary tree of the fast kurtogram (Antoni 2007): level k splits 0..fs/2 into
2^k bands and level k + 0.6 (log2 3 - 1 = 0.585) into 3 x 2^(k-1). Each band's complex envelope is the
inverse FFT of that band's bins alone (an ideal band-pass, decimated for free), so a whole level
costs about one FFT of the record. Kurtosis of a complex envelope is E|c|^4 / (E|c|^2)^2 - 2: zero for
Gaussian noise, large for repetitive impacts. Negentropy (Antoni 2016) is E[x ln x] of the
normalised squared envelope x, in the time domain (impulsiveness) and in the envelope spectrum
(cyclostationarity: lines); each is given as its excess over Gaussian noise (1 - Euler's gamma).
"""

from __future__ import annotations

import numpy as np
from scipy import fft as _fft

from ..core._validate import as_record, clean_signal, positive, response_channel
from ..core.errors import ParameterError
from ..core.results import Kurtogram
from .spectral import symmetric_window

__all__ = ["kurtogram", "Kurtogram", "band_ses", "kurtogram_of", "ses_power"]

_GAUSS_NEGENTROPY = 1.0 - np.euler_gamma  # E[x ln x] for x ~ Exp(1): the squared envelope of noise


def _tree(max_level: float):
    """(level label, number of bands) of the 1/3-binary tree up to max_level."""
    out = [(0.0, 1)]
    k = 1
    while k <= max_level:
        out.append((float(k), 2 ** k))
        if k + 0.585 <= max_level:
            out.append((round(k + 0.585, 1), 3 * 2 ** (k - 1)))
        k += 1
    return out


def _band_bins(n_bins: int, nb: int, i: int) -> tuple[int, int]:
    return int(round(i * n_bins / nb)), int(round((i + 1) * n_bins / nb))


def _complex_envelope(X: np.ndarray, k0: int, k1: int, n: int, length: int | None = None) -> np.ndarray:
    """The analytic signal of bins k0..k1 of rfft X (record length n), shifted to baseband and sampled
    at length samples over the record (default k1 - k0): amplitude in the record's unit."""
    m = k1 - k0
    L = m if length is None else length
    return _fft.ifft(X[k0:k1], n=L) * (2.0 * L / n)


def _spectrum_map(X: np.ndarray, n: int, fs: float, *, min_bandwidth: float, max_level: float, k_cyc: int,
                  f_lo: float = 0.0, f_hi: float | None = None):
    """Kurtosis and negentropy of every band of the tree whose width is at least min_bandwidth, whose
    lower edge is at f_lo or above and of which at least 3/4 lies below f_hi (NaN for the others). The
    bands of one level and one width are transformed together (``_band_rows``)."""
    k_hi = np.inf if f_hi is None else f_hi * n / fs
    n_bins = X.size - 1
    levels, nbs, kur, neg = [], [], [], []
    for lev, nb in _tree(max_level):
        if fs / 2 / nb < min_bandwidth:
            continue
        kv, nv = np.full(nb, np.nan), np.full(nb, np.nan)
        widths: dict = {}
        for i in range(nb):
            k0, k1 = _band_bins(n_bins, nb, i)
            if k0 * fs / n < f_lo - 1e-9 or k1 - k0 < 8 or min(k1, k_hi) - k0 < 0.75 * (k1 - k0):
                continue
            widths.setdefault(k1 - max(k0, 1), []).append((i, max(k0, 1)))
        for m, bands in widths.items():
            at = [i for i, _ in bands]
            kv[at], nv[at] = _band_rows(X, [k0 for _, k0 in bands], m, n, k_cyc)
        levels.append(lev); nbs.append(nb); kur.append(kv); neg.append(nv)
    return tuple(levels), tuple(nbs), tuple(kur), tuple(neg)


def _band_rows(X: np.ndarray, starts: list, m: int, n: int, k_cyc: int) -> tuple:
    """(kurtosis, negentropy) of the bands of m bins starting at ``starts``: their complex envelopes
    (``_complex_envelope``) in one inverse FFT of many rows, on two threads. Kurtosis E|c|^4 / (E|c|^2)^2
    - 2; negentropy the mean of the time domain's and the envelope spectrum's (each bin of cyclic order
    1..k_cyc normalised by its expected level for band-limited noise, a triangle in cyclic frequency),
    each E[x ln x] of the normalised values less Gaussian noise's. Each mean is taken row by row
    (``_row_means``): numpy sums a 2-D array's rows in another order than a row alone, and a band's
    values must not depend on how many bands share its width."""
    idx = np.asarray(starts)[:, None] + np.arange(m)
    c = _fft.ifft(X[idx], n=m, axis=-1, workers=2) * (2.0 * m / n)
    e = np.abs(c) ** 2
    e_mean = _row_means(e)
    # squared as a Python float (libm's pow, which may differ from x * x by a unit): the values the
    # validation figures were measured with, to the last bit
    kurt = _row_means(e ** 2) / np.maximum([float(v) ** 2 for v in e_mean], 1e-300) - 2.0
    x = e / np.maximum(e_mean, 1e-300)[:, None]
    neg_t = _row_means(x * np.log(np.maximum(x, 1e-300))) - _GAUSS_NEGENTROPY
    k = np.arange(1, min(k_cyc, m // 2) + 1)
    if k.size < 8:
        return kurt, np.full(len(starts), np.nan)
    P = np.abs(_fft.rfft(e - e_mean[:, None], axis=-1, workers=2)) ** 2
    y = P[:, k] / (1.0 - k / m)
    y = y / np.maximum(_row_means(y), 1e-300)[:, None]
    neg_s = _row_means(y * np.log(np.maximum(y, 1e-300))) - _GAUSS_NEGENTROPY
    return kurt, 0.5 * (neg_t + neg_s)


def _row_means(a: np.ndarray) -> np.ndarray:
    return np.array([row.mean() for row in a])


def kurtogram_of(x: np.ndarray | None, fs: float, *, min_bandwidth: float, max_level: float | None,
                  criterion: str, cyclic_max: float | None, X: np.ndarray | None = None,
                  f_lo: float = 0.0, n: int | None = None, f_hi: float | None = None) -> Kurtogram:
    """The map of one signal x, or of its rfft X (record length n)."""
    n = x.size if n is None else n
    if X is None:
        X = _fft.rfft(x - x.mean())
    if max_level is None:
        max_level = max(0.0, np.log2(fs / 2 / min_bandwidth))
    k_cyc = int(round((cyclic_max if cyclic_max else min_bandwidth) * n / fs))
    levels, nbs, kur, neg = _spectrum_map(X, n, fs, min_bandwidth=min_bandwidth, max_level=max_level, k_cyc=k_cyc,
                                          f_lo=f_lo, f_hi=f_hi)
    kg = Kurtogram(fs, levels, nbs, kur, neg, (), criterion, np.nan, min_bandwidth,
                   {"max_level": max_level, "cyclic_max_hz": cyclic_max, "min_frequency_hz": f_lo,
                    "max_frequency_hz": fs / 2 if f_hi is None else f_hi})
    lo, hi, _, val = kg.best(criterion)
    return Kurtogram(fs, levels, nbs, kur, neg, (lo, hi), criterion, val, min_bandwidth, kg.params)


def kurtogram(rec, *, channel=None, min_bandwidth: float | None = None, max_level: float | None = None,
              criterion: str = "kurtosis", cyclic_max: float | None = None, min_frequency: float = 0.0,
              fs: float | None = None) -> Kurtogram:
    """Fast kurtogram (1/3-binary tree) and infogram of one channel (Antoni 2007, 2016).

    Parameters
    ----------
    rec : Record or array_like
        The record.
    channel : str or int, optional
        The channel.
    min_bandwidth : float, optional
        Narrowest band in Hz (default fs/64): for bearings at least three times the highest fault
        frequency, so the envelope carries its third harmonic.
    max_level : float, optional
        Deepest level of the tree.
    criterion : {"kurtosis", "negentropy"}
        Impulsiveness, or the infogram's average of impulsiveness and envelope-spectrum lines.
    cyclic_max : float, optional
        Highest envelope frequency the negentropy weighs (default ``min_bandwidth``).
    min_frequency : float
        Bands whose lower edge lies below it are left out (NaN): shaft harmonics live there.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Kurtogram
        The map and the best band (``band``, Hz).

    Raises
    ------
    ParameterError
        For bad parameters or data.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=2.0, seed=1)
    >>> kg = vm.kurtogram(rec, min_bandwidth=600, min_frequency=1500)
    >>> kg.band[0] >= 1500.0                      # above the shaft harmonics' region
    True
    """
    rec = as_record(rec, fs=fs)
    i = response_channel(rec, channel)
    x = clean_signal(rec, i, min_samples=256)
    if criterion not in ("kurtosis", "negentropy"):
        raise ParameterError(f"criterion={criterion!r} must be 'kurtosis' or 'negentropy'")
    bw = rec.fs / 64 if min_bandwidth is None else positive(min_bandwidth, "min_bandwidth")
    if bw > rec.fs / 2:
        raise ParameterError(f"min_bandwidth={bw:g} Hz exceeds the Nyquist frequency {rec.fs / 2:g} Hz")
    if max_level is not None and not (np.isfinite(max_level) and 0 <= max_level <= 12):
        raise ParameterError(f"max_level={max_level!r} must be between 0 and 12")
    if cyclic_max is not None:
        positive(cyclic_max, "cyclic_max")
    f_lo = positive(min_frequency, "min_frequency", allow_zero=True)
    if f_lo + bw > rec.fs / 2:
        raise ParameterError(f"min_frequency={f_lo:g} Hz plus min_bandwidth={bw:g} Hz exceeds the Nyquist "
                             f"frequency {rec.fs / 2:g} Hz: no band is left")
    return kurtogram_of(x, rec.fs, min_bandwidth=bw, max_level=max_level, criterion=criterion,
                         cyclic_max=cyclic_max, f_lo=f_lo)


def ses_power(X: np.ndarray, n: int, fs: float, band: tuple, f_max: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Squared-envelope spectrum of band (lo, hi) up to f_max at the record's resolution fs/n:
    (freq, amplitude of the squared envelope (unit^2), highest valid cyclic frequency)."""
    n_bins = X.size - 1
    k0 = max(1, int(np.floor(band[0] * n / fs)))
    k1 = min(n_bins + 1, int(np.ceil(band[1] * n / fs)))
    m = k1 - k0
    L = _fft.next_fast_len(2 * m)           # room for the squared envelope's doubled bandwidth
    c = _complex_envelope(X, k0, k1, n, L)
    e = np.abs(c) ** 2
    w = symmetric_window("hann", L)
    E = _fft.rfft((e - e.mean()) * w)
    k_max = min(E.size - 1, int(np.ceil(f_max * n / fs)) + 2)
    freq = np.arange(k_max + 1) * (fs / n)
    return freq, np.abs(E[: k_max + 1]) * (2.0 / w.sum()), m * fs / n


def band_ses(rec, *, band, f_max: float | None = None, channel=None, fs: float | None = None):
    """Squared-envelope spectrum of one band computed in the frequency domain (ideal band-pass).

    Parameters
    ----------
    rec : Record or array_like
        The record.
    band : tuple of float
        (lo, hi) Hz.
    f_max : float, optional
        Highest envelope frequency (default the band's width).
    channel : str or int, optional
        The channel.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    tuple of numpy.ndarray
        (freq, values) at the record's resolution.

    Raises
    ------
    ParameterError
        For a band outside (0, fs/2).

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=2.0, seed=1)
    >>> freq, ses = vm.band_ses(rec, band=(2500, 4500), f_max=500.0)
    >>> bool(499.0 <= freq[-1] <= 501.0)   # up to f_max, at the record's 0.5 Hz resolution
    True
    """
    from ..core._validate import check_band
    rec = as_record(rec, fs=fs)
    i = response_channel(rec, channel)
    x = clean_signal(rec, i, min_samples=256)
    lo, hi = check_band(band, rec.fs)
    fmax = hi - lo if f_max is None else positive(f_max, "f_max")
    freq, amp, _ = ses_power(_fft.rfft(x - x.mean()), x.size, rec.fs, (lo, hi), fmax)
    return freq, amp
