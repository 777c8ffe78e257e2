"""Ring-down special cases: dry (Coulomb) friction, damping that changes with amplitude, and the
over-damped decay, and each reported mode's backbone (steps of :func:`vibmeasure.ringdown`)."""

from __future__ import annotations

import numpy as np

from ..core.errors import warn_quality
from ..core.results import ModalEstimate
from ._decay import cycle_peaks, noise_std, spectral_peak


def _nonlinear_damping(x, fs, fd, noise, t_end):
    """Coulomb (linear envelope) and amplitude-dependent damping from the cycle amplitudes."""
    tp, ap, cut = _regular_cycles(x, fs, fd, noise)
    if tp.size < 8:
        return {}
    coul = _coulomb_envelope(x, fs, fd, noise, tp, ap, cut)
    if coul is not None:
        return coul
    rows, fq = _cycle_groups(tp, ap, fd)
    out: dict = {}
    if len(rows) >= 4 and np.isfinite(fq).all() and _frequency_moves(np.array([r[0] for r in rows]), fq):
        out["frequency_dependent"] = True
    if len(rows) >= 3:
        out["zeta_vs_amplitude"] = [{"amplitude": a_, "zeta": z_} for a_, z_ in rows]
        if _damping_moves(np.array([r[0] for r in rows]), np.array([r[1] for r in rows])):
            out["amplitude_dependent"] = True
    return out


def coulomb_signature(x, fs, fd, noise) -> dict | None:
    """The dry-friction test every decay estimator runs (``_coulomb_envelope`` on the leading regular
    cycles): {"decay_per_cycle", "decay_per_cycle_std", ...} when the envelope falls linearly and the
    motion stops, else None."""
    tp, ap, cut = _regular_cycles(x, fs, fd, noise)
    if tp.size < 8:
        return None
    return _coulomb_envelope(x, fs, fd, noise, tp, ap, cut)


def _regular_cycles(x, fs, fd, noise):
    """Cycle peaks above 10 x the noise, only the leading run of regular half cycles: where another
    component (a leaked neighbour, noise) takes over, the spacing of the extremes goes astray."""
    tp, ap = cycle_peaks(x, fs, fd)
    ok = ap > 10 * noise
    cut = False
    if tp.size > 2:
        dt = np.diff(tp) * 2 * fd  # in half periods; a missed extreme gives 3, a phase jump 1.5
        bad = np.flatnonzero((np.abs(dt - np.round(dt)) > 0.25) | (np.round(dt) < 1))
        bad = bad[ok[bad + 1]]
        if bad.size:
            ok[bad[0] + 1:] = False
            cut = True
    return tp[ok], ap[ok], cut


def _coulomb_envelope(x, fs, fd, noise, tp, ap, cut):
    """Dry friction: an envelope that falls linearly (exponential and linear fits to the amplitudes
    compared) and stops the motion: it reaches zero just after the last cycle and the mass then
    stays put (beating of close modes also looks linear for a while, but goes on). Else None."""
    lin = np.polyfit(tp, ap, 1)
    r_lin = ap - np.polyval(lin, tp)
    ex = np.polyfit(tp, np.log(ap), 1, w=ap)  # weighted by amplitude: least squares on the amplitudes
    r_exp = ap - np.exp(np.polyval(ex, tp))
    rss_lin, rss_exp = float(r_lin @ r_lin), float(r_exp @ r_exp)
    t_zero = -lin[1] / lin[0] if lin[0] < 0 else np.inf
    after = x[int(min(x.size, np.ceil((t_zero + 1.5 / fd) * fs))):]
    # stuck: the rest stays within the noise (a noise-free record's noise estimate is 0: within round-off)
    # the line reaches zero after the last cycle used (those stop at 10 x the noise, so at 30 dB the
    # last lies a few cycles before the stop); what follows stays put
    stuck = (not cut and tp[-1] <= t_zero and after.size >= fs / fd
             and np.std(after) <= 3 * noise + 1e-9 * float(np.max(np.abs(x))))
    if not (stuck and rss_lin < 0.2 * rss_exp):
        return None
    slope_std = np.sqrt(rss_lin / max(tp.size - 2, 1) / np.sum((tp - tp.mean()) ** 2))
    return {"coulomb": True, "peak_times": tp, "decay_per_cycle": float(-lin[0] / fd),
            "decay_per_cycle_std": float(slope_std / fd)}


