"""Half-power bandwidth: of a ring-down's spectrum (bias-corrected, with a std) and of an FRF or
spectrum peak (the exact relations per form). The one place half-power lives."""

from __future__ import annotations

import numpy as np

from ..core._validate import check_band, memory_guard, name_index
from ..core.errors import FitError, ParameterError, warn_quality
from ..core.results import FRF, ModalEstimate, Spectrum
from ._decay import _halfpower_points, _hp_nfft, baseline_line, half_power_crossings, noise_std, spectral_peak
from .damping import _finish, _prepare, coulomb_extras

__all__ = ["half_power", "half_power_frf"]


MIN_SIGMA_T = 4.0       # half-power: the record must capture the decay (sigma * T >= 4)


@memory_guard
def half_power(obj, *, band=None, channel=None, start: float | None = None, fs: float | None = None) -> ModalEstimate:
    """Half-power bandwidth of an FRF or spectrum peak, or of a ring-down's spectrum.

    On an FRF or spectrum the exact relations per form apply (``half_power_frf``). On a ring-down the
    decay's power spectrum (zero-padded 16 x, no window) is a Lorentzian whose half-power points lie at
    wd +- sigma, so zeta = sigma / sqrt(wd^2 + sigma^2); refused when the record stops before the decay
    is over (sigma T < 4). The method gives no statistical std (NaN).

    Parameters
    ----------
    obj : FRF, Spectrum, Record or array_like
        What to measure.
    band : tuple of float, optional
        (lo, hi) Hz where the peak is searched.
    channel : str or int, optional
        The channel (the FRF's output).
    start : float, optional
        Time (s) where a free decay begins.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    ModalEstimate
        One mode; ``extras`` holds f1_hz, f2_hz and the lines across the band.

    Raises
    ------
    ParameterError
        For bad input.
    FitError
        When the bandwidth spans fewer than 3 lines, or the decay outlasts the record.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> h = vm.synth.modal_frf(np.linspace(1, 100, 4000), fn=[30.0], zeta=[0.02], shapes=[[1.0]], form="mobility")
    >>> round(float(vm.half_power(h).zeta[0]), 3)
    0.02
    """
    from ..core.record import Record
    if isinstance(obj, (FRF, Spectrum)):
        return half_power_frf(obj, band=band, output=0 if channel is None else channel)
    if not isinstance(obj, (Record, np.ndarray, list, tuple)):
        raise ParameterError(f"obj must be a ring-down Record (or array with fs), got {type(obj).__name__}")
    rec, idx, x, _, flags, i0, _ = _prepare(obj, channel, None, start, fs, trim=True, work=10)
    band = check_band(band, rec.fs)   # the peak is searched in the user's band (no band-pass: it would widen it)
    fsr = rec.fs
    n = x.size
    x = _hp_baseline_removed(x, fsr, band)
    f1, f2, phase, (sd_sum, sd_width) = _halfpower_points(x, fsr, band, details=True)
    sigma = np.pi * (f2 - f1)
    T = n / fsr
    if sigma * T < MIN_SIGMA_T:
        raise FitError(f"half_power: the record does not capture the decay (sigma*T = {sigma * T:.2f} < "
                       f"{MIN_SIGMA_T:g}): truncation widens the peak; use vm.ringdown or a longer record")
    if (f2 - f1) * _hp_nfft(n) / fsr < 8:
        flags.append("resolution_limited")  # under 8 spectral lines across the half-power band
    fd = 0.5 * (f1 + f2)
    if band is not None and not band[0] <= fd <= band[1]:
        raise FitError(f"half_power: the peak found ({fd:.4g} Hz) lies outside band={band}; no mode in that band")
    raw = _hp_modal(f1, f2)
    fn, zeta, bias = _hp_unbiased(raw, phase, fsr, n, band)
    if zeta > HP_MAX_ZETA:
        raise FitError(f"half_power: zeta {zeta:.3g} is above {HP_MAX_ZETA}, where the half-power estimate's bias "
                       "after its correction can exceed 0.5 %; use vm.ringdown (maximum likelihood, any damping)")
    # first order: sigma = pi (f2 - f1), fd = (f1 + f2) / 2
    sd_sigma, sd_fd = np.pi * sd_width, 0.5 * sd_sum
    wn = 2 * np.pi * fn
    fn_std = float(sd_fd)
    zeta_std = float(sd_sigma / wn)
    extras = {"f1_hz": float(f1), "f2_hz": float(f2), "sigma_T": float(sigma * T),
              "bias_removed_fn_hz": bias[0], "bias_removed_zeta": bias[1], "phase_rad": phase,
              "std": "first order, from the noise in the lines at the half-power crossings",
              "start_s": i0 / fsr + rec.t0}
    extras.update(coulomb_extras(rec, idx, i0, None, fn * np.sqrt(max(1 - zeta ** 2, 0.0)), noise_std(x, fsr), flags))
    return _finish(rec, idx, "halfpower", fn, zeta, fn_std, zeta_std, flags, extras)


