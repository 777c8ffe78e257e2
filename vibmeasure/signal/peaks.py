"""Spectral peak picking with window-matched sub-bin interpolation, harmonic and sideband families.

A stationary tone at bin k + d (0 <= d <= 1/2) gives neighbouring magnitudes whose ratio is
W(1 - d) / W(d), W the magnitude of the window's own transform (with the spectrum's zero
padding). Solving that equation with the actual window - not a table, not a parabola - locates
the tone to round-off for any window; the amplitude is then corrected by W(0) / W(d), which
removes the scalloping loss. Spectra without window information fall back to a Gaussian
(log-parabola) fit.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.optimize import brentq
from scipy.signal import find_peaks

from ..core._validate import check_band, name_index
from ..core.errors import ParameterError
from ..core.results import Peaks, Spectrum

__all__ = ["pick_peaks", "harmonic_family", "sideband_family", "interpolate_peak"]


@lru_cache(maxsize=32)
def _window_cached(key, nperseg):
    from .spectral import get_window
    return get_window(key if not isinstance(key, list) else tuple(key), nperseg)


def _W(win, nfft, d):
    """|sum w[n] exp(-i 2 pi d n / nfft)|: the window's transform d bins from its centre."""
    n = np.arange(win.size)
    return abs(np.sum(win * np.exp(-2j * np.pi * d * n / nfft)))


@lru_cache(maxsize=32)
def _cosine_sum(key, nperseg):
    """The coefficients c_m of a periodic cosine-sum window w[n] = sum_m c_m cos(2 pi m n / N)
    (Hann, Hamming, Blackman, Blackman-Harris, Nuttall, flat top, boxcar), or None for any other
    window: its DFT is zero beyond the few lines the cosine terms occupy."""
    win = _window_cached(key, nperseg)
    spec = np.fft.rfft(win) / win.size
    m_max = min(11, spec.size)
    if np.max(np.abs(spec[m_max:]), initial=0.0) > 1e-12 * abs(spec[0]):
        return None
    c = spec[:m_max].real * np.r_[1.0, 2.0 * np.ones(m_max - 1)]
    if np.max(np.abs(spec[:m_max].imag)) > 1e-12 * abs(spec[0]):
        return None
    c[np.abs(c) < 1e-14 * abs(c[0])] = 0.0  # rounding of the window's own DFT
    return tuple(float(v) for v in np.trim_zeros(c, "b"))


def _W_cos(c, N, nfft, d):
    """|W(d)| of a cosine-sum window in closed form: each cosine term is two shifted Dirichlet kernels
    sum_n exp(-i x n) = exp(-i x (N-1)/2) sin(N x / 2) / sin(x / 2). O(number of terms), exact."""
    import cmath
    import math
    th = 2 * math.pi * d / nfft

    def dirichlet(x):
        s = math.sin(0.5 * x)
        core = N if abs(s) < 1e-300 else math.sin(0.5 * N * x) / s
        return cmath.exp(-0.5j * x * (N - 1)) * core

    total = c[0] * dirichlet(th)
    for m in range(1, len(c)):
        ph = 2 * math.pi * m / N
        total += 0.5 * c[m] * (dirichlet(th - ph) + dirichlet(th + ph))
    return abs(total)


def _W_cos_many(c, N, nfft, d):
    """``_W_cos`` at many offsets at once (for the inverse table)."""
    d = np.asarray(d, float)
    th = 2 * np.pi * d / nfft

    def dirichlet(x):
        s = np.sin(0.5 * x)
        small = np.abs(s) < 1e-300
        core = np.where(small, float(N), np.sin(0.5 * N * x) / np.where(small, 1.0, s))
        return np.exp(-0.5j * x * (N - 1)) * core

    total = c[0] * dirichlet(th)
    for m in range(1, len(c)):
        ph = 2 * np.pi * m / N
        total = total + 0.5 * c[m] * (dirichlet(th - ph) + dirichlet(th + ph))
    return np.abs(total)


@lru_cache(maxsize=32)
def _inverse_ratio(c, N, nfft):
    """d as a function of the neighbour ratio alpha = W(1 - d) / W(d), 0 <= d <= 1/2, for one window:
    a cubic spline through 513 exact points (its start is within 1e-9 bin; one Newton step on the exact
    ratio then reaches round-off), or None where the ratio is not monotone."""
    from scipy.interpolate import CubicSpline
    d = np.linspace(0.0, 0.5, 513)
    alpha = _W_cos_many(c, N, nfft, 1.0 - d) / _W_cos_many(c, N, nfft, d)
    if not np.all(np.isfinite(alpha)) or not np.all(np.diff(alpha) > 0):
        return None
    return CubicSpline(alpha, d)


