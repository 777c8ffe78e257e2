"""Ring-down maximum likelihood: the damped-sinusoid model with offset and drift, its Jacobian in
bounded chunks, Levenberg-Marquardt, and each component's share and energy (steps of
:func:`vibmeasure.ringdown`), and the Cramer-Rao bound of that model (:func:`ringdown_crb`)."""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError
from ._poles import pole_to_modal

CHUNK = 1 << 16


def _evaluate(p, x, w, t, tn, nm, want_model=False):
    from scipy.linalg.blas import dsyrk
    P = p.size
    JtJ = np.zeros((P, P))
    Jtr = np.zeros(P)
    rss = 0.0
    model_all = np.empty_like(x) if want_model else None
    weighted = not w.all()
    # t is uniform: e^(lam t) over a chunk is e^(lam t_chunk_start) times one kernel e^(lam (t - t0))
    # computed once per component (a third of the exponentials for a 200k-sample record)
    lead = t[:min(CHUNK, x.size)] - t[0]
    kern = [np.exp(lead * complex(-p[4 * k], p[4 * k + 1])) for k in range(nm)]
    for s0 in range(0, x.size, CHUNK):
        s1 = min(s0 + CHUNK, x.size)
        tt = t[s0:s1]
        J = np.empty((P, s1 - s0))  # row-major by parameter: each column write is contiguous
        model = p[-2] + p[-1] * tn[s0:s1]
        for k in range(nm):
            sg, om, a, b = p[4 * k:4 * k + 4]
            z = kern[k][:s1 - s0] * np.exp(complex(-sg, om) * t[s0])  # e^(-sg t) (cos + i sin)
            c, sn = z.real, z.imag
            mk = a * c + b * sn
            model += mk
            np.multiply(-tt, mk, out=J[4 * k])
            np.multiply(tt, b * c - a * sn, out=J[4 * k + 1])
            J[4 * k + 2] = c
            J[4 * k + 3] = sn
        J[-2] = 1.0
        J[-1] = tn[s0:s1]
        r = x[s0:s1] - model
        if weighted:
            ww = w[s0:s1]
            r = r * ww
            J *= ww
        JtJ += dsyrk(1.0, J.T, trans=1, lower=0)  # J J' without a copy (J.T is Fortran-ordered)
        Jtr += J @ r
        rss += float(r @ r)
        if want_model:
            model_all[s0:s1] = model
    JtJ = JtJ + JtJ.T   # dsyrk filled the upper triangle (the lower is zero): mirror it
    JtJ.flat[::P + 1] *= 0.5
    return rss, JtJ, Jtr, model_all


def _lm(p, x, w, t, tn, nm, max_iter=80, want_model=False):
    """(p, rss, Fisher matrix, and with ``want_model`` the model at p, kept from the evaluation
    that accepted it rather than computed again)."""
    with np.errstate(over="ignore", invalid="ignore"):
        out = _lm_inner(p, x, w, t, tn, nm, max_iter, want_model)
    return out if want_model else out[:3]