def _cycle_groups(tp, ap, fd):
    """Local damping (amplitude, zeta) and frequency over groups of cycles."""
    g = max(3, tp.size // 8)
    rows, freqs = [], []
    for i in range(0, tp.size - g + 1, g):
        tt, aa = tp[i:i + g], ap[i:i + g]
        delta = -np.polyfit(tt, np.log(aa), 1)[0] / fd
        rows.append((float(np.exp(np.mean(np.log(aa)))), float(delta / np.sqrt(4 * np.pi ** 2 + delta ** 2))))
        # the group's own frequency: half cycles counted between its first and last extreme, step by
        # step (one per extreme: the whole span divided by the average line's half period miscounts a
        # decay whose frequency moves 10-25 % away from that line)
        halves = np.sum(np.round(np.diff(tt) * 2 * fd))
        freqs.append(halves / (2 * (tt[-1] - tt[0])) if tt[-1] > tt[0] else np.nan)
    return rows, np.asarray(freqs)


def _slope_significance(X, y):
    """Slope of y on X and its standard error."""
    c = np.polyfit(X, y, 1)
    res = y - np.polyval(c, X)
    se = np.sqrt(res @ res / max(X.size - 2, 1) / np.sum((X - X.mean()) ** 2)) + 1e-300
    return c[0], se


def _frequency_moves(amp, fq) -> bool:
    """A stiffening or softening structure chirps as it decays (and a sum of close 'modes' would
    mimic that): the slope of fn on log amplitude (friction-like) or on A^2 (cubic stiffness) must
    stand out of the groups' scatter (4 std) and move fn by more than 0.2 %."""
    for X in (np.log(amp), amp ** 2):
        if np.ptp(X) <= 0:
            continue
        slope, se = _slope_significance(X, fq)
        if abs(slope) / se > 4 and abs(slope) * np.ptp(X) > 2e-3 * np.mean(fq):
            return True
    return False


def _damping_moves(amp, z) -> bool:
    """zeta depends on amplitude: a slope on log amplitude of 4 std that changes zeta by 20 %."""
    X = np.log(amp)
    if np.ptp(X) <= 0:
        return False
    slope, se = _slope_significance(X, z)
    return abs(slope) / se > 4 and abs(slope) * np.ptp(X) / max(np.mean(np.abs(z)), 1e-300) > 0.2


def _dominant_cycles(x, fs):
    """The strongest line, the broadband noise and the cycle-amplitude analysis at that line."""
    fd0 = spectral_peak(x, fs)
    noise = noise_std(x, fs)
    return {"fd": fd0, "noise": noise, "nl": _nonlinear_damping(x, fs, fd0, noise, t_end=x.size / fs)}


def _amplitude_check(x, fs, band, pre):
    """Damping versus amplitude from the cycle amplitudes of the dominant (or in-band) mode.

    Runs only where one mode dominates: the band's signal (band-passed, the filter's ringing
    skipped), or the whole record when 80 % of its energy lies within +-20 % of the strongest line.
    """
    from scipy import signal as _sig
    y = x - np.median(x)
    if band is not None:
        lo, hi = band
        sos = _sig.butter(4, (max(lo, 1e-3 * fs), hi), btype="bandpass", fs=fs, output="sos")
        y = _sig.sosfiltfilt(sos, y)
        r_min = float(np.min(-np.log(np.abs(_sig.sos2zpk(sos)[1])))) * fs
        skip = int(min(y.size // 4, 7 * fs / r_min))
        y = y[skip:]
        fd = spectral_peak(y, fs, band)
        out = _nonlinear_damping(y, fs, fd, noise_std(y, fs), t_end=y.size / fs)
    else:
        # the cycle amplitudes and the noise do not depend on the offset: the shared analysis serves
        fd = pre["fd"]
        P = np.abs(np.fft.rfft(y)) ** 2
        f = np.fft.rfftfreq(y.size, 1 / fs)
        near = (f > 0.8 * fd) & (f < 1.2 * fd)
        if P[near].sum() < 0.8 * P[1:].sum():
            return {}
        out = dict(pre["nl"])
    out.pop("coulomb", None)
    out.pop("peak_times", None)
    out["fd"] = fd
    return out


def _coulomb_check(x, fs, rec, idx, flags, i0, how, pre):
    """A single-mode decay whose cycle amplitudes fall linearly: report Coulomb friction."""
    fd0, nl = pre["fd"], pre["nl"]
    if not nl.get("coulomb"):
        return None
    tp = nl["peak_times"]
    k = np.round((tp - tp[0]) * fd0 * 2)  # half-cycle numbers (peak and trough pairs)
    half, icpt = np.polyfit(k, tp, 1)
    # maximum likelihood on the closed-form dry-friction response, released at the first turning
    # point: frequency, friction decay, amplitude, release time and offset
    from scipy.optimize import least_squares
    from ..models.sdof import coulomb_response
    te0 = icpt - half * np.floor(icpt / half)  # the earliest turning point in the record
    i_a = max(0, int(np.ceil(te0 * fs)))
    t = np.arange(x.size) / fs
    a0 = float(np.interp(te0, t, x) - np.median(x[-max(8, x.size // 10):]))
    q0 = np.array([1 / (2 * half), nl["decay_per_cycle"], a0, te0, float(np.median(x[-max(8, x.size // 10):]))])

    def resid(q):
        return x[i_a:] - (q[4] + coulomb_response(t[i_a:] - q[3], fn=q[0], friction_decay=abs(q[1]), amplitude=q[2]))
    sol = least_squares(resid, q0, x_scale=np.abs(q0) + [0, 0, 0, half, abs(a0)], method="lm")
    q = sol.x
    s2 = float(sol.fun @ sol.fun) / max(sol.fun.size - q.size, 1)
    try:
        cov = s2 * np.linalg.inv(sol.jac.T @ sol.jac)
        fn, fn_std = float(q[0]), float(np.sqrt(cov[0, 0]))
        dec, dec_std = float(abs(q[1])), float(np.sqrt(cov[1, 1]))
    except np.linalg.LinAlgError:
        fn, fn_std, dec, dec_std = 1 / (2 * half), np.nan, nl["decay_per_cycle"], nl["decay_per_cycle_std"]
    nl = dict(nl, decay_per_cycle=dec, decay_per_cycle_std=dec_std)
    extras = {"friction_decay_per_cycle": nl["decay_per_cycle"],
              "friction_decay_per_cycle_std": nl["decay_per_cycle_std"],
              "friction_displacement": nl["decay_per_cycle"] / 4.0, "start_s": i0 / fs + rec.t0,
              "start_found": how, "channel": rec.channels[idx].name,
              "stop_s": float(tp[-1] + rec.t0 + i0 / fs)}
    est = ModalEstimate(fn=[fn], zeta=[np.nan], fn_std=[fn_std], zeta_std=[np.nan], method="ml",
                        flags=tuple(flags), mode_flags=(("coulomb_friction",),), unit=rec.channels[idx].unit,
                        extras=extras)
    warn_quality(f"ringdown: dry (Coulomb) friction: the amplitude falls linearly by "
                 f"{nl['decay_per_cycle']:.4g} {rec.channels[idx].unit} per cycle; no viscous zeta is reported",
                 stacklevel=8)
    return est


def _overdamped_try(x, fs, rec, idx, flags):
    """No oscillating mode: an over-damped SDOF decays as two real exponentials.

    Accepted when that model (plus an offset) leaves a residual at the noise level and both
    rates are positive and distinct; otherwise None.
    """
    from scipy.optimize import least_squares
    n = x.size
    t = np.arange(n) / fs
    tail = x[-max(8, n // 10):]
    y = x - np.median(tail)
    peak = float(np.max(np.abs(y)))
    noise = max(noise_std(x, fs), 1e-9 * peak)
    if peak < 20 * noise:
        return None
    # start rates: the slope of ln|y| early and late in the decay
    big = np.abs(y) > 0.05 * peak
    if big.sum() < 8:
        return None
    t_end = t[np.flatnonzero(big)[-1]]
    r_slow = max(3.0 / max(t_end, 1e-12), 1e-6)

    def fun(q):
        e1, e2 = np.exp(-np.exp(q[0]) * t), np.exp(-np.exp(q[1]) * t)
        A = np.column_stack([e1, e2, np.ones_like(t)])
        c, *_ = np.linalg.lstsq(A, x, rcond=None)
        return x - A @ c

    best = None
    for ratio in (1.2, 3.0, 10.0, 30.0, 100.0):
        sol = least_squares(fun, np.log([r_slow, r_slow * ratio]), method="lm", xtol=1e-14, ftol=1e-14)
        if best is None or sol.cost < best.cost:
            best = sol
    sol = best
    res_rms = float(np.sqrt(2 * sol.cost / max(n - 5, 1)))
    ra, rb = np.sort(np.exp(sol.x))
    if not (res_rms < 1.5 * noise and np.isfinite(ra * rb)):
        return None
    wn = np.sqrt(ra * rb)
    zeta = (ra + rb) / (2 * wn)
    try:
        cov = res_rms ** 2 * np.linalg.inv(sol.jac.T @ sol.jac)
        # zeta = cosh((ln rb - ln ra) / 2) in the log-rate parameters
        u = 0.5 * abs(sol.x[1] - sol.x[0])
        g = np.array([-0.5, 0.5]) * np.sinh(u) * np.sign(sol.x[1] - sol.x[0])
        zstd = float(np.sqrt(max(g @ cov @ g, 0)))
    except np.linalg.LinAlgError:
        zstd = np.nan
    est = ModalEstimate(fn=[np.nan], zeta=[zeta], fn_std=[np.nan], zeta_std=[zstd], method="ml",
                        flags=tuple(flags) + ("overdamped",), unit=rec.channels[idx].unit,
                        extras={"decay_rates_per_s": [ra, rb], "wn_rad_s": wn, "channel": rec.channels[idx].name,
                                "noise_std": noise})
    warn_quality(f"overdamped: no oscillation in the record; zeta = {zeta:.4g} from two decay rates "
                 f"({ra:.4g}, {rb:.4g} 1/s), no natural frequency is reported", stacklevel=8)
    return est


def _add_backbone(extras, flags, iso, fs, fn, zeta, noise, j):
    """fn and zeta versus amplitude of reported mode j (isolated from the others; a table with a
    ``mode`` column), its weakly nonlinear model in extras["backbone_model"][j], and the flag
    amplitude_dependent_frequency when fn moves significantly (slope on log amplitude above 4 std)
    by more than 1e-4 over the amplitude range."""
    from .backbone import backbone, fit_backbone, frequency_trend
    bb = backbone(iso, fs, fn=fn, zeta=zeta, noise=noise)
    if bb.empty:
        return None
    bb.insert(0, "mode", j)
    if len(bb) >= 4:
        extras.setdefault("backbone_model", {})[j] = fit_backbone(bb)
        change, signif = frequency_trend(bb)
        if signif > 4 and abs(change) > 1e-4:
            flags.append("amplitude_dependent_frequency")
            extras.setdefault("frequency_change_over_decay", {})[j] = change
    return bb