def _linear_magnitude(spec: Spectrum, ch: int) -> np.ndarray:
    v = np.abs(spec.values[ch])
    return np.sqrt(v) if spec.kind in ("psd", "power") else v


def interpolate_peak(mag: np.ndarray, k: int, *, window=None, nperseg=None, nfft=None) -> tuple[float, float]:
    """Sub-bin position (in bins) and scalloping-corrected magnitude of the peak at bin k."""
    if not 0 < k < mag.size - 1:
        return float(k), float(mag[k])
    a, b, c = mag[k - 1], mag[k], mag[k + 1]
    if window is not None and nperseg and nfft:
        try:
            win = _window_cached(window if not isinstance(window, tuple) else window, int(nperseg))
        except (ParameterError, TypeError):
            win = None
        if win is not None:
            side = 1 if c >= a else -1
            alpha = (c if side > 0 else a) / b if b > 0 else 0.0
            key = window if not isinstance(window, list) else tuple(window)
            try:
                coef = _cosine_sum(key, int(nperseg))
            except TypeError:  # an unhashable window (an array): evaluate its transform directly
                coef = None
            if coef is not None:  # closed form: O(1) per evaluation, whatever the segment length
                Wd = lambda d: _W_cos(coef, int(nperseg), nfft, d)  # noqa: E731
            else:
                Wd = lambda d: _W(win, nfft, d)  # noqa: E731
            w0 = Wd(0.0)
            f = lambda d: Wd(1.0 - d) / Wd(d) - alpha  # noqa: E731
            inv = _inverse_ratio(coef, int(nperseg), int(nfft)) if coef is not None else None
            if inv is not None and inv.x[0] <= alpha <= inv.x[-1]:
                d = float(inv(alpha))                      # within 1e-9 bin
                slope = float(inv(alpha, 1))               # dd / dalpha
                d = min(max(d - f(d) * slope, 0.0), 0.5)   # one Newton step on the exact ratio
                return k + side * d, b * w0 / Wd(d)
            lo_v, hi_v = f(0.0), f(0.5)
            if lo_v <= 0 <= hi_v:
                d = brentq(f, 0.0, 0.5, xtol=1e-12) if lo_v < 0 < hi_v else (0.0 if lo_v == 0 else 0.5)
                return k + side * d, b * w0 / Wd(d)
    # Gaussian interpolation on log magnitude (exact for a Gaussian window)
    la, lb, lc = np.log(np.maximum([a, b, c], 1e-300))
    den = la - 2 * lb + lc
    d = 0.5 * (la - lc) / den if den < 0 else 0.0
    return k + d, float(np.exp(lb - 0.25 * (la - lc) * d))


