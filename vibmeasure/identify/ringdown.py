"""Free-decay (ring-down) identification by maximum likelihood.

The record after the decay start is modelled as a sum of exponentially damped sinusoids plus
an offset and a linear drift, in white Gaussian noise:

    x(t) = sum_k exp(-s_k t) (a_k cos(w_k t) + b_k sin(w_k t)) + c0 + c1 t

Least squares is then maximum likelihood. A subspace estimate (ESPRIT on a lagged Hankel
covariance) gives the start values and the model order; Levenberg-Marquardt on all parameters
finishes; standard deviations come from the Fisher information at the solution with the noise
variance estimated from the residual (scaled up where the residual spectrum near a mode is
stronger than the broadband level). Modes whose damping is not significantly positive are
stationary tones (mains, machinery) and are kept in the model but not reported as modes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..core._threads import single_threaded
from ..core._validate import as_record, check_band, check_memory, clean_signal, memory_guard, response_channel
from ..core.errors import FitError, ParameterError, warn_quality
from ..core.record import Record
from ..core.results import FLAG_TEXT, ModalEstimate
from ._decay import (alive_until, band_noise_std, clipped_mask, decay_start, decimation_factor,
                     noise_std, trim_to_decay)
from ._poles import pole_to_modal
from ._rd_checks import (_add_backbone, _amplitude_check, _coulomb_check, _dominant_cycles, _nonlinear_damping,
                         _overdamped_try)
from ._rd_ml import (_colored_noise_scale, _evaluate, _lm, _mode_energy, _mode_model, _mode_shares,  # noqa: F401
                     _pack, ringdown_crb)  # ringdown_crb: public here too
from ._rd_start import SUBSAMPLE, _linear_amplitudes, start_poles
from .limits import MAX_REL_ZETA_STD

__all__ = ["ringdown", "ringdown_crb"]

DETECT = 50.0          # a mode must carry this many times the per-sample noise variance in energy
FEW_CYCLES = 5
MIN_FS_OVER_FN = 10.0
NUM_FLOOR = 1e-9  # relative to the peak: below this, 'noise' is rounding and modes are artefacts


@memory_guard
@single_threaded
def ringdown(rec, *, channel=None, n_modes="auto", band=None, start: float | None = None, max_modes: int = 8,
             fs: float | None = None, progress=None) -> ModalEstimate:
    """Natural frequencies and damping ratios from a free decay, by maximum likelihood.

    Damped sinusoids plus offset and drift are fitted to the decay in white noise (start values from
    ESPRIT and the spectrum's peaks, then Levenberg-Marquardt), with standard deviations from the Fisher
    information (docs/methods/ringdown.md).

    Parameters
    ----------
    rec : Record or array_like
        The ring-down (an array needs ``fs``). A force channel marks the end of the excitation.
    channel : str or int, optional
        The response channel (default the first that is not a force).
    n_modes : "auto" or int
        "auto" keeps every decaying mode that stands out of the noise (up to ``max_modes``); an int
        keeps that many of the strongest.
    band : tuple of float, optional
        (lo, hi) Hz: report only modes inside (the others stay in the model as nuisance).
    start : float, optional
        Time (s from the record's start) where the free decay begins; default: found from the force
        pulse or the trigger, else the first sample.
    max_modes : int
        The most modes "auto" keeps.
    fs : float, optional
        Sampling rate for an array.
    progress : callable, optional
        ``progress(fraction)`` after each stage.

    Returns
    -------
    ModalEstimate
        fn (Hz, undamped), zeta, fn_std, zeta_std, amplitude, phase and flags; ``extras`` holds the noise
        level, the fitted span, stationary tones, Coulomb friction and the backbone where found.

    Raises
    ------
    ParameterError
        For bad input (NaN, constant, too short, unknown channel).
    FitError
        When no decaying mode stands out of the noise, or every mode's damping is too uncertain
        (relative std above 0.3).

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.free_decay(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40, seed=1)
    >>> est = vm.ringdown(rec)
    >>> round(float(est.fn[0]), 2), round(float(est.zeta[0]), 3)
    (10.37, 0.02)
    """
    try:
        return _ringdown(rec, channel, n_modes, band, start, max_modes, fs, progress)
    except np.linalg.LinAlgError as exc:
        raise _numerical_failure(exc) from None


def _numerical_failure(exc) -> FitError:
    return FitError(f"ringdown: the fit failed numerically ({exc}); the record may hold something the model "
                    "of damped sinusoids plus offset and drift does not describe (a step, a saturation): "
                    "give band= or start=, or cut the record")


def _ringdown(rec, channel, n_modes, band, start, max_modes, fs, progress, linear=False,
              poles=None) -> ModalEstimate:
    """The ring-down pipeline, one line per step (``linear``: the nonlinear checks left out)."""
    d = _prepare(rec, channel, n_modes, band, start, max_modes, fs, progress)
    d.linear, d.poles = linear, poles
    special = None if linear else _special_cases(d)   # dry friction; amplitude dependence, one mode
    if special is not None:
        return special
    d.tick(0.15)
    s = _start_values(d)                 # subspace and spectral poles, linear amplitudes, model order
    if s is None:
        return _nothing_oscillates(d)    # over-damped, or a FitError that says so
    _trim_to_noise_floor(d, s)
    f = _ml_fit(d, s)                    # Levenberg-Marquardt with backward elimination, Fisher stds
    c = _classify(d, f)                  # modes, tones, nuisance, refused; flags per mode
    if not c.report:
        return _nothing_to_report(d, f, c)
    est = _assemble(d, f, c)             # nonlinear checks, backbones, extras
    _warn_flags(est, c.rejected)
    d.tick(1.0)
    return est


# ---------------------------------------------------------------------------------------------
# the pipeline's state and steps
@dataclass
class _Decay:
    """What the steps share: the record, the channel's samples and the decay being fitted."""
    rec: Record
    idx: int
    fsr: float
    x_all: np.ndarray
    band: tuple | None
    band_asked: tuple | None
    n_modes: int | None
    max_modes: int
    tick: Callable
    flags: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    i0: int = 0
    how: str = ""
    x: np.ndarray | None = None
    w: np.ndarray | None = None
    clip: np.ndarray | None = None
    t: np.ndarray | None = None
    tn: np.ndarray | None = None
    nl_pre: dict = field(default_factory=dict)
    decimation: int = 1
    linear: bool = False      # the nonlinear and over-damped alternatives left out (linear_decay)
    poles: object = None      # given start poles (linear_decay of a replicate)


@dataclass
class _Start:
    sig: np.ndarray
    om: np.ndarray
    a: np.ndarray
    b: np.ndarray
    noise: float


def _check_counts(n_modes, max_modes):
    if n_modes != "auto":
        if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
            raise ParameterError(f"n_modes={n_modes!r} must be 'auto' or an integer >= 1")
        n_modes = int(n_modes)
        max_modes = max(max_modes, n_modes)
    else:
        n_modes = None
    if isinstance(max_modes, bool) or not isinstance(max_modes, (int, np.integer)) or max_modes < 1:
        raise ParameterError(f"max_modes={max_modes!r} must be an integer >= 1")
    return n_modes, max_modes


def _prepare(rec, channel, n_modes, band, start, max_modes, fs, progress) -> _Decay:
    """Checked input, the decay start, the record cut where the decay has long reached the noise, and
    the clipped samples masked out."""
    rec = as_record(rec, fs=fs)
    idx = response_channel(rec, channel)
    check_memory(16 * 8.0 * rec.n_samples, "ringdown", rec.n_samples)  # measured: 15 record-sized arrays at the peak
    x_all = clean_signal(rec, idx, min_samples=16)
    band = check_band(band, rec.fs)
    n_modes, max_modes = _check_counts(n_modes, max_modes)
    d = _Decay(rec, idx, rec.fs, x_all, band, band, n_modes, max_modes,
               progress if callable(progress) else (lambda fraction: None))
    if start is not None:
        from ..core._validate import positive
        d.i0 = int(round(positive(start, "start", allow_zero=True) * d.fsr))
        if not 0 <= d.i0 < x_all.size - 16:
            raise ParameterError(f"start={start} s is outside the record (0..{rec.duration:g} s)")
        d.how = "given"
    else:
        d.i0, d.how = decay_start(rec, idx, x_all)
        if d.i0 > 0:
            d.flags.append("start_detected")
    x = x_all[d.i0:]
    d.x = x[:trim_to_decay(x, d.fsr, d.flags)]
    d.clip = clipped_mask(d.x)
    if d.clip.any():
        d.flags.append("clipped")
        d.notes.append(f"{int(d.clip.sum())} clipped samples excluded")
    d.w = (~d.clip).astype(float)
    if d.w.sum() < 16:
        raise FitError("almost every sample is clipped: nothing left to fit")
    _decimate_oversampled(d)
    return d


def _decimate_oversampled(d: _Decay) -> None:
    """A decay sampled far above its content is fitted on a decimated copy (see
    :func:`._decay.decimation_factor`): the noise outside the kept band carries no information about
    the modes, so the fit is as efficient and costs a fraction. The filter's first samples (its
    start-up on the decay's abrupt start) are left out, and the decay start moves with them."""
    from scipy import signal as _sig
    if d.clip.any():   # a filter smears the clipping into its neighbours
        return
    q, f_top = decimation_factor(d.x, d.fsr, d.band)
    if q < 2:
        return
    y = _sig.resample_poly(d.x, 1, q)
    skip = 10 + 1   # resample_poly's filter spans 10 output samples each side: its start-up
    d.x = y[skip:-skip]
    d.w = np.ones(d.x.size)
    d.clip = np.zeros(d.x.size, bool)
    d.i0 += skip * q
    d.fsr = d.fsr / q
    d.decimation = q
    d.notes.append(f"fitted on every {q}th sample after an anti-alias filter (content below {f_top:.4g} Hz; "
                   f"the decimated rate {d.fsr:.4g} Hz keeps 20 samples per cycle)")


def _special_cases(d: _Decay):
    """Dry (Coulomb) friction: its estimate. Damping that changes with amplitude: one mode fitted
    (a sum of close 'modes' would mimic the non-exponential envelope). The dominant line, the noise
    and the cycle amplitudes are computed once for both checks."""
    pre = _dominant_cycles(d.x, d.fsr) if (~d.clip).all() else None
    if pre is not None:
        coul = _coulomb_check(d.x, d.fsr, d.rec, d.idx, d.flags, d.i0 / d.decimation, d.how, pre)
        if coul is not None:
            return coul
    nl_pre = _amplitude_check(d.x, d.fsr, d.band, pre) if pre is not None else {}
    if (nl_pre.get("amplitude_dependent") or nl_pre.get("frequency_dependent")) and d.n_modes is None:
        d.n_modes = 1
        if d.band is None:
            d.band = (0.8 * nl_pre["fd"], min(1.2 * nl_pre["fd"], 0.499 * d.fsr))
        what = "damping" if nl_pre.get("amplitude_dependent") else "frequency"
        d.notes.append(f"{what} changes with amplitude: one mode fitted in "
                       f"{d.band[0]:.4g}-{d.band[1]:.4g} Hz; fn and zeta are averages over the decay (see the backbone)")
    d.nl_pre = nl_pre
    return None


def _start_values(d: _Decay) -> _Start | None:
    """Poles from ESPRIT and from the spectrum's peaks (from the unclipped tail when the record is
    clipped at its start), their linear amplitudes, and the components that stand out of the noise
    (the band's first); None when no oscillating component does."""
    x, w, fsr = d.x, d.w, d.fsr
    c0 = int(np.flatnonzero(d.clip)[-1]) + 1 if d.clip.any() else 0
    if x.size - c0 < 64:
        raise FitError(f"only {x.size - c0} samples follow the last clipped one: too few to fit a decay")
    osc = start_poles(x, c0, d.fsr, d.max_modes, d.n_modes) if d.poles is None else np.asarray(d.poles, complex)
    if not osc.size:
        return None
    sig0, om0 = np.maximum(-osc.real, 1e-6 * osc.imag), osc.imag
    t = np.arange(x.size) / fsr
    tn = t / (t[-1] if t[-1] > 0 else 1.0) - 0.5
    coef, noise0, drss = _linear_amplitudes(x, w, t, sig0, om0, tn)
    if c0:  # amplitudes were referred to the tail's start: refer them to the record's
        coef2, _, drss = _linear_amplitudes(x[c0:], w[c0:], t[c0:] - t[c0], sig0, om0, tn[c0:])
        k = om0.size
        z = (coef2[:k] - 1j * coef2[k:2 * k]) * np.exp((sig0 - 1j * om0) * t[c0])
        coef = np.concatenate([z.real, -z.imag, coef[2 * k:]])
    noise0 = max(noise0, NUM_FLOOR * float(np.max(np.abs(x))))
    k = om0.size
    strong = [i for i in np.argsort(-drss) if drss[i] > DETECT * noise0 ** 2]
    if d.band is None:
        keep = strong[: (d.n_modes or d.max_modes)]
    else:  # the band's modes first, then the strongest others as nuisance
        fk = np.hypot(om0, sig0) / (2 * np.pi)
        isin = [i for i in strong if d.band[0] <= fk[i] <= d.band[1]]
        inb = isin[: (d.n_modes or d.max_modes)]
        keep = inb + [i for i in strong if i not in isin][: max(0, d.max_modes - len(inb))]
    if not keep:
        return None
    return _Start(sig0[keep], om0[keep], coef[:k][keep], coef[k:2 * k][keep], noise0)


def _nothing_oscillates(d: _Decay):
    od = None if d.linear else _overdamped_try(d.x_all[d.i0:], d.rec.fs, d.rec, d.idx, d.flags)
    if od is not None:
        return od
    raise FitError("no decaying mode stands out of the noise (the record looks like noise)")


def _trim_to_noise_floor(d: _Decay, s: _Start) -> None:
    """Cut the decay where its longest-lived component sinks to 0.3 x the noise (with a band: the
    band's modes and the band's own noise floor, not the broadband level that out-of-band components
    and coloured noise raise)."""
    n_end = d.x.size
    floor = np.full(s.sig.size, s.noise or 0.0)
    if d.band_asked is not None and s.noise:
        fk = np.hypot(s.om, s.sig) / (2 * np.pi)
        inband = (fk >= d.band_asked[0]) & (fk <= d.band_asked[1])
        if inband.any():
            floor = np.where(inband, min(s.noise, band_noise_std(d.x, d.fsr, d.band_asked)), np.inf)
    if s.noise and (s.sig > 0).all():
        t_floor = np.max(np.log(np.maximum(np.hypot(s.a, s.b) / (0.3 * floor), 1.0)) / s.sig)
        n_end = int(min(d.x.size, max(np.ceil(t_floor * d.fsr) + 1, 64)))
        # the extrapolation never cuts a component the data shows alive (a decay whose damping falls
        # with its amplitude outlives its start's rate): the longest-lived one is followed in blocks
        # (only a cut needs the check: the block search can lengthen the span, never past the record)
        if n_end < d.x.size:
            k = int(np.argmax(np.where(np.isfinite(floor), 1.0 / s.sig, -np.inf)))
            broad = noise_std(d.x, d.fsr)
            n_end = max(n_end, min(d.x.size, alive_until(d.x, d.fsr, s.om[k] / (2 * np.pi), s.sig[k], broad)))
        if n_end < d.x.size and "noise_floor" not in d.flags:
            d.flags.append("noise_floor")
    d.x, d.w = d.x[:n_end], d.w[:n_end]
    d.t = np.arange(n_end) / d.fsr
    d.tn = d.t / (d.t[-1] if d.t[-1] > 0 else 1.0) - 0.5


def _drop_weakest(p, share):
    """The parameters without the component of least share (one at a time: two look-alikes each
    seem dispensable while the other stands in for it)."""
    nm = (p.size - 2) // 4
    drop = int(np.argmin(share))
    return np.concatenate([p[4 * k:4 * k + 4] for k in range(nm) if k != drop] + [p[-2:]])


def _screen_subsampled(d: _Decay, p, q):
    """Long record: the clearly weak components go on every q-th sample (its Fisher information is
    1/q of the record's), so the full record is fitted once, with the survivors."""
    x, w, t, tn = d.x[::q], d.w[::q], d.t[::q], d.tn[::q]
    for _round in range(d.max_modes + 2):
        nm = (p.size - 2) // 4
        p, rss_q, A_q = _lm(p, x, w, t, tn, nm)
        s2_q = rss_q / max(w.sum() - p.size, 1.0)
        share = _mode_shares(p, A_q, nm, d.t[-1]) * q
        if nm == 1 or not (share <= 0.25 * DETECT * s2_q).any():
            break
        p = _drop_weakest(p, share)
    return p


def _fit_full(d: _Decay, p, q):
    """Maximum likelihood on the whole decay, with backward elimination of components whose share
    of the fit is below DETECT noise variances."""
    x, w, t, tn = d.x, d.w, d.t, d.tn
    for _round in range(d.max_modes + 2):
        nm = (p.size - 2) // 4
        if q > 1:  # converge on every q-th sample first: the full record then needs a step or two
            p, _, _ = _lm(p, x[::q], w[::q], t[::q], tn[::q], nm)
        p, rss, A, model = _lm(p, x, w, t, tn, nm, want_model=True)
        d.tick(0.3 + 0.6 * (_round + 1) / (d.max_modes + 2))
        dof = max(w.sum() - p.size, 1.0)
        s2 = max(rss / dof, (NUM_FLOOR * float(np.max(np.abs(x)))) ** 2 * 1e-6)
        share = _mode_shares(p, A, nm, t[-1])
        if not (share <= DETECT * s2).any() or nm == 1:
            break
        p = _drop_weakest(p, share)
    return p, A, s2, model


@dataclass
class _Fit:
    p: np.ndarray
    nm: int
    sig: np.ndarray
    om: np.ndarray
    a: np.ndarray
    b: np.ndarray
    noise: float
    sig_std: np.ndarray
    model: np.ndarray
    fn: np.ndarray
    zeta: np.ndarray
    fn_std: np.ndarray
    zeta_std: np.ndarray
    scale: np.ndarray


def _ml_fit(d: _Decay, s: _Start) -> _Fit:
    """Levenberg-Marquardt on all parameters; standard deviations from the Fisher information with
    the residual's noise level, scaled up where the residual near a mode is stronger (coloured)."""
    p = _pack(s.sig, s.om, s.a, s.b)
    d.tick(0.3)
    q = d.x.size // SUBSAMPLE
    if q > 1:
        p = _screen_subsampled(d, p, q)
    p, A, s2, model = _fit_full(d, p, q)
    nm = (p.size - 2) // 4
    try:
        cov = s2 * np.linalg.inv(A)
    except np.linalg.LinAlgError:
        cov = s2 * np.linalg.pinv(A)
    sig, om = p[0:4 * nm:4], p[1:4 * nm:4]
    noise = float(np.sqrt(s2))
    wn = np.hypot(om, sig)
    stds = np.array([pole_to_modal(sig[k], om[k], cov[4 * k:4 * k + 2, 4 * k:4 * k + 2])[2:] for k in range(nm)])
    scale = _colored_noise_scale((d.x - model) * d.w, d.w, d.fsr, om / (2 * np.pi), sig / np.pi, noise)
    return _Fit(p, nm, sig, om, p[2:4 * nm:4], p[3:4 * nm:4], noise,
                np.sqrt(np.maximum(np.diag(cov)[0:4 * nm:4], 0)), model, wn / (2 * np.pi), sig / wn,
                stds[:, 0] * scale, stds[:, 1] * scale, scale)


@dataclass
class _Modes:
    report: list
    mode_flags: list
    rejected: list
    tones: np.ndarray
    nuisance: np.ndarray
    wander: np.ndarray
    e_fit: np.ndarray


def _classify(d: _Decay, f: _Fit) -> _Modes:
    """Modes, stationary tones (damping not significantly positive) and nuisance components, which
    stay in the model but are not modes: baseline wander (under two cycles in the fitted span) and
    short transients (under 1.5 cycles above the noise) beside a stronger mode. A mode whose zeta is
    too uncertain is refused."""
    t_end = d.t[-1]
    amp = np.hypot(f.a, f.b)
    tones = (f.sig <= 2 * f.sig_std) | (f.sig <= 0)
    alive = np.minimum(t_end, np.log(np.maximum(amp / max(f.noise, 1e-300), 1.0)) / np.maximum(f.sig, 1e-300))
    e_fit = _mode_energy(f.a, f.b, f.sig, d.t)
    fd = f.om / (2 * np.pi)
    wander = fd * t_end < 2
    transient = (fd * alive < 1.5) & (e_fit < e_fit.max())
    nuisance = (wander | transient) & ~tones
    report, mode_flags, rejected = [], [], []
    for k in np.argsort(f.fn):
        if tones[k] or nuisance[k] or (d.band is not None and not d.band[0] <= f.fn[k] <= d.band[1]):
            continue
        if f.zeta_std[k] > MAX_REL_ZETA_STD * f.zeta[k]:
            rejected.append({"fn_hz": f.fn[k], "zeta": f.zeta[k], "zeta_std": f.zeta_std[k]})
            continue
        report.append(k)
        mode_flags.append(_mode_flags(d, f, k, amp, fd))
    if d.n_modes is not None and len(report) > d.n_modes:  # a nuisance pole may have wandered in: the strongest
        top = sorted(np.argsort(-np.array([e_fit[k] for k in report]))[:d.n_modes])
        report, mode_flags = [report[j] for j in top], [mode_flags[j] for j in top]
    return _Modes(report, mode_flags, rejected, tones, nuisance, wander, e_fit)


def _mode_flags(d: _Decay, f: _Fit, k: int, amp, fd) -> list:
    mf = []
    if f.scale[k] > 1:
        mf.append("colored_noise")
    t_alive = min(d.t[-1], np.log(max(amp[k] / max(f.noise, 1e-300), 1.0)) / f.sig[k])
    if fd[k] * t_alive < FEW_CYCLES:
        mf.append("few_cycles")
    if d.rec.fs / f.fn[k] < MIN_FS_OVER_FN:
        mf.append("resolution_limited")
    bw = f.sig / np.pi  # half-power bandwidth, Hz
    if any(abs(fd[j] - fd[k]) < max(3 * (bw[k] + bw[j]), 2.0 / d.t[-1]) for j in range(f.nm) if j != k):
        mf.append("close_modes")
    if "clipped" in d.flags:
        mf.append("clipped")
    return mf


def _nothing_to_report(d: _Decay, f: _Fit, c: _Modes):
    """No mode to report: an over-damped decay, or a FitError that names why."""
    od = None if d.linear else _overdamped_try(d.x_all[d.i0:], d.rec.fs, d.rec, d.idx, d.flags)
    if od is not None:
        return od
    if c.rejected:
        r0 = c.rejected[0]
        raise FitError(f"damping is too uncertain to report: the mode at {r0['fn_hz']:.6g} Hz has zeta "
                       f"{r0['zeta']:.3g} +- {r0['zeta_std']:.2g} (relative std above {MAX_REL_ZETA_STD}); "
                       "record a longer or cleaner decay")
    fd_all = f.om / (2 * np.pi)
    if (c.tones | c.nuisance).any():
        ks = int(np.argmax(c.e_fit))
        if c.wander[ks]:
            cyc = fd_all[ks] * d.t[-1]
            raise FitError(f"the record is too short: it spans {cyc:.2g} cycles of its strongest component "
                           f"({fd_all[ks]:.4g} Hz in {d.t[-1]:.3g} s above the noise); at least 2 cycles are needed "
                           "(a longer record, or less damping, is needed for fn and zeta)")
        if not c.tones.any():
            raise FitError("no decaying mode: only baseline wander or short transients stand out of the noise")
        err = FitError(f"no decaying mode: only stationary tones at {np.round(fd_all[c.tones], 4).tolist()} Hz")
        err.tones_hz = [float(v) for v in fd_all[c.tones]]   # callers (EFDD) tell a harmonic by it
        raise err
    raise FitError("no decaying mode" + (f" inside band={d.band}" if d.band else "") + " stands out of the noise")


def _assemble(d: _Decay, f: _Fit, c: _Modes) -> ModalEstimate:
    """The estimate of the reported modes with their flags, the nonlinear checks, the backbones
    and the extras (noise, span, tones, nuisance, refused modes, notes)."""
    fd_all = f.om / (2 * np.pi)
    extras = {"noise_std": f.noise * np.sqrt(d.decimation),   # per sample at the record's own rate
              "start_s": d.i0 / d.rec.fs + d.rec.t0, "start_found": d.how,
              "fit_span_s": float(d.t[-1]), "n_samples_used": int(d.w.sum()) * d.decimation,
              "decimation": d.decimation,
              "tones_hz": fd_all[c.tones].tolist(), "channel": d.rec.channels[d.idx].name,
              "nuisance": [{"fn_hz": f.fn[k], "zeta": f.zeta[k], "why": "baseline wander" if c.wander[k] else "transient"}
                           for k in np.flatnonzero(c.nuisance)],
              "rejected_modes": c.rejected, "notes": d.notes,
              "band_hz": None if d.band_asked is None else [float(d.band_asked[0]), float(d.band_asked[1])]}
    ik = np.asarray(c.report)
    fn_r, zeta_r = f.fn[ik].copy(), f.zeta[ik].copy()
    fn_std_r, zeta_std_r = f.fn_std[ik].copy(), f.zeta_std[ik].copy()
    if d.linear:
        extras["fitted_poles"] = (-f.sig + 1j * f.om).tolist()
    else:
        _nonlinear_checks(d, f, c, ik, extras, fn_r, zeta_r, zeta_std_r)
    resid_all = d.x - f.model
    tables = []
    for j, k in enumerate([] if d.linear else ik):  # every reported mode, isolated from the other reported modes
        if np.isfinite(zeta_r[j]):
            # unreported components within 20 % of the mode are part of it: a chirping (nonlinear) decay
            # is fitted as a mode plus a close helper that takes up its frequency change
            own = [k] + [i for i in range(f.fn.size) if i not in ik and abs(f.fn[i] / f.fn[k] - 1) < 0.2]
            iso = resid_all + sum(_mode_model(f.p, i, d.t) for i in own)
            tables.append(_add_backbone(extras, c.mode_flags[j], iso, d.fsr, f.fn[k], f.zeta[k], f.noise, j))
    tables = [b for b in tables if b is not None]
    if tables:
        import pandas as pd
        extras["backbone"] = pd.concat(tables, ignore_index=True)
    if np.any(fn_r >= 0.499 * d.fsr):
        raise FitError(f"ringdown: a mode at {float(np.max(fn_r)):.4g} Hz is at the Nyquist limit (fs/2 = "
                       f"{d.fsr / 2:g} Hz): aliased or unresolved; sample faster (at least 10 x the frequency)")
    amp, phase = np.hypot(f.a, f.b), np.arctan2(-f.b, f.a)
    return ModalEstimate(fn=fn_r, zeta=zeta_r, fn_std=fn_std_r, zeta_std=zeta_std_r, method="ml",
                         flags=tuple(d.flags), mode_flags=tuple(tuple(m) for m in c.mode_flags), amplitude=amp[ik],
                         phase=phase[ik], unit=d.rec.channels[d.idx].unit, extras=extras)


def _nonlinear_checks(d: _Decay, f: _Fit, c: _Modes, ik, extras, fn_r, zeta_r, zeta_std_r) -> None:
    """Dry friction and amplitude-dependent damping on the strongest reported mode, isolated from the
    others (in place: flags, extras, and a Coulomb mode's zeta set to NaN)."""
    fd_all = f.om / (2 * np.pi)
    kd = ik[int(np.argmax(np.hypot(f.a, f.b)[ik]))]
    pos = int(np.flatnonzero(ik == kd)[0])
    iso = d.x - f.model + _mode_model(f.p, kd, d.t)
    nl = _nonlinear_damping(iso, d.fsr, fd_all[kd], f.noise, t_end=d.t[-1])
    if nl.get("coulomb"):
        c.mode_flags[pos].append("coulomb_friction")
        fn_r[pos], zeta_r[pos], zeta_std_r[pos] = fd_all[kd], np.nan, np.nan
        extras["friction_decay_per_cycle"] = nl["decay_per_cycle"]
        extras["friction_decay_per_cycle_std"] = nl["decay_per_cycle_std"]
        extras["friction_displacement"] = nl["decay_per_cycle"] / 4.0
    if d.nl_pre.get("amplitude_dependent"):
        nl = d.nl_pre
        kd_in = [j for j, k in enumerate(ik) if abs(fd_all[k] - d.nl_pre["fd"]) < 0.2 * d.nl_pre["fd"]]
        pos = kd_in[0] if kd_in else pos
    if nl.get("amplitude_dependent"):
        c.mode_flags[pos].append("amplitude_dependent")
    if "zeta_vs_amplitude" in nl:
        extras["zeta_vs_amplitude"] = nl["zeta_vs_amplitude"]


def _warn_flags(est: ModalEstimate, rejected):
    serious = [f for f in est.flags if f not in ("noise_floor", "start_detected")]
    msgs = [f"{f}: {FLAG_TEXT.get(f, f)}" for f in serious]
    if rejected:
        msgs.append(f"{len(rejected)} mode(s) left out: damping relative std above {MAX_REL_ZETA_STD}")
    if msgs:
        warn_quality("ringdown: " + "; ".join(msgs), stacklevel=7)