def _lm_inner(p, x, w, t, tn, nm, max_iter, want_model):
    """Levenberg-Marquardt with Nielsen's damping update (the damping follows the ratio of the
    actual to the predicted gain, so it neither bounces nor stalls in the long valleys that a
    slow baseline component makes with the offset and drift terms)."""
    sig_min = -1.0 / max(t[-1], 1e-300)  # a mode may grow at most e-fold over the record
    rss, A, g, model = _evaluate(p, x, w, t, tn, nm, want_model)
    lam, nu = 1e-4, 2.0
    slow = 0
    for _ in range(max_iter):
        d = np.sqrt(np.diag(A)) + 1e-300
        An = A / np.outer(d, d)
        try:
            hn = np.linalg.solve(An + lam * np.eye(p.size), g / d)
        except np.linalg.LinAlgError:
            lam *= nu
            nu *= 2
            continue
        step = hn / d
        pn = p + step
        if nm:
            pn[1:4 * nm:4] = np.abs(pn[1:4 * nm:4])
            pn[0:4 * nm:4] = np.maximum(pn[0:4 * nm:4], sig_min)
        rss_n, An_, gn, model_n = _evaluate(pn, x, w, t, tn, nm, want_model)
        # predicted gain of the damped Gauss-Newton step (scaled variables): h'(lam h + g)
        pred = float(hn @ (lam * hn + g / d))
        if np.isfinite(rss_n) and np.all(np.isfinite(gn)) and rss_n <= rss:
            small = True
            for k in range(nm):
                om = max(abs(pn[4 * k + 1]), 1e-300)
                amp = np.hypot(pn[4 * k + 2], pn[4 * k + 3]) + 1e-300
                small &= abs(step[4 * k]) < 1e-13 * om and abs(step[4 * k + 1]) < 1e-13 * om
                small &= abs(step[4 * k + 2]) < 1e-11 * amp and abs(step[4 * k + 3]) < 1e-11 * amp
            gain = rss - rss_n
            rho = gain / pred if pred > 0 else 0.0
            p, rss, A, g, model = pn, rss_n, An_, gn, model_n
            lam = max(lam * max(1 / 3, 1 - (2 * rho - 1) ** 3), 1e-15)
            nu = 2.0
            if small or gain <= 1e-15 * rss:
                break
            s2 = rss / max(x.size - p.size, 1)
            if _converged(p, A, g, step, s2, nm, t[-1]):
                break
            # a crawl: two accepted steps in a row each gaining under 1e-5 of a noise variance
            # move the parameters by about 3e-3 of their std
            slow = slow + 1 if gain < 1e-5 * s2 else 0
            if slow >= 2:
                break
        else:
            lam *= nu
            nu *= 2
            if lam > 1e12:
                break
    return p, rss, A, model


def _converged(p, A, g, step, s2, nm, t_end) -> bool:
    """Converged when the last step moved every decay rate and frequency by under 1e-3 of its std,
    or when the Newton decrement (what a further Gauss-Newton step could still gain) is below a
    millionth of one noise variance. (Baseline wander, under two cycles in the span, is a nuisance:
    its slow crawl along the valley it forms with the drift term does not move the modes.)"""
    try:
        Ainv = np.linalg.inv(A)
        Ainv_d = np.diag(Ainv)
        dec = float(g @ Ainv @ g)
    except np.linalg.LinAlgError:
        Ainv_d, dec = np.full(p.size, np.inf), np.inf
    osc = [k for k in range(nm) if abs(p[4 * k + 1]) * t_end >= 4 * np.pi]
    nl_idx = np.array([4 * k for k in osc] + [4 * k + 1 for k in osc], dtype=int)
    if osc and np.all(np.abs(step[nl_idx]) < 1e-3 * np.sqrt(np.maximum(s2 * Ainv_d[nl_idx], 0))):
        return True
    return dec < 1e-6 * s2


def _mode_shares(p, A, nm, t_end):
    """Each component's share of the fit: the Wald form of its amplitudes from the Fisher matrix A
    (the rise in the residual sum of squares if it were left out, to first order). Baseline wander
    (under two cycles in the span) is collinear with the offset and drift, so its Wald share is
    small however much of the record it carries: it gets inf (never a candidate for removal)."""
    try:
        Ainv = np.linalg.inv(A)
    except np.linalg.LinAlgError:
        Ainv = np.linalg.pinv(A)
    share = np.empty(nm)
    for k in range(nm):
        g_ = [4 * k + 2, 4 * k + 3]
        try:
            share[k] = float(p[g_] @ np.linalg.solve(Ainv[np.ix_(g_, g_)], p[g_]))
        except np.linalg.LinAlgError:
            share[k] = 0.0
    share[np.abs(p[1:4 * nm:4]) * t_end < 4 * np.pi] = np.inf
    return share


def _pack(sig, om, a, b):
    p = np.empty(4 * sig.size + 2)
    p[0:-2:4], p[1:-2:4], p[2:-2:4], p[3:-2:4] = sig, om, a, b
    p[-2:] = 0.0
    return p


def _mode_model(p, k, t):
    sg, om, a, b = p[4 * k:4 * k + 4]
    e = np.exp(-sg * t)
    return e * (a * np.cos(om * t) + b * np.sin(om * t))


