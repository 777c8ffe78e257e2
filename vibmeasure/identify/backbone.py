"""Backbone of a nonlinear free decay: natural frequency and damping versus amplitude, and the
weakly nonlinear SDOF model (Duffing stiffness, amplitude-dependent damping) that explains it.

Real structures soften or stiffen and their damping changes as the vibration dies out. Over a window
of a few cycles the decay is still a damped sinusoid, so fitting one by maximum likelihood on
overlapping windows gives fn and zeta at the window's amplitude, each with its std from the window's
Fisher information. The backbone is that table.

The model (first-order harmonic balance / averaging, amplitude A of the displacement-like signal):
    wn(A)^2           = w0^2 + (3/4) (k3/m) A^2 + c4 A^4        (cubic stiffness k3; c4 the next order)
    zeta(A) wn(A)/w0  = zeta_v + f_c / A + q A + r A^2          (viscous, dry friction, quadratic; r nuisance)
with f_c = 2 F_c / (pi k) and q = 4 c2 w / (3 pi k) in terms of the friction force F_c and the
quadratic damping coefficient c2 (the damping terms act on the decay rate: a viscous damper's zeta
falls as a stiffening spring raises wn). Both relations are linear in their unknowns, fitted by
weighted least squares with the windows' std, and returned with their std; the model stands only
where both fits pass their goodness-of-fit test (``fit_backbone``).
"""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError
from ._decay import alive_until, noise_std
from ._poles import pole_to_modal

__all__ = ["backbone", "fit_backbone"]

MIN_CYCLES = 6      # cycles per window: enough for fn and zeta, short enough to follow the amplitude
MAX_WINDOWS = 40    # long decays use longer windows: the cost stays linear in the record
SNR_STOP = 10.0     # windows end where the amplitude falls below this many of its own std
MAX_SAMPLES = 2048  # samples per window fit (longer windows are subsampled)


def _window_fit(y, t, sig, om):
    """ML fit of a*e^{-s t}cos(w t) + b*e^{-s t}sin(w t) + c on one window: (p, cov, rss) or None.

    Gauss-Newton on (s, w) with the linear part (a, b, c) solved exactly at each step (variable
    projection); small normal equations throughout, a handful of iterations from the global start.
    The Jacobian rows (d/ds, d/dw, cos, sin, 1) live in one array, so one product gives both the
    linear and the full normal equations. (The window-by-window fallback of _windows_fit.)"""
    p = np.array([sig, om, 0.0, 0.0, 0.0])
    J = np.empty((5, t.size))
    J[4] = 1.0

    def at(p):
        z = np.exp(complex(-p[0], p[1]) * t)   # e^{-s t} (cos w t + i sin w t): one exponential
        J[2], J[3] = z.real, z.imag
        L = J[2:]
        lin = np.linalg.solve(L @ L.T, L @ y)
        r = y - lin @ L
        J[0] = -t * (lin[0] * J[2] + lin[1] * J[3])
        J[1] = t * (lin[1] * J[2] - lin[0] * J[3])
        return lin, r

    try:
        for it in range(13):
            lin, r = at(p)
            p[2:] = lin
            if it == 12:
                break
            step = np.linalg.solve(J @ J.T, J @ r)
            p[:2] += step[:2]
            if abs(step[1]) < 1e-8 * abs(p[1]) and abs(step[0]) < 1e-8 * abs(p[1]):
                # converged: one more pass refreshes the linear part and the Jacobian at the solution
                lin, r = at(p)
                p[2:] = lin
                break
        rss = float(r @ r)
        cov = rss / max(t.size - 5, 1) * np.linalg.inv(J @ J.T)
    except np.linalg.LinAlgError:
        return None
    return p, cov, rss


BATCH_WINDOWS = 64   # windows fitted together (vectorised Gauss-Newton), bounded memory


def _windows_fit(x, starts, nw, q, t, sig, om):
    """_window_fit for every window at once, BATCH_WINDOWS at a time: the same variable-projection
    Gauss-Newton from the global start, each window stopping when its step is below 1e-8 of w (then
    refreshed at its solution), at most 12 steps. (p, cov) per window; None where a fit fails (a
    batch with a singular system is done window by window)."""
    from numpy.lib.stride_tricks import sliding_window_view
    if starts.size == 0 or nw > x.size:
        return []
    view = sliding_window_view(x, nw)
    out = []
    for b0 in range(0, starts.size, BATCH_WINDOWS):
        Y = view[starts[b0:b0 + BATCH_WINDOWS]][:, ::q]
        try:
            out += _batch_fit(Y, t, sig, om)
        except np.linalg.LinAlgError:
            for y in Y:
                res = _window_fit(y, t, sig, om)
                out.append(None if res is None else res[:2])
    return out