def _hp_baseline_removed(x, fs, band):
    """The decay without its offset and drift, which would otherwise stand as the strongest
    low-frequency 'peak'. The line through the midpoints of consecutive extremes (``baseline_line``)
    holds while the decay per half cycle is small; a decay that has died within the record's first half
    (past 5 / sigma it is below 0.7 % of its start) leaves the line alone in the rest, fitted there."""
    y = x - baseline_line(x, fs, spectral_peak(x, fs, band))
    f1 = f2 = 0.0
    for trial in (y, x):   # a heavily damped decay biases the midpoints' line: then the plain record
        try:
            f1, f2 = _halfpower_points(trial, fs, band)
            break
        except FitError:
            continue
    t = np.arange(x.size) / fs
    t_dead = 5.0 / (np.pi * (f2 - f1)) if f2 > f1 else np.inf
    if t_dead < 0.5 * t[-1]:
        tail = t >= t_dead
        y = x - np.polyval(np.polyfit(t[tail], x[tail], 1), t)
    return y

def _hp_modal(f1, f2) -> tuple[float, float]:
    """(fn, zeta) of a decay whose spectrum's half-power points are f1, f2 (the Lorentzian's wd +- sigma)."""
    sigma, wd = np.pi * (f2 - f1), np.pi * (f1 + f2)
    wn = np.hypot(wd, sigma)
    return wn / (2 * np.pi), sigma / wn

HP_BIAS_ITERATIONS = 6

# Above this damping the bias left after the correction exceeds 0.5 % at some phases of the decay
# (noise-free, 9 phases: 0.1 % at zeta 0.2, 1.1 % at 0.22, 4 % at 0.25): refused.
HP_MAX_ZETA = 0.2

def _hp_unbiased(raw, phase, fs, n, band) -> tuple[float, float, tuple]:
    """(fn, zeta, (fn bias, zeta bias)): the half-power estimate less its bias. The Lorentzian ignores
    the mirror term at -wd, so the crossings (and the peak's phase) move with damping and the decay's
    phase (fn +1 % and zeta -1 % at zeta 0.1, +3.5 % and -3.4 % at 0.2, phase 0); the same procedure
    on the exact decay at the estimate gives the bias of each, found by a few fixed-point steps."""
    fn, zeta, ph = raw[0], raw[1], phase
    bias = (0.0, 0.0)
    for _ in range(HP_BIAS_ITERATIONS):
        if not (0 < zeta < 0.5):
            break
        wn = 2 * np.pi * fn
        t = np.arange(n) / fs
        model = np.exp(-zeta * wn * t) * np.cos(wn * np.sqrt(1 - zeta ** 2) * t + ph)
        try:
            m1, m2, m_phase, _ = _halfpower_points(model, fs, band, details=True)
        except FitError:
            break
        m = _hp_modal(m1, m2)
        bias = (m[0] - fn, m[1] - zeta)
        fn, zeta = raw[0] - bias[0], raw[1] - bias[1]
        ph = phase - float(np.angle(np.exp(1j * (m_phase - ph))))
    return float(fn), float(zeta), (float(bias[0]), float(bias[1]))

MIN_LINES_OK = 10    # half-power bandwidth spanned by fewer lines: resolution-limited

def _zeta_from_points(w1, w2, form):
    if form == "mobility":
        zeta = (w2 - w1) / (2 * np.sqrt(w1 * w2))
        wn = np.sqrt(w1 * w2)
        return zeta, wn
    rho = (w2 ** 2 - w1 ** 2) / (w2 ** 2 + w1 ** 2)
    zeta = np.sqrt(0.5 * (1 - 1 / np.sqrt(1 + rho ** 2)))
    if form == "accelerance":
        wn = np.sqrt(2 * (1 - 2 * zeta ** 2) / (1 / w1 ** 2 + 1 / w2 ** 2))
    else:
        wn = np.sqrt((w1 ** 2 + w2 ** 2) / (2 * (1 - 2 * zeta ** 2)))
    return zeta, wn