def _mode_energy(a, b, sig, t):
    """Energy sum over samples of each mode's contribution (about A^2/2 per sample)."""
    n = t.size
    fs = (n - 1) / t[-1] if t[-1] > 0 else 1.0
    out = np.empty(a.size)
    for k in range(a.size):
        A2 = a[k] ** 2 + b[k] ** 2
        s = sig[k]
        if s * t[-1] < 1e-9:
            out[k] = 0.5 * A2 * n
        else:
            out[k] = 0.5 * A2 * fs * (1 - np.exp(-2 * s * t[-1])) / (2 * s)
    return out


def _colored_noise_scale(resid, w, fs, fd, bw, noise):
    """Per mode: sqrt(local residual PSD / white level) where it clearly exceeds 1, else 1."""
    from ._decay import _welch_linear
    n = int(w.sum())
    scale = np.ones(fd.size)
    if n < 256 or noise <= 0:
        return scale
    nper = int(min(4096, 2 ** int(np.log2(n // 8))))
    pxx = _welch_linear(resid, fs, nper, detrend="constant")
    f = np.arange(pxx.size) * fs / nper
    white = 2 * noise ** 2 / fs
    df = f[1] - f[0]
    for k in range(fd.size):
        half = max(5 * bw[k], 3 * df)
        sel = (f >= fd[k] - half) & (f <= fd[k] + half)
        nb = int(sel.sum())
        if nb < 2:
            continue
        ratio = float(pxx[sel].mean() / white)
        # the band mean of nb Welch bins scatters by about 1/sqrt(nb * segments)
        segs = max(1, 2 * n // nper - 1)
        if ratio > 1 + 4 / np.sqrt(nb * segs):
            scale[k] = np.sqrt(ratio)
    return scale


def ringdown_crb(*, fn: float, zeta: float, fs: float, duration: float, amplitude: float = 1.0,
                 phase: float = 0.0, noise_std: float | None = None, snr_db: float | None = None) -> dict:
    """Cramer-Rao bound on fn and zeta for one damped sinusoid in white Gaussian noise.

    The signal is ``amplitude * exp(-zeta wn t) cos(wd t + phase)`` sampled at ``fs`` for ``duration``
    s. The bound is the inverse Fisher information of (sigma, wd, a, b), mapped to fn and zeta: the std
    any unbiased estimator can reach. Use it to plan a test.

    Parameters
    ----------
    fn : float
        Natural frequency in Hz.
    zeta : float
        Damping ratio.
    fs : float
        Sampling rate in Hz.
    duration : float
        Record length in s.
    amplitude : float
        Initial amplitude.
    phase : float
        Initial phase in radians.
    noise_std : float, optional
        Noise standard deviation (give it or ``snr_db``).
    snr_db : float, optional
        10 log10(A^2 / (2 s^2)).

    Returns
    -------
    dict
        fn_std, zeta_std (and fn, zeta).

    Raises
    ------
    ParameterError
        Without noise_std or snr_db, or for values out of range.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> crb = vm.ringdown_crb(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40)
    >>> bool(crb["zeta_std"] < 1e-3)
    True
    """
    from ..core._validate import positive
    fn, fs, duration = positive(fn, "fn"), positive(fs, "fs"), positive(duration, "duration")
    if not 0 < zeta < 1:
        raise ParameterError(f"zeta={zeta} must be in (0, 1) for an oscillating decay")
    if (noise_std is None) == (snr_db is None):
        raise ParameterError("give exactly one of noise_std and snr_db")
    s = noise_std if noise_std is not None else abs(amplitude) / np.sqrt(2 * 10 ** (snr_db / 10))
    s = positive(s, "noise_std")
    wn = 2 * np.pi * fn
    sig, om = zeta * wn, wn * np.sqrt(1 - zeta ** 2)
    t = np.arange(int(round(duration * fs))) / fs
    a, b = amplitude * np.cos(phase), -amplitude * np.sin(phase)
    e = np.exp(-sig * t)
    c, sn = e * np.cos(om * t), e * np.sin(om * t)
    m = a * c + b * sn
    J = np.column_stack([-t * m, t * (b * c - a * sn), c, sn])
    cov = s ** 2 * np.linalg.inv(J.T @ J)
    _, _, fn_std, zeta_std = pole_to_modal(sig, om, cov[:2, :2])
    return {"fn": fn, "zeta": zeta, "fn_std": fn_std, "zeta_std": zeta_std, "noise_std": float(s)}