def _batch_fit(Y, t, sig, om):
    m = Y.shape[0]
    p = np.tile([sig, om, 0.0, 0.0, 0.0], (m, 1))
    J = np.empty((m, 5, t.size))
    J[:, 4] = 1.0

    def at(p):
        z = np.exp((-p[:, :1] + 1j * p[:, 1:2]) * t)
        J[:, 2], J[:, 3] = z.real, z.imag
        L = J[:, 2:]
        lin = np.linalg.solve(L @ L.transpose(0, 2, 1), (L @ Y[:, :, None]))[:, :, 0]
        r = Y - np.einsum("wk,wkn->wn", lin, L)
        J[:, 0] = -t * (lin[:, :1] * J[:, 2] + lin[:, 1:2] * J[:, 3])
        J[:, 1] = t * (lin[:, 1:2] * J[:, 2] - lin[:, :1] * J[:, 3])
        return lin, r

    active = np.ones(m, bool)
    for _ in range(12):
        lin, r = at(p)
        step = np.linalg.solve(J @ J.transpose(0, 2, 1), (J @ r[:, :, None]))[:, :, 0]
        p[active, :2] += step[active, :2]
        done = (np.abs(step[:, 1]) < 1e-8 * np.abs(p[:, 1])) & (np.abs(step[:, 0]) < 1e-8 * np.abs(p[:, 1]))
        active &= ~done
        if not active.any():
            break
    lin, r = at(p)   # the linear part and the Jacobian at the solution
    p[:, 2:] = lin
    rss = np.einsum("wn,wn->w", r, r)
    cov = rss[:, None, None] / max(t.size - 5, 1) * np.linalg.inv(J @ J.transpose(0, 2, 1))
    return [(p[k].copy(), cov[k]) for k in range(m)]


