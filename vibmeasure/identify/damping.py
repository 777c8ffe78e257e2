"""Classic damping estimates from a free decay: logarithmic decrement, Hilbert envelope and
half-power bandwidth of the ring-down spectrum. Each returns a ModalEstimate for one mode, so it
can be compared with the maximum-likelihood :func:`~vibmeasure.ringdown` on the same record.
"""

from __future__ import annotations

import numpy as np
from scipy import signal as _sig

from ..core._validate import as_record, check_band, check_memory, clean_signal, memory_guard, response_channel
from ..core.errors import FitError, ParameterError, warn_quality
from ..core.results import ModalEstimate
from ._decay import (_halfpower_points, baseline_line, clipped_mask, cycle_peaks, decay_start, detrend_linear,
                     noise_std, spectral_peak, trim_to_decay)
from ._rd_checks import coulomb_signature

__all__ = ["log_decrement", "hilbert_decay", "zeta_from_delta"]

PEAK_SNR = 10.0         # log decrement: peaks below 10x the noise std are excluded
ENVELOPE_DB = 20.0      # Hilbert: fit the envelope where it is 20 dB above the in-band noise
HILBERT_FLOOR = 1e-4    # Hilbert: dynamic range the analytic signal of a finite record supports


def zeta_from_delta(delta):
    """Exact damping ratio from the logarithmic decrement: zeta = delta / sqrt(4 pi^2 + delta^2).

    Parameters
    ----------
    delta : float or array_like
        Logarithmic decrement ln(A_i / A_{i+1}).

    Returns
    -------
    float or numpy.ndarray

    Raises
    ------
    ParameterError
        For a negative or non-finite decrement.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(float(vm.zeta_from_delta(0.1257)), 4)
    0.02
    """
    try:
        delta = np.asarray(delta, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"delta={delta!r} must be a number or numbers") from None
    if not np.all(np.isfinite(delta)) or np.any(delta < 0):
        raise ParameterError("delta must be finite and >= 0: a negative decrement is a growing oscillation")
    return delta / np.sqrt(4 * np.pi ** 2 + delta ** 2)