def pick_peaks(spec: Spectrum, *, n: int | None = None, prominence: float | None = None, band=None,
               min_distance_hz: float | None = None, channel=0) -> Peaks:
    """Peaks of one channel of a spectrum, strongest first, located and scaled to a fraction of a bin.

    Each peak is refined with the window's own main-lobe shape (sub-bin frequency and amplitude).

    Parameters
    ----------
    spec : Spectrum
        An amplitude or power spectrum.
    n : int, optional
        Keep the n strongest.
    prominence : float, optional
        In the spectrum's unit (default 10 x the median level: about 20 dB above the floor).
    band : tuple of float, optional
        (lo, hi) Hz to search.
    min_distance_hz : float, optional
        Smallest distance between two peaks.
    channel : str or int
        The channel.

    Returns
    -------
    Peaks
        ``freq``, ``amplitude``, ``prominence``; ``to_frame()`` gives a table.

    Raises
    ------
    ParameterError
        For an unknown channel or a band outside the spectrum.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(4096) / 1024.0
    >>> rec = vm.Record.from_array(np.sin(2 * np.pi * 100.3 * t), fs=1024.0)
    >>> round(float(vm.pick_peaks(vm.amplitude_spectrum(rec), n=1).freq[0]), 2)
    100.3
    """
    if not isinstance(spec, Spectrum):
        raise ParameterError(f"spec must be a vm.Spectrum, got {type(spec).__name__}")
    if spec.kind in ("csd", "coherence"):
        raise ParameterError(f"peaks are picked on amplitude, power, PSD or envelope spectra, not {spec.kind!r}")
    ch = name_index(spec.channels, channel)
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1):
        raise ParameterError(f"n={n!r} must be None or an integer >= 1")
    vals = np.abs(spec.values[ch])
    if not np.isfinite(vals).all():
        raise ParameterError("the spectrum has NaN/inf lines")
    df = spec.df
    fs = spec.params.get("fs", 2 * spec.freq[-1])
    sel = np.ones(vals.size, bool)
    if band is not None:
        lo, hi = check_band(band, fs)
        sel = (spec.freq >= lo) & (spec.freq <= hi)
    dist = None
    if min_distance_hz is not None:
        if not np.isfinite(min_distance_hz) or min_distance_hz <= 0:
            raise ParameterError(f"min_distance_hz={min_distance_hz!r} must be > 0")
        dist = max(1, int(round(min_distance_hz / df)))
    try:
        prom = float(10 * np.median(vals[1:])) if prominence is None else float(prominence)
    except (TypeError, ValueError):
        raise ParameterError(f"prominence={prominence!r} must be a number") from None
    if not np.isfinite(prom) or prom < 0:
        raise ParameterError(f"prominence={prominence!r} must be a finite number >= 0")
    idx, props = find_peaks(vals, prominence=prom, distance=dist)
    keep = sel[idx]
    idx, proms = idx[keep], props["prominences"][keep]
    order = np.argsort(-vals[idx])
    if n is not None:
        order = order[:n]
    idx, proms = idx[order], proms[order]
    mag = np.sqrt(vals) if spec.kind in ("psd", "power") else vals    # _linear_magnitude, |values| reused
    p = spec.params
    freqs, amps = [], []
    for k in idx:
        pos, m = interpolate_peak(mag, int(k), window=p.get("window"), nperseg=p.get("nperseg"), nfft=p.get("nfft"))
        freqs.append(spec.freq[0] + pos * df)
        amps.append(m ** 2 if spec.kind in ("psd", "power") else m)
    return Peaks(np.asarray(freqs), np.asarray(amps), np.asarray(proms, float), channel=spec.channels[ch],
                 unit=spec.unit, kind=spec.kind)


def _line_near(spec: Spectrum, ch: int, f: float, tol: float, floor: float):
    """The strongest local maximum within f +- tol, interpolated; None below floor."""
    sel = np.flatnonzero(np.abs(spec.freq - f) <= tol)
    if sel.size == 0:
        return None
    vals = np.abs(spec.values[ch])
    k = int(sel[np.argmax(vals[sel])])
    if vals[k] <= floor or k in (0, vals.size - 1) or not (vals[k] >= vals[k - 1] and vals[k] >= vals[k + 1]):
        return None
    mag = _linear_magnitude(spec, ch)
    p = spec.params
    pos, m = interpolate_peak(mag, k, window=p.get("window"), nperseg=p.get("nperseg"), nfft=p.get("nfft"))
    return spec.freq[0] + pos * spec.df, (m ** 2 if spec.kind in ("psd", "power") else m)


def _channel_floor(spec, channel, floor):
    """The channel's row and the level a family line must exceed (default 5x the median)."""
    if not isinstance(spec, Spectrum):
        raise ParameterError(f"spec must be a vm.Spectrum, got {type(spec).__name__}")
    ch = name_index(spec.channels, channel)
    vals = np.abs(spec.values[ch])
    return ch, (float(5 * np.median(vals[1:])) if floor is None else floor)