def backbone(x, fs: float, *, fn: float, zeta: float, noise: float, cycles: float | None = None):
    """fn and zeta versus amplitude of a one-mode decay ``x`` (the mode isolated: other modes and
    offsets removed), from ML fits on half-overlapping windows. Returns a DataFrame with t_s,
    amplitude (the fitted envelope's root mean square over the window: the amplitude the window's
    frequency answers to), fn_hz, fn_std_hz, zeta, zeta_std; empty when fewer than three
    windows measure their amplitude to better than 1/SNR_STOP (``noise`` is the per-sample std)."""
    import pandas as pd
    cols = ["t_s", "amplitude", "fn_hz", "fn_std_hz", "zeta", "zeta_std"]
    x = np.asarray(x, float)
    if not (np.isfinite(fn) and fn > 0 and np.isfinite(zeta) and 0 < zeta < 1):
        return pd.DataFrame(columns=cols)
    wn = 2 * np.pi * fn
    sig, om = zeta * wn, wn * np.sqrt(1 - zeta ** 2)
    a0 = np.max(np.abs(x[: max(int(fs / fn), 8)]))
    # a window of n samples measures an amplitude to about noise * sqrt(2 / n): the decay is followed
    # until the amplitude is SNR_STOP times that, for the shortest window, at the global decay rate
    floor = SNR_STOP * max(noise, 1e-300) * np.sqrt(2 / max(MIN_CYCLES * fs / fn, 1.0))
    t_alive = min(x.size / fs, np.log(max(a0 / floor, 1.0)) / max(sig, 1e-300))
    # a decay whose damping falls with its amplitude outlives the global rate: followed while it stands
    # out of the noise in its band (the windows' own amplitude test still ends the table)
    t_alive = max(t_alive, alive_until(x, fs, fn, sig, noise_std(x, fs)) / fs)
    cyc_alive = fn * t_alive
    per_win = max(MIN_CYCLES, cyc_alive / (MAX_WINDOWS / 2 + 1)) if cycles is None else float(cycles)
    nw = int(round(per_win * fs / fn))
    step = max(nw // 2, 1)
    rows = []
    starts = np.arange(0, max(int(t_alive * fs) - nw + 1, 0), step)
    starts = starts[starts + nw <= x.size]
    tc = (nw - 1) / (2 * fs)
    q = max(1, nw // MAX_SAMPLES)  # every q-th sample keeps the model exact; the std says what it costs
    t = (np.arange(nw) / fs - tc)[::q]  # centred: amplitudes refer to the window's middle
    fits = _windows_fit(x, starts, nw, q, t, sig, om)
    for s0, out in zip(starts, fits):
        if out is None:
            continue
        p, cov = out
        amp = float(np.hypot(p[2], p[3]))
        amp_std = float(np.sqrt(max(cov[2, 2] + cov[3, 3], 0) / 2))
        if amp < SNR_STOP * amp_std:
            break
        if p[0] <= 0:
            continue
        f_n, z, f_std, z_std = pole_to_modal(p[0], abs(p[1]), cov[:2, :2])
        # the window's frequency answers to its mean square amplitude, not the centre's: for an envelope
        # a e^(-s t) over a window of length T that is a^2 sinh(s T) / (s T) (1 % in k3 at s T = 0.25)
        st = max(p[0] * nw / fs, 1e-12)
        rows.append((s0 / fs + tc, amp * np.sqrt(np.sinh(st) / st), f_n, f_std, z, z_std))
    df = pd.DataFrame(rows, columns=cols)
    return df if len(df) >= 3 else pd.DataFrame(columns=cols)


GOF_FACTOR = 4.0   # a model fits when its reduced chi-square is under this x its 99 % quantile
# The model's own error in k3 (windows of a chirping decay, harmonics beyond the A^4 term): +0.2-1.1 %
# on exact Duffing decays (k3/k 0.02-0.2, benchmarks/edges.py case 16); added to the std in quadrature
K3_MODEL_ERROR = 0.01


def fit_backbone(bb) -> dict:
    """The weakly nonlinear SDOF model of a backbone table (see the module doc): w0, k3/m (and k3/k
    = k3/(m w0^2)), zeta_v, the friction term f_c and the quadratic term q, each with its std; and
    the reduced chi-square of each fit (about 1 when the model explains the backbone within its std).

    Goodness of fit: the model stands (``fits`` True) only when each fit's reduced chi-square is
    under GOF_FACTOR times its 99 % quantile (the window stds are white-noise bounds that understate
    the windows' scatter by up to 2x; the gate looks for a wrong model, chi-square 50-5000 on strongly
    nonlinear decays, not a low std) and the friction term is not materially negative (beyond 3 of its
    stds and 5 % of the damping at the smallest amplitude: a negative friction is no physics). Otherwise its parameters are NaN, ``fits`` is False and
    ``reason`` says which test failed: a number from a model that does not describe the data would be
    a confident wrong answer."""
    import pandas as pd
    if not isinstance(bb, pd.DataFrame) or not {"amplitude", "fn_hz", "fn_std_hz", "zeta", "zeta_std"} <= set(bb):
        raise ParameterError("bb must be a backbone DataFrame (amplitude, fn_hz, fn_std_hz, zeta, zeta_std)")
    if len(bb) < 4:
        raise ParameterError(f"a backbone model needs at least 4 windows, got {len(bb)}")
    A = bb["amplitude"].to_numpy(float)
    w = 2 * np.pi * bb["fn_hz"].to_numpy(float)
    w_std = 2 * np.pi * np.maximum(bb["fn_std_hz"].to_numpy(float), 1e-300)
    z = bb["zeta"].to_numpy(float)
    z_std = np.maximum(bb["zeta_std"].to_numpy(float), 1e-300)

    def wls(X, y, s):
        Xw, yw = X / s[:, None], y / s
        coef, *_ = np.linalg.lstsq(Xw, yw, rcond=None)
        r = yw - Xw @ coef
        chi2 = float(r @ r) / max(len(y) - X.shape[1], 1)
        cov = np.linalg.pinv(Xw.T @ Xw) * max(chi2, 1.0)  # scatter beyond the stated std widens it
        return coef, np.sqrt(np.diag(cov)), chi2

    # w^2 = w0^2 + (3/4)(k3/m) A^2 + c4 A^4, with std(w^2) = 2 w std(w). First-order harmonic balance
    # stops at A^2; the next order (harmonics, O((k3 A^2 / k)^2)) is the free nuisance c4: without it
    # k3/m came out 4-13 of its stds high on exact Duffing decays (k3/k 0.02-0.2)
    cw, sw, chi_w = wls(np.column_stack([np.ones_like(A), 0.75 * A ** 2, A ** 4]), w ** 2, 2 * w * w_std)
    w0 = float(np.sqrt(max(cw[0], 1e-300)))
    # the damping terms act on the decay rate zeta w: a viscous c gives zeta w = c / 2m at every
    # amplitude, so zeta itself falls as a stiffening spring raises w (z w / w0 is fitted; zeta_v at w0).
    # An A^2 term (cubic damping, and the windows' own second-order error on a chirping decay) is a
    # nuisance: without it zeta_v came out 1-2 of its stds high at k3/k 0.1-0.2
    cz, sz, chi_z = wls(np.column_stack([np.ones_like(A), 1 / A, A, A ** 2]), z * w / w0, z_std * w / w0)
    k3_std = float(np.hypot(sw[1], K3_MODEL_ERROR * cw[1]))
    model = {"fn0_hz": w0 / (2 * np.pi), "fn0_std_hz": float(sw[0] / (2 * w0) / (2 * np.pi)),
             "k3_over_m": float(cw[1]), "k3_over_m_std": k3_std,
             "k3_over_k": float(cw[1] / w0 ** 2), "k3_over_k_std": k3_std / w0 ** 2,
             "zeta_viscous": float(cz[0]), "zeta_viscous_std": float(sz[0]),
             "friction_term": float(cz[1]), "friction_term_std": float(sz[1]),
             "quadratic_term": float(cz[2]), "quadratic_term_std": float(sz[2])}
    reason = _lack_of_fit(chi_w, chi_z, len(bb), model, float(A.min()))
    if reason:
        model = {k: float("nan") for k in model}
    return dict(model, chi2_frequency=chi_w, chi2_damping=chi_z, fits=reason is None, reason=reason)


def _lack_of_fit(chi_w: float, chi_z: float, n: int, model: dict, a_min: float):
    """Why the backbone model does not describe the windows, or None when it does (see fit_backbone).
    A negative friction term counts when it is beyond 3 stds and takes more than 5 % off the damping
    at the smallest amplitude (a Duffing decay's harmonics leave one of -1 % there)."""
    from scipy.stats import chi2
    out = []
    for name, c, dof in (("frequency", chi_w, n - 3), ("damping", chi_z, n - 4)):
        limit = GOF_FACTOR * float(chi2.ppf(0.99, max(dof, 1))) / max(dof, 1)
        if not c <= limit:
            out.append(f"the {name} model leaves reduced chi-square {c:.3g} > {limit:.3g}")
    fc = model["friction_term"]
    if fc < -3 * model["friction_term_std"] and -fc / a_min > 0.05 * abs(model["zeta_viscous"]):
        out.append(f"negative friction term {model['friction_term']:.3g} +- {model['friction_term_std']:.2g}")
    return "; ".join(out) + ": the decay is not the weakly nonlinear SDOF the model assumes" if out else None


def frequency_trend(bb) -> tuple[float, float]:
    """Relative change of fn over the backbone's amplitude range and its significance (slope of fn
    on log amplitude over its std): the test behind the flag amplitude_dependent_frequency."""
    if len(bb) < 4:
        return 0.0, 0.0
    X = np.log(bb["amplitude"].to_numpy(float))
    y = bb["fn_hz"].to_numpy(float)
    s = np.maximum(bb["fn_std_hz"].to_numpy(float), 1e-300)
    if np.ptp(X) <= 0:
        return 0.0, 0.0
    M = np.column_stack([np.ones_like(X), X]) / s[:, None]
    coef, *_ = np.linalg.lstsq(M, y / s, rcond=None)
    r = y / s - M @ coef
    chi2 = max(float(r @ r) / max(len(y) - 2, 1), 1.0)
    se = float(np.sqrt(np.linalg.pinv(M.T @ M)[1, 1] * chi2))
    return float(coef[1] * np.ptp(X) / np.mean(y)), float(abs(coef[1]) / max(se, 1e-300))