def half_power_frf(obj, *, band=None, output=0, input=0) -> ModalEstimate:
    """Half-power bandwidth of one FRF (or a magnitude spectrum) peak, with the exact relations.

    Mobility: zeta = (f2 - f1) / (2 sqrt(f1 f2)). Receptance and accelerance: with
    rho = (f2^2 - f1^2) / (f2^2 + f1^2), zeta = sqrt((1 - 1/sqrt(1 + rho^2)) / 2) (exact for one
    mode; (f2 - f1)/(2 f_peak) would overestimate by about 2 zeta^2 and 4 zeta^2). Crossings are
    interpolated in |H|^2. Refused when the lower half-power point does not exist (zeta > 0.38) or
    the bandwidth spans fewer than 3 lines; flagged below 10 lines and when another peak is near.
    A spectrum is treated as accelerance when it measures acceleration, else as receptance.
    """
    if isinstance(obj, FRF):
        o = name_index(obj.outputs, output, what="output")
        i = name_index(obj.inputs, input, what="input")
        freq, P, form = obj.freq, np.abs(obj.h[o, i]) ** 2, obj.form
        coh = obj.coherence[o] if obj.coherence is not None else None
    elif isinstance(obj, Spectrum):
        freq = obj.freq
        ch = name_index(obj.channels, output, what="channel")
        v = np.abs(obj.values[ch])
        P = v if obj.kind in ("psd", "power") else v ** 2
        form = "accelerance" if obj.quantity == "acceleration" else "receptance"
        coh = None
    else:
        raise ParameterError(f"half_power takes a vm.FRF, a vm.Spectrum or a ring-down vm.Record, "
                             f"got {type(obj).__name__}")
    if form == "unknown":
        form = "receptance"
    sel = np.ones(freq.size, bool) if band is None else (freq >= band[0]) & (freq <= band[1])
    sel &= freq > 0
    if not sel.any():
        raise ParameterError(f"band={band!r} holds no line of the data")
    # NaN lines outside the band (a swept sine leaves them where it had no power) do not matter, nor those
    # at the band's ends: the band shrinks to the measured lines between them
    finite = np.isfinite(P)
    k = np.flatnonzero(sel & finite)
    if k.size and finite[k[0]:k[-1] + 1][sel[k[0]:k[-1] + 1]].all():
        sel = sel & (np.arange(sel.size) >= k[0]) & (np.arange(sel.size) <= k[-1])
    if not finite[sel].all():
        raise ParameterError(f"the FRF/spectrum has NaN/inf lines inside band={band!r}: narrow the band")
    k = int(np.flatnonzero(sel)[np.argmax(P[sel])])
    f1, f2, lo, hi = half_power_crossings(freq, P, k, lower_msg="the lower half-power point does not exist "
                                          "(zeta > 0.38, or the peak sits at the start of the data)")
    if not finite[lo:hi + 1].all():
        raise ParameterError(f"the half-power band of the peak at {freq[k]:.6g} Hz reaches NaN/inf lines: the data "
                             "around the peak is incomplete")
    df = float(freq[1] - freq[0])
    lines = (f2 - f1) / df
    if lines < 3:
        raise FitError(f"half_power: the half-power bandwidth spans {lines:.2g} lines (< 3): the resolution "
                       f"({df:.4g} Hz) cannot measure zeta; use vm.fit_modes or a finer resolution")
    zeta, wn = _zeta_from_points(2 * np.pi * f1, 2 * np.pi * f2, form)
    flags = []
    if lines < MIN_LINES_OK:
        flags.append("resolution_limited")
    # another peak within three bandwidths?
    bw = f2 - f1
    near = (np.abs(freq - freq[k]) > bw) & (np.abs(freq - freq[k]) < 3 * bw + bw)
    if near.any():
        idx = np.flatnonzero(near)
        loc = [j for j in idx if 0 < j < P.size - 1 and P[j] >= P[j - 1] and P[j] >= P[j + 1] and P[j] > 0.25 * P[k]]
        if loc:
            flags.append("close_modes")
    if coh is not None and np.mean(coh[lo:hi + 1]) < 0.8:
        flags.append("low_coherence")
    est = ModalEstimate(fn=[wn / (2 * np.pi)], zeta=[zeta], fn_std=[np.nan], zeta_std=[np.nan], method="halfpower",
                        flags=tuple(flags), extras={"f1_hz": float(f1), "f2_hz": float(f2), "lines": float(lines),
                                                    "form": form, "peak_hz": float(freq[k]),
                                                    "std": "the half-power method gives no statistical std"})
    if flags:
        warn_quality(f"half_power: {', '.join(flags)} ({lines:.3g} lines across the half-power band)", stacklevel=3)
    return est