def harmonic_family(spec: Spectrum, f0: float | None = None, *, n_harmonics: int = 10, channel=0,
                    rtol: float = 2e-3, floor: float | None = None) -> dict:
    """Harmonics 1X, 2X, ... of a fundamental: given, or the one whose harmonics explain most peaks.

    Each harmonic is searched within max(1.5 df, rtol x k f0) of k f0.

    Parameters
    ----------
    spec : Spectrum
        An amplitude spectrum.
    f0 : float, optional
        The fundamental in Hz (default: found from the strongest peaks).
    n_harmonics : int
        How many harmonics to look for.
    channel : str or int
        The channel.
    rtol : float
        Relative search width per harmonic.
    floor : float, optional
        A line below it counts as not found (default: from the spectrum's median).

    Returns
    -------
    dict
        {"f0_hz", "lines": [{order, expected_hz, found_hz, amplitude}], "found": count}.

    Raises
    ------
    ParameterError
        For an unknown channel or a fundamental outside the spectrum.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(8192) / 1024.0
    >>> x = sum(np.sin(2 * np.pi * k * 30.0 * t) / k for k in (1, 2, 3))
    >>> vm.harmonic_family(vm.amplitude_spectrum(vm.Record.from_array(x, fs=1024.0)), 30.0)["found"] >= 3
    True
    """
    if isinstance(n_harmonics, bool) or not isinstance(n_harmonics, (int, np.integer)) or n_harmonics < 1:
        raise ParameterError(f"n_harmonics={n_harmonics!r} must be an integer >= 1")
    ch, floor = _channel_floor(spec, channel, floor)

    def fam(f):
        lines = []
        for k in range(1, n_harmonics + 1):
            fk = k * f
            if fk > spec.freq[-1]:
                break
            hit = _line_near(spec, ch, fk, max(1.5 * spec.df, rtol * fk), floor)
            lines.append({"order": k, "expected_hz": fk, "found_hz": hit[0] if hit else None,
                          "amplitude": hit[1] if hit else None})
        return lines

    if f0 is None:
        pk = pick_peaks(spec, n=8, channel=ch)
        if len(pk) == 0:
            raise ParameterError("no peak stands out of the spectrum: give f0")
        best, best_score = None, -1.0
        for fp in pk.freq:
            for m in (1, 2, 3):
                f = fp / m
                if f < 2 * spec.df:
                    continue
                lines = fam(f)
                score = sum(np.sqrt(l["amplitude"]) for l in lines if l["amplitude"]) * \
                    (1 if lines and lines[0]["amplitude"] else 0.5)
                if score > best_score * 1.0001:
                    best, best_score = f, score
        f0 = best
        # refine f0 from the found harmonics (least squares through the origin)
        lines = fam(f0)
        ks = np.array([l["order"] for l in lines if l["found_hz"]], float)
        fsd = np.array([l["found_hz"] for l in lines if l["found_hz"]], float)
        if ks.size:
            f0 = float(ks @ fsd / (ks @ ks))
    lines = fam(float(f0))
    return {"f0_hz": float(f0), "lines": lines, "found": sum(l["found_hz"] is not None for l in lines)}


def sideband_family(spec: Spectrum, carrier: float, spacing: float, *, n: int = 3, channel=0,
                    floor: float | None = None) -> dict:
    """Lines at carrier + k x spacing, k = -n..n, each searched within max(1.5 df, spacing / 10).

    Parameters
    ----------
    spec : Spectrum
        An amplitude spectrum.
    carrier : float
        The carrier in Hz (a gear mesh, a bearing line).
    spacing : float
        The sideband spacing in Hz (a shaft speed).
    n : int
        Sidebands on each side.
    channel : str or int
        The channel.
    floor : float, optional
        A line below it counts as not found.

    Returns
    -------
    dict
        {"carrier_hz", "spacing_hz", "lines": [{order, expected_hz, found_hz, amplitude}], "found": how many
    sidebands (the carrier not counted) stand out}.

    Raises
    ------
    ParameterError
        For an unknown channel or lines outside the spectrum.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(8192) / 1024.0
    >>> x = (1 + 0.5 * np.cos(2 * np.pi * 10.0 * t)) * np.sin(2 * np.pi * 200.0 * t)
    >>> vm.sideband_family(vm.amplitude_spectrum(vm.Record.from_array(x, fs=1024.0)), 200.0, 10.0, n=1)["found"]
    2
    """
    if not (np.isfinite(carrier) and np.isfinite(spacing)) or carrier <= 0 or spacing <= 0:
        raise ParameterError(f"carrier={carrier!r} and spacing={spacing!r} must be > 0 Hz")
    ch, floor = _channel_floor(spec, channel, floor)
    tol = max(1.5 * spec.df, spacing / 10)
    lines = []
    for k in range(-n, n + 1):
        fk = carrier + k * spacing
        if not 0 < fk < spec.freq[-1]:
            continue
        hit = _line_near(spec, ch, fk, tol, floor)
        lines.append({"order": k, "expected_hz": fk, "found_hz": hit[0] if hit else None,
                      "amplitude": hit[1] if hit else None})
    return {"carrier_hz": carrier, "spacing_hz": spacing, "lines": lines,
            "found": sum(l["found_hz"] is not None and l["order"] != 0 for l in lines)}