def _prepare(rec, channel, band, start, fs, *, trim=False, work=8):
    """Channel, decay start, optional band-pass; with ``trim`` the record is cut where its decay
    has long sunk into the noise (after the band-pass when there is one: the band's own floor).
    ``work`` is the number of record-sized arrays the caller needs, for the memory check."""
    rec = as_record(rec, fs=fs)
    idx = response_channel(rec, channel)
    check_memory(work * 8.0 * rec.n_samples, "damping estimate", rec.n_samples)
    x = clean_signal(rec, idx, min_samples=16)
    band = check_band(band, rec.fs)
    flags = []
    if start is None:
        i0, _ = decay_start(rec, idx, x)
    else:
        from ..core._validate import positive
        i0 = int(round(positive(start, "start", allow_zero=True) * rec.fs))
        if not 0 <= i0 < x.size - 16:
            raise ParameterError(f"start={start} s is outside the record (0..{rec.duration:g} s)")
    x = x[i0:]
    if trim and band is None:
        x = x[:trim_to_decay(x, rec.fs, flags)]
    if clipped_mask(x).any():
        flags.append("clipped")
    skip = 0
    if band is not None:
        sos = _sig.butter(4, band if band[0] > 0 else band[1], btype="bandpass" if band[0] > 0 else "lowpass",
                          fs=rec.fs, output="sos")
        # an offset or drift would make the filter ring at the band edge at both ends: remove it first
        x = _sig.sosfiltfilt(sos, detrend_linear(x))
        # the filter's ringing at both ends: wait until its slowest pole has decayed by e^-7
        r_min = float(np.min(-np.log(np.abs(_sig.sos2zpk(sos)[1])))) * rec.fs
        skip = int(min(x.size // 4, 7 * rec.fs / r_min))
        if trim:
            x = x[:max(trim_to_decay(x, rec.fs, flags), min(x.size, 4 * skip + 64))]
    return rec, idx, x, band, flags, i0, skip


def _finish(rec, idx, method, fn, zeta, fn_std, zeta_std, flags, extras):
    if fn and fn >= 0.499 * rec.fs:
        raise FitError(f"{method}: the decay's frequency {fn:.4g} Hz is at the Nyquist limit (fs/2 = {rec.fs / 2:g} Hz): "
                       "aliased or unresolved; sample faster (at least 10 x the frequency)")
    if fn and fn * rec.duration < 1:
        raise FitError(f"{method}: {fn:.4g} Hz completes less than one cycle in the {rec.duration:g} s record: below "
                       "the frequency resolution")
    if not np.isfinite(zeta) or zeta <= 0:
        raise FitError(f"{method}: the amplitude does not decay (zeta = {zeta:.3g}); not a free decay")
    if fn and rec.fs / fn < 10:
        flags.append("resolution_limited")
    est = ModalEstimate(fn=[fn], zeta=[zeta], fn_std=[fn_std], zeta_std=[zeta_std], method=method,
                        flags=tuple(flags), unit=rec.channels[idx].unit,
                        extras=dict(extras, channel=rec.channels[idx].name))
    serious = [f for f in est.flags if f != "noise_floor"]
    if serious:
        warn_quality(f"{method}: quality flags {serious}", stacklevel=4)
    return est


@memory_guard
def log_decrement(rec, *, channel=None, n: int | None = None, band=None, start: float | None = None,
                  fs: float | None = None) -> ModalEstimate:
    """Damping from the logarithmic decrement of successive cycle amplitudes.

    Each half-cycle extreme is refined by a local parabola and paired with the next extreme of opposite
    sign, so offsets and drift cancel; peaks below 10 x the noise std are left out. Without ``n`` the
    decrement is the slope of a weighted regression of ln(amplitude) over all usable cycles; with ``n``
    the mean of ln(A_i / A_{i+n}) / n. zeta = delta / sqrt(4 pi^2 + delta^2) (exact).

    Parameters
    ----------
    rec : Record or array_like
        The ring-down.
    channel : str or int, optional
        The response channel.
    n : int, optional
        Cycles between the amplitudes compared.
    band : tuple of float, optional
        (lo, hi) Hz band-pass first (one mode).
    start : float, optional
        Time (s) where the free decay begins.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    ModalEstimate
        One mode, with its std.

    Raises
    ------
    ParameterError
        For bad input.
    FitError
        For too few cycles above the noise.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=1000.0, duration=10.0, snr_db=60, seed=1)
    >>> round(float(vm.log_decrement(rec).zeta[0]), 3)
    0.02
    """
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1):
        raise ParameterError(f"n={n!r} must be None (regression) or an integer >= 1 (cycles apart)")
    rec, idx, x, band, flags, i0, skip = _prepare(rec, channel, band, start, fs, trim=True)
    fsr = rec.fs
    fd0 = spectral_peak(x[skip: x.size - skip] if skip else x, fsr, band)  # without the filter's end effects
    x = x - baseline_line(x, fsr, fd0)  # offset and drift would shift the extremes in time
    noise = max(noise_std(x, fsr), 1e-9 * float(np.max(np.abs(x))))
    tp, ap = _same_sign_peaks(x, fsr, fd0, skip, noise, flags)
    m = tp.size
    need = 3 if n is None else n + 2
    if m < need:
        raise FitError(f"log_decrement: {m} cycle(s) above {PEAK_SNR:g}x the noise; at least {need} are needed")
    if m < 5:
        flags.append("few_cycles")
    Td, Td_std = _period(tp, fd0)
    delta, delta_std = _decrement(tp, ap, Td, Td_std, n)
    if not delta > 0:
        raise FitError(f"log_decrement: the peaks do not decay (decrement {delta:.3g}): a driven or growing "
                       "response, or a record that starts before the decay")
    zeta = float(zeta_from_delta(delta))
    dz = 4 * np.pi ** 2 / (4 * np.pi ** 2 + delta ** 2) ** 1.5
    zeta_std = float(dz * delta_std)
    fd = 1.0 / Td
    if abs(fd - fd0) > 0.05 * fd0:
        raise FitError(f"log_decrement: the extremes repeat at {fd:.4g} Hz but the spectrum peaks at {fd0:.4g} Hz"
                       f"{f' in band={band}' if band is not None else ''}: they do not belong to one mode (close "
                       "modes, a band edge or noise); narrow the band around the mode or use vm.ringdown")
    fn = fd / np.sqrt(1 - zeta ** 2)
    fn_std = float(fn * Td_std / Td)
    others = _other_modes(x, fsr, fd0, zeta, band)
    if others:
        flags.append("several_modes")
    extras = {"delta": float(delta), "delta_std": float(delta_std), "n_cycles": int(m), "cycles_apart": n,
              "noise_std": noise, "start_s": i0 / fsr + rec.t0, "other_modes_hz": others}
    extras.update(coulomb_extras(rec, idx, i0, x if band is not None else None, fd0, noise, flags))
    return _finish(rec, idx, "logdec", fn, zeta, fn_std, zeta_std, flags, extras)


def coulomb_extras(rec, idx, i0, x, fd, noise, flags) -> dict:
    """A dry-friction decay (its envelope falls linearly and stops) has no viscous zeta: the flag
    ``coulomb_friction`` and the friction decay per cycle, for every classic estimator. The test needs
    the motion after it stopped: the channel from the decay's start, not trimmed to the decay (``x``,
    the band-passed decay, when the estimator band-passes)."""
    if x is None:
        raw = np.asarray(rec.data[idx, i0:], float)
        x = raw - np.median(raw)   # a line through the extremes would tilt the stuck tail
    sig = coulomb_signature(x, rec.fs, fd, noise)
    if sig is None:
        return {}
    flags.append("coulomb_friction")
    return {"friction_decay_per_cycle": sig["decay_per_cycle"],
            "friction_decay_per_cycle_std": sig["decay_per_cycle_std"]}


# Another decaying mode whose spectral peak stands at least OTHER_MODE_RATIO of the analysed mode's (and
# 20 dB over the noise) makes the cycle extremes beat, and the decrement mixes the two. Measured: a
# second mode at 25 Hz beside one at 10 Hz (zeta 0.02 each, 40 dB, 10 seeds) reads zeta -0.4, +3.5,
# +10.8 and +29.7 % off at initial amplitude ratios 0.1, 0.3, 0.5 and 1: all 40 flagged; the 3-mode
# sample record (zeta 21 % high) flagged; no single-mode decay of 203 (zeta 0.001-0.1, 20-60 dB) flagged.
OTHER_MODE_RATIO = 0.03


def _other_modes(x, fs, fd, zeta, band) -> list:
    """Frequencies (Hz) of other decaying modes in the analysed range: peaks of the decay's amplitude
    spectrum outside the analysed mode's skirt (three of the record's resolution lines, or three
    half-power bandwidths) whose prominence is at least OTHER_MODE_RATIO of its peak (the ripple that
    the trimmed record's end leaves on the skirts has next to none) and 20 dB over the noise."""
    from scipy.signal import find_peaks
    nfft = int(2 ** np.ceil(np.log2(4 * x.size)))
    # a record that stops before the decay is over leaks a ripple of sidelobes beside the mode: the
    # second half fades out (a half cosine), the start keeps its weight (a faster mode lives there)
    fade = np.ones(x.size)
    h = x.size // 2
    fade[h:] = 0.5 * (1 + np.cos(np.pi * np.arange(x.size - h) / max(x.size - h, 1)))
    A = np.abs(np.fft.rfft(x * fade, nfft))
    f = np.fft.rfftfreq(nfft, 1 / fs)
    k0 = int(round(fd * nfft / fs))
    main = float(A[max(k0 - 2, 0): k0 + 3].max())
    lo, hi = band if band is not None else (0.0, fs / 2)
    skirt = max(4 * fs / x.size, 6 * zeta * fd)
    floor = float(np.median(A[(f > lo) & (f <= hi)])) if np.any((f > lo) & (f <= hi)) else 0.0
    # a mode's peak stands out of the noise too: 20 dB over the spectrum's median (noise peaks reach ~10 dB)
    peaks, _ = find_peaks(A, prominence=max(OTHER_MODE_RATIO * main, 10 * floor))
    peaks = peaks[(f[peaks] > lo) & (f[peaks] <= hi) & (np.abs(f[peaks] - fd) > skirt)]
    return [float(f[k]) for k in peaks]


def _same_sign_peaks(x, fs, fd0, skip, noise, flags):
    """Cycle amplitudes two half-cycles apart (peaks, or troughs: they share no extreme except at the
    ends), outside the filter's end effects, up to the first one below PEAK_SNR x the noise."""
    tp, ap = cycle_peaks(x, fs, fd0)
    keep = (tp >= skip / fs) & (tp <= (x.size - skip) / fs)
    tp, ap = tp[keep], ap[keep]
    h = np.round((tp - tp[0]) * 2 * fd0).astype(int) if tp.size else np.empty(0, int)
    par = h % 2 == 0
    tp, ap = tp[par], ap[par]
    below = np.flatnonzero(ap <= PEAK_SNR * noise)
    if below.size:
        flags.append("noise_floor")
        tp, ap = tp[:below[0]], ap[:below[0]]
    return tp, ap


def _period(tp, fd0):
    """Damped period and its std: cycle numbers from the times (robust to a missed extreme), then the
    period as the slope of time on cycle number."""
    m = tp.size
    k = np.round((tp - tp[0]) * fd0).astype(float)
    Td, t_icpt = np.polyfit(k, tp, 1)
    rt = tp - (Td * k + t_icpt)
    Td_std = np.sqrt(rt @ rt / max(m - 2, 1) / np.sum((k - k.mean()) ** 2)) if m > 2 else np.nan
    return Td, Td_std


def _decrement(tp, ap, Td, Td_std, n):
    """delta and its std: the weighted regression of ln A over all cycles (n None), or the mean of
    ln(A_i / A_{i+n}) / n over cycles n apart."""
    m = tp.size
    if n is None:
        wts = ap ** 2
        W = wts.sum()
        tbar = (wts * tp).sum() / W
        y = np.log(ap)
        ybar = (wts * y).sum() / W
        sxx = (wts * (tp - tbar) ** 2).sum()
        slope = (wts * (tp - tbar) * (y - ybar)).sum() / sxx
        res = y - (ybar + slope * (tp - tbar))
        s2 = (wts * res ** 2).sum() / max(m - 2, 1)
        sigma, sigma_std = -slope, np.sqrt(s2 / sxx) if m > 2 else np.nan
        return sigma * Td, np.hypot(sigma_std * Td, sigma * Td_std)
    d = np.log(ap[:-n] / ap[n:]) / n
    # pairs sharing cycles are correlated: about m/n independent ones
    return float(d.mean()), float(d.std(ddof=1) / np.sqrt(max(d.size / n, 1))) if d.size > 1 else np.nan


@memory_guard
def hilbert_decay(rec, *, channel=None, band=None, start: float | None = None,
                  fs: float | None = None) -> ModalEstimate:
    """Damping from the Hilbert envelope of the band-passed decay.

    The mode is band-passed into its analytic signal (zero-phase Butterworth; default +-30 % around the
    strongest line), the log-envelope fitted by weighted least squares where it stands 20 dB above the
    in-band noise, and the damped frequency taken from the unwrapped phase's slope.

    Parameters
    ----------
    rec : Record or array_like
        The ring-down.
    channel : str or int, optional
        The response channel.
    band : tuple of float, optional
        (lo, hi) Hz of the band-pass.
    start : float, optional
        Time (s) where the free decay begins.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    ModalEstimate
        One mode, with its std.

    Raises
    ------
    ParameterError
        For bad input.
    FitError
        For too short a decay above the noise.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=1000.0, duration=10.0, snr_db=60, seed=1)
    >>> round(float(vm.hilbert_decay(rec).zeta[0]), 3)
    0.02
    """
    rec, idx, x, _, flags, i0, _ = _prepare(rec, channel, None, start, fs, trim=True, work=10)
    fsr = rec.fs
    fd0 = spectral_peak(x, fsr, check_band(band, fsr))
    band = _hilbert_band(x, fsr, fd0, check_band(band, fsr))
    env, ph, t, skip = _demodulate(x, fsr, band, fd0)
    ok = _envelope_span(x, fsr, band, env, skip, flags)
    if int(ok.sum()) < 3 * fsr / fd0:
        raise FitError(f"hilbert_decay: the envelope is {ENVELOPE_DB:g} dB above the noise for less than "
                       "3 cycles after the filter's end effects")
    wn, zeta, fn_std, zeta_std = _envelope_fit(t[ok], env[ok], ph[ok], fsr, band[1] - band[0])
    if fsr * (t[ok][-1] - t[ok][0]) * fd0 / fsr < 5:
        flags.append("few_cycles")
    extras = {"band_hz": list(band), "fit_from_s": float(t[ok][0]), "fit_to_s": float(t[ok][-1]),
              "start_s": i0 / fsr + rec.t0}
    extras.update(coulomb_extras(rec, idx, i0, x, fd0, noise_std(x, fsr), flags))
    return _finish(rec, idx, "hilbert", wn / (2 * np.pi), zeta, fn_std, zeta_std, flags, extras)


def _hilbert_band(x, fs, fd0, b0):
    """The given band, or +-30 % around the strongest line, wider for a heavily damped mode (the
    filter must ring out faster than the decay)."""
    if b0 is not None:
        return b0
    try:
        f1, f2 = _halfpower_points(x, fs, None)
        width = max(0.3, 5 * (f2 - f1) / fd0)
    except FitError:
        width = 0.3
    return (max(fd0 * (1 - width), fd0 * 0.05), min(fd0 * (1 + width), 0.49 * fs))


def _demodulate(x, fs, band, fd0):
    """Envelope and phase of the band's analytic signal by complex demodulation: shift the band's
    centre to DC, zero-phase low-pass to half the band, shift back. Unlike an FFT Hilbert transform
    this is exact for a one-sided decay once the filter's own transient has died out (no 1/t tails
    from the abrupt start). The envelope is 2|zb| and the phase unwrap(angle(zb)) + 2 pi f0 t: the
    shifted-back signal is never formed. Also the samples to skip at each end: the filter's slowest
    pole must have died out (e^-7) and 3 cycles passed."""
    bw = band[1] - band[0]
    f0 = 0.5 * (band[0] + band[1])
    t = np.arange(x.size) / fs
    sos = _sig.butter(4, 0.5 * bw, btype="lowpass", fs=fs, output="sos")
    arg = 2 * np.pi * f0 * t
    zb = _sig.sosfiltfilt(sos, x * np.cos(arg)) - 1j * _sig.sosfiltfilt(sos, x * np.sin(arg))
    env = 2 * np.abs(zb)
    ph = np.unwrap(np.angle(zb))
    del zb
    ph += arg
    del arg
    r_min = float(np.min(-np.log(np.abs(_sig.sos2zpk(sos)[1])))) * fs
    skip = int(min(x.size // 4, max(3 * fs / fd0, 7 * fs / r_min)))
    return env, ph, t, skip


def _envelope_span(x, fs, band, env, skip, flags):
    """The samples fitted: past the filter's end effects, and while the envelope stands ENVELOPE_DB
    above the in-band noise (the analytic signal of an abrupt start carries errors of about 1e-4 of
    the peak, HILBERT_FLOOR)."""
    noise_in_band = max(noise_std(x, fs) * np.sqrt(2 * (band[1] - band[0]) / fs), HILBERT_FLOOR * env.max())
    ok = np.zeros(x.size, bool)
    ok[skip:x.size - skip] = True
    above = env > noise_in_band * 10 ** (ENVELOPE_DB / 20)
    if not above[skip:].all():
        flags.append("noise_floor")
        ok[skip + int(np.argmin(above[skip:])):] = False
    return ok


def _envelope_fit(tt, env, pp, fs, bw):
    """Weighted least squares of the log-envelope (decay rate) and of the phase (damped frequency)
    over time, weights env^2; stds with the samples' correlation over about fs / bw samples (the
    factor 1.6 on that is calibrated by Monte Carlo against the observed scatter, white noise)."""
    m = tt.size
    le = np.log(env)
    wts = env ** 2
    W = wts.sum()
    tbar = (wts * tt).sum() / W
    sxx = (wts * (tt - tbar) ** 2).sum()
    sl = (wts * (tt - tbar) * (le - (wts * le).sum() / W)).sum() / sxx
    res = le - ((wts * le).sum() / W + sl * (tt - tbar))
    pl = (wts * (tt - tbar) * (pp - (wts * pp).sum() / W)).sum() / sxx
    resp = pp - ((wts * pp).sum() / W + pl * (tt - tbar))
    corr = max(1.0, 1.6 * fs / bw)
    sig_std = np.sqrt((wts * res ** 2).sum() / max(m - 2, 1) / sxx * corr)
    om_std = np.sqrt((wts * resp ** 2).sum() / max(m - 2, 1) / sxx * corr)
    sigma, om = -sl, pl
    wn = np.hypot(sigma, om)
    zeta = sigma / wn
    g_z = np.array([om ** 2, -sigma * om]) / wn ** 3
    zeta_std = float(np.sqrt((g_z[0] * sig_std) ** 2 + (g_z[1] * om_std) ** 2))
    fn_std = float(np.hypot(sigma * sig_std, om * om_std) / wn / (2 * np.pi))
    return wn, zeta, fn_std, zeta_std


