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

import numpy as np

from ..core._threads import single_threaded
from ..core._validate import as_record, check_band, check_memory, clean_signal, memory_guard, response_channel
from ..core.errors import FitError, ParameterError, warn_quality
from ..core.results import FLAG_TEXT, ModalEstimate
from ._decay import band_noise_std, clipped_mask, cycle_peaks, decay_start, noise_std, spectral_peak, trim_to_decay
from ._poles import pole_to_modal

__all__ = ["ringdown", "ringdown_crb"]

DETECT = 50.0          # a mode must carry this many times the per-sample noise variance in energy
MAX_REL_ZETA_STD = 0.3  # refuse a mode whose zeta is this uncertain (relative std)
FEW_CYCLES = 5
MIN_FS_OVER_FN = 10.0
CHUNK = 1 << 16
SUBSAMPLE = 100_000  # longer records are first fitted on every q-th sample, then polished in full
NUM_FLOOR = 1e-9  # relative to the peak: below this, 'noise' is rounding and modes are artefacts


# ---------------------------------------------------------------------------------------------
# subspace start values
def _esprit(x: np.ndarray, fs: float, max_modes: int, n_modes: int | None):
    """Continuous-time poles s = -sigma + i w from a lagged-Hankel ESPRIT; also the eigenvalues."""
    n = x.size
    y = x - x.mean()
    X = np.abs(np.fft.rfft(y))
    f = np.fft.rfftfreq(n, 1 / fs)
    floor = np.median(X[1:]) + 1e-300
    sig = np.flatnonzero(X[1:] > 30 * floor) + 1
    fmax = f[sig].max() if sig.size else fs / 4
    lag = max(1, int(fs / (3.0 * max(fmax, fs / n))))
    L = int(min(max(32, 4 * max_modes + 8), 160, max(8, (n - 1) // (3 * lag))))
    span = (L - 1) * lag
    if n - span < 2 * L:
        lag = max(1, (n // 3) // L)
        span = (L - 1) * lag
    m = n - span
    if m < L:
        raise FitError(f"the decay has {n} samples: too short for identification")
    q = max(1, m // 60000)  # row stride: bounded work on long records
    rows = np.lib.stride_tricks.as_strided(y, shape=((m - 1) // q + 1, L),
                                           strides=(y.strides[0] * q, y.strides[0] * lag))
    R = rows.T @ rows
    lam, U = np.linalg.eigh(R)
    lam, U = lam[::-1], U[:, ::-1]
    noise_eig = np.median(lam[L // 2:]) + 1e-300 * lam[0]
    r = int(np.sum(lam > 4.0 * noise_eig))
    if n_modes is not None:
        r = max(r, 2 * n_modes)
    r = int(min(max(r + 1, 2), L - 2, 2 * max_modes + 3))
    Us = U[:, :r]
    Phi = np.linalg.lstsq(Us[:-1], Us[1:], rcond=None)[0]
    z = np.linalg.eigvals(Phi)
    z = z[np.abs(z) > 1e-12]
    s = np.log(z) * fs / lag
    return s


def _spectral_candidates(x, fs, n_max):
    """Poles from the strongest peaks of the zero-padded spectrum (half-power width -> decay rate).

    They complement the subspace poles: the lagged Hankel spans a short time, so a weak-looking
    but long-lived low-frequency mode may be missing from its leading subspace.
    """
    from scipy.signal import find_peaks
    n = x.size
    nfft = int(2 ** np.ceil(np.log2(4 * n)))
    P = np.abs(np.fft.rfft(x - x.mean(), nfft)) ** 2
    df = fs / nfft
    floor = np.median(P) + 1e-300
    # ten unpadded bins apart: the sidelobes of a strong line (1.5 bins apart) are not modes;
    # closer modes are the subspace method's job
    pk, _ = find_peaks(P, height=100 * floor, distance=max(1, int(10 * nfft / n)))
    pk = pk[np.argsort(-P[pk])]
    # a peak must stand 10x above the sidelobe envelope P_j / (pi d)^2 of every stronger peak j
    # (d in unpadded bins): leakage of a record that ends before the decay does is not a mode
    kept = []
    for k in pk:
        if all(P[k] > 10 * P[j] / (np.pi * abs(k - j) * n / nfft) ** 2 for j in kept):
            kept.append(k)
        if len(kept) >= n_max:
            break
    out = []
    for k in kept:
        if k < 2 or k > P.size - 3:
            continue
        half = P[k] / 2
        lo, hi = k, k
        while lo > 0 and P[lo] > half:
            lo -= 1
        while hi < P.size - 1 and P[hi] > half:
            hi += 1
        sigma = max(np.pi * (hi - lo) * df, np.pi * fs / n)
        out.append(complex(-sigma, 2 * np.pi * k * df))
    return np.asarray(out)


def _basis(t, sig, om):
    e = np.exp(-np.outer(t, sig))
    return e * np.cos(np.outer(t, om)), e * np.sin(np.outer(t, om))


def _linear_amplitudes(x, w, t, sig, om, tn):
    """Least-squares a_k, b_k and offset/drift for fixed poles; returns (coef, residual rms).

    Long records are subsampled (every q-th sample keeps the model exact): start values only.
    """
    q = max(1, x.size // SUBSAMPLE)
    x, w, t, tn = x[::q], w[::q], t[::q], tn[::q]
    C, S = _basis(t, sig, om)
    A = np.column_stack([C, S, np.ones_like(t), tn])
    Aw = A * w[:, None]
    coef, *_ = np.linalg.lstsq(Aw, x * w, rcond=None)
    res = (x - A @ coef) * w
    k = sig.size
    # each mode's share of the fit: the rise in the residual sum of squares if it were left out
    # (Wald form b' inv(cov_bb) b), in full-record units; unlike its energy this stays small for
    # collinear look-alikes (sidelobes) that cancel each other
    G = np.linalg.pinv(Aw.T @ Aw)
    drss = np.empty(k)
    for i in range(k):
        idx = [i, k + i]
        bb = coef[idx]
        try:
            drss[i] = float(bb @ np.linalg.solve(G[np.ix_(idx, idx)], bb))
        except np.linalg.LinAlgError:
            drss[i] = 0.0
    return coef, float(np.sqrt(res @ res / max(w.sum() - A.shape[1], 1))), drss * q


# ---------------------------------------------------------------------------------------------
# nonlinear least squares (Levenberg-Marquardt, chunked so memory stays bounded)
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
    JtJ = np.triu(JtJ) + np.triu(JtJ, 1).T
    return rss, JtJ, Jtr, model_all


def _lm(p, x, w, t, tn, nm, max_iter=80):
    with np.errstate(over="ignore", invalid="ignore"):
        return _lm_inner(p, x, w, t, tn, nm, max_iter)


def _lm_inner(p, x, w, t, tn, nm, max_iter):
    """Levenberg-Marquardt with Nielsen's damping update (the damping follows the ratio of the
    actual to the predicted gain, so it neither bounces nor stalls in the long valleys that a
    slow baseline component makes with the offset and drift terms)."""
    sig_min = -1.0 / max(t[-1], 1e-300)  # a mode may grow at most e-fold over the record
    rss, A, g, _ = _evaluate(p, x, w, t, tn, nm)
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
        rss_n, An_, gn, _ = _evaluate(pn, x, w, t, tn, nm)
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
            p, rss, A, g = pn, rss_n, An_, gn
            lam = max(lam * max(1 / 3, 1 - (2 * rho - 1) ** 3), 1e-15)
            nu = 2.0
            if small or gain <= 1e-15 * rss:
                break
            # converged when the last step moved every decay rate and frequency by under 1e-3 of
            # its std, or when the Newton decrement (what a further Gauss-Newton step could still
            # gain) is below a millionth of one noise variance
            s2 = rss / max(x.size - p.size, 1)
            try:
                Ainv_d = np.diag(np.linalg.inv(A))
                dec = float(g @ np.linalg.solve(A, g))
            except np.linalg.LinAlgError:
                Ainv_d, dec = np.full(p.size, np.inf), np.inf
            # (baseline wander, under two cycles in the span, is a nuisance: its slow crawl along
            # the valley it forms with the drift term does not move the modes)
            osc = [k for k in range(nm) if abs(p[4 * k + 1]) * t[-1] >= 4 * np.pi]
            nl_idx = np.r_[[4 * k for k in osc], [4 * k + 1 for k in osc]].astype(int)
            if osc and np.all(np.abs(step[nl_idx]) < 1e-3 * np.sqrt(np.maximum(s2 * Ainv_d[nl_idx], 0))):
                break
            if dec < 1e-6 * s2:
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
    return p, rss, A


# ---------------------------------------------------------------------------------------------
@memory_guard
@single_threaded
def ringdown(rec, *, channel=None, n_modes="auto", band=None, start: float | None = None, max_modes: int = 8,
             fs: float | None = None, progress=None) -> ModalEstimate:
    """Natural frequencies and damping ratios from a free decay, by maximum likelihood.

    Parameters
    ----------
    rec : Record (or array with ``fs``)
        The ring-down. With several channels, ``channel`` picks one (default: the first that
        is not a force); a force channel marks the end of the excitation.
    n_modes : "auto" or int
        "auto" keeps every decaying mode that stands out of the noise (up to ``max_modes``);
        an int keeps that many of the strongest.
    band : (lo, hi) Hz, optional
        Report only modes inside this band (the others stay in the model as nuisance).
    start : float, optional
        Time (s, from the record's start) where the free decay begins; default: found from the
        force pulse or the trigger, else the first sample.

    progress : callable, optional
        ``progress(fraction)`` after each stage (checks, start values, each maximum-likelihood round).

    Returns
    -------
    ModalEstimate with fn (Hz, undamped), zeta, fn_std, zeta_std, amplitude, phase and flags.
    ``extras`` holds the noise level, the fitted span, stationary tones and, where found,
    Coulomb friction and damping versus amplitude.

    Raises
    ------
    ParameterError for bad input; FitError when no decaying mode stands out of the noise or
    every mode's damping is too uncertain (relative std above 0.3).
    """
    rec = as_record(rec, fs=fs)
    idx = response_channel(rec, channel)
    check_memory(16 * 8.0 * rec.n_samples, "ringdown", rec.n_samples)  # measured: 15 record-sized arrays at the peak
    x_all = clean_signal(rec, idx, min_samples=16)
    fsr = rec.fs
    band = check_band(band, fsr)
    band_asked = band
    if n_modes != "auto":
        if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
            raise ParameterError(f"n_modes={n_modes!r} must be 'auto' or an integer >= 1")
        n_modes = int(n_modes)
        max_modes = max(max_modes, n_modes)
    else:
        n_modes = None
    if isinstance(max_modes, bool) or not isinstance(max_modes, (int, np.integer)) or max_modes < 1:
        raise ParameterError(f"max_modes={max_modes!r} must be an integer >= 1")
    flags: list[str] = []
    notes: list[str] = []
    tick = progress if callable(progress) else (lambda fraction: None)

    if start is not None:
        from ..core._validate import positive
        i0 = int(round(positive(start, "start", allow_zero=True) * fsr))
        if not 0 <= i0 < x_all.size - 16:
            raise ParameterError(f"start={start} s is outside the record (0..{rec.duration:g} s)")
        how = "given"
    else:
        i0, how = decay_start(rec, idx, x_all)
        if i0 > 0:
            flags.append("start_detected")
    x = x_all[i0:]
    x = x[:trim_to_decay(x, fsr, flags)]
    clip = clipped_mask(x)
    if clip.any():
        flags.append("clipped")
        notes.append(f"{int(clip.sum())} clipped samples excluded")
    w = (~clip).astype(float)
    if w.sum() < 16:
        raise FitError("almost every sample is clipped: nothing left to fit")

    # --- dry friction: a linear envelope is not a sum of damped sinusoids --------------------
    # (the dominant line, the noise and the cycle amplitudes are computed once for both checks)
    pre = _dominant_cycles(x, fsr) if (~clip).all() else None
    if pre is not None:
        coul = _coulomb_check(x, fsr, rec, idx, flags, i0, how, pre)
        if coul is not None:
            return coul

    # --- damping that changes with amplitude: one mode, described by a table ------------------
    nl_pre = _amplitude_check(x, fsr, band, pre) if pre is not None else {}
    if (nl_pre.get("amplitude_dependent") or nl_pre.get("frequency_dependent")) and n_modes is None:
        # a sum of close 'modes' would mimic the non-exponential envelope: fit one mode instead
        n_modes = 1
        if band is None:
            band = (0.8 * nl_pre["fd"], min(1.2 * nl_pre["fd"], 0.499 * fsr))
        what = "damping" if nl_pre.get("amplitude_dependent") else "frequency"
        notes.append(f"{what} changes with amplitude: one mode fitted in "
                     f"{band[0]:.4g}-{band[1]:.4g} Hz; fn and zeta are averages over the decay (see the backbone)")

    tick(0.15)
    # --- start values and model order -----------------------------------------------------
    # start values from the unclipped tail when the record is clipped at its start
    c0 = int(np.flatnonzero(clip)[-1]) + 1 if clip.any() else 0
    if x.size - c0 < 64:
        raise FitError(f"only {x.size - c0} samples follow the last clipped one: too few to fit a decay")
    xs = x[c0:]
    try:
        s = _esprit(xs, fsr, max_modes, n_modes)
    except np.linalg.LinAlgError as exc:
        raise FitError(f"subspace start values failed: {exc}") from None
    osc = s[(s.imag > 2 * np.pi * fsr / x.size * 0.25) & (s.imag < np.pi * fsr * 0.999)]
    spec = _spectral_candidates(xs, fsr, max_modes)
    if spec.size:
        res_w = 2 * np.pi * 10 * fsr / x.size  # ten bins of the unpadded spectrum: sidelobes
        new = [c for c in spec if not osc.size or np.min(np.abs(osc.imag - c.imag)) > max(res_w, -c.real)]
        osc = np.concatenate([osc, np.asarray(new, dtype=complex)])
    sig0 = np.maximum(-osc.real, 1e-6 * osc.imag) if osc.size else np.empty(0)
    om0 = osc.imag if osc.size else np.empty(0)
    t = np.arange(x.size) / fsr
    T = t[-1] if t[-1] > 0 else 1.0
    tn = t / T - 0.5
    noise0 = None
    if om0.size:
        coef, noise0, drss = _linear_amplitudes(x, w, t, sig0, om0, tn)
        if c0:  # amplitudes were referred to the tail's start: refer them to the record's
            coef2, _, drss = _linear_amplitudes(x[c0:], w[c0:], t[c0:] - t[c0], sig0, om0, tn[c0:])
            k = om0.size
            z = (coef2[:k] - 1j * coef2[k:2 * k]) * np.exp((sig0 - 1j * om0) * t[c0])
            coef = np.concatenate([z.real, -z.imag, coef[2 * k:]])
        noise0 = max(noise0, NUM_FLOOR * float(np.max(np.abs(x))))
        k = om0.size
        a, b = coef[:k], coef[k:2 * k]
        energy = drss
        strong = [i for i in np.argsort(-energy) if energy[i] > DETECT * noise0 ** 2]
        if band is None:
            keep = strong[: (n_modes or max_modes)]
        else:  # the band's modes first, then the strongest others as nuisance
            fk = np.hypot(om0, sig0) / (2 * np.pi)
            isin = [i for i in strong if band[0] <= fk[i] <= band[1]]
            inb = isin[: (n_modes or max_modes)]
            keep = inb + [i for i in strong if i not in isin][: max(0, max_modes - len(inb))]
        sig0, om0, a, b = sig0[keep], om0[keep], a[keep], b[keep]
    if om0.size == 0:
        od = _overdamped_try(x_all[i0:], fsr, rec, idx, flags)
        if od is not None:
            return od
        raise FitError("no decaying mode stands out of the noise (the record looks like noise)")

    # --- trim where the decay has sunk into the noise ---------------------------------------
    env_amp = np.hypot(a, b)
    decaying = sig0 > 0
    n_end = x.size
    floor = np.full(sig0.size, noise0 or 0.0)
    if band_asked is not None and noise0:
        # the band's modes sink into the band's noise, not into the broadband level (which out-of-band
        # components and coloured noise raise): they decide the span; the nuisance follows
        inband = (np.hypot(om0, sig0) / (2 * np.pi) >= band_asked[0]) & (np.hypot(om0, sig0) / (2 * np.pi) <= band_asked[1])
        if inband.any():
            floor = np.where(inband, min(noise0, band_noise_std(x, fsr, band_asked)), np.inf)
    if noise0 and decaying.all():
        t_floor = np.max(np.log(np.maximum(env_amp / (0.3 * floor), 1.0)) / sig0)
        n_end = int(min(x.size, max(np.ceil(t_floor * fsr) + 1, 64)))
        if n_end < x.size and "noise_floor" not in flags:
            flags.append("noise_floor")
    x, w, t = x[:n_end], w[:n_end], t[:n_end]
    T = t[-1] if t[-1] > 0 else 1.0
    tn = t / T - 0.5

    # --- maximum likelihood -----------------------------------------------------------------
    tick(0.3)
    p = _pack(sig0, om0, a, b)
    q = x.size // SUBSAMPLE
    if q > 1:
        # long record: the clearly weak components go on every q-th sample (its Fisher information
        # is 1/q of the record's), so the full record is fitted once, with the survivors
        for _round in range(max_modes + 2):
            nm = (p.size - 2) // 4
            p, rss_q, A_q = _lm(p, x[::q], w[::q], t[::q], tn[::q], nm)
            s2_q = rss_q / max(w[::q].sum() - p.size, 1.0)
            share = _mode_shares(p, A_q, nm, t[-1]) * q
            if nm == 1 or not (share <= 0.25 * DETECT * s2_q).any():
                break
            drop = int(np.argmin(share))
            p = np.concatenate([p[4 * k:4 * k + 4] for k in range(nm) if k != drop] + [p[-2:]])
    for _round in range(max_modes + 2):
        nm = (p.size - 2) // 4
        if q > 1:  # converge on every q-th sample first: the full record then needs a step or two
            p, _, _ = _lm(p, x[::q], w[::q], t[::q], tn[::q], nm)
        p, rss, A = _lm(p, x, w, t, tn, nm)
        tick(0.3 + 0.6 * (_round + 1) / (max_modes + 2))
        dof = max(w.sum() - p.size, 1.0)
        s2 = max(rss / dof, (NUM_FLOOR * float(np.max(np.abs(x)))) ** 2 * 1e-6)
        share = _mode_shares(p, A, nm, t[-1])
        weak = share <= DETECT * s2
        if not weak.any() or nm == 1:
            break
        # backward elimination, one mode at a time: two look-alikes each seem dispensable while
        # the other stands in for it, so only the weakest goes before the next fit
        drop = int(np.argmin(share))
        p = np.concatenate([p[4 * k:4 * k + 4] for k in range(nm) if k != drop] + [p[-2:]])
    nm = (p.size - 2) // 4
    try:
        cov = s2 * np.linalg.inv(A)
    except np.linalg.LinAlgError:
        cov = s2 * np.linalg.pinv(A)
    sig, om = p[0:4 * nm:4], p[1:4 * nm:4]
    a, b = p[2:4 * nm:4], p[3:4 * nm:4]
    noise = float(np.sqrt(s2))
    sig_std = np.sqrt(np.maximum(np.diag(cov)[0:4 * nm:4], 0))
    _, _, _, model = _evaluate(p, x, w, t, tn, nm, want_model=True)
    resid = (x - model) * w

    wn = np.hypot(om, sig)
    fn = wn / (2 * np.pi)
    zeta = sig / wn
    stds = np.array([pole_to_modal(sig[k], om[k], cov[4 * k:4 * k + 2, 4 * k:4 * k + 2])[2:] for k in range(nm)])
    fn_std, zeta_std = stds[:, 0].copy(), stds[:, 1].copy()
    scale = _colored_noise_scale(resid, w, fsr, om / (2 * np.pi), sig / np.pi, noise)
    fn_std *= scale
    zeta_std *= scale

    # --- classify, flag, report -------------------------------------------------------------
    amp = np.hypot(a, b)
    phase = np.arctan2(-b, a)
    tones = (sig <= 2 * sig_std) | (sig <= 0)
    # nuisance components stay in the model but are not modes: baseline wander (under two cycles
    # in the fitted span) and short transients (under 1.5 cycles above the noise) beside a
    # stronger mode
    alive = np.minimum(t[-1], np.log(np.maximum(np.hypot(a, b) / max(noise, 1e-300), 1.0))
                       / np.maximum(sig, 1e-300))
    e_fit = _mode_energy(a, b, sig, t)
    wander = om / (2 * np.pi) * t[-1] < 2
    transient = (om / (2 * np.pi) * alive < 1.5) & (e_fit < e_fit.max())
    nuisance = (wander | transient) & ~tones
    order = np.argsort(fn)
    report, mode_flags, rejected = [], [], []
    fd_all = om / (2 * np.pi)
    for k in order:
        if tones[k] or nuisance[k]:
            continue
        if band is not None and not band[0] <= fn[k] <= band[1]:
            continue
        mf = []
        if scale[k] > 1:
            mf.append("colored_noise")
        t_alive = min(t[-1], np.log(max(amp[k] / max(noise, 1e-300), 1.0)) / sig[k])
        if fd_all[k] * t_alive < FEW_CYCLES:
            mf.append("few_cycles")
        if fsr / fn[k] < MIN_FS_OVER_FN:
            mf.append("resolution_limited")
        bw = sig / np.pi  # half-power bandwidth, Hz
        near = [j for j in range(nm) if j != k and abs(fd_all[j] - fd_all[k]) < max(3 * (bw[k] + bw[j]),
                                                                                   2.0 / t[-1])]
        if near:
            mf.append("close_modes")
        if "clipped" in flags:
            mf.append("clipped")
        if zeta_std[k] > MAX_REL_ZETA_STD * zeta[k]:
            rejected.append({"fn_hz": fn[k], "zeta": zeta[k], "zeta_std": zeta_std[k]})
            continue
        report.append(k)
        mode_flags.append(mf)
    if n_modes is not None and len(report) > n_modes:  # a nuisance pole may have wandered in: keep the strongest
        e_rep = np.array([e_fit[k] for k in report])
        top = sorted(np.argsort(-e_rep)[:n_modes])
        report = [report[j] for j in top]
        mode_flags = [mode_flags[j] for j in top]
    if not report:
        od = _overdamped_try(x_all[i0:], fsr, rec, idx, flags)
        if od is not None:
            return od
        if rejected:
            r0 = rejected[0]
            raise FitError(f"damping is too uncertain to report: the mode at {r0['fn_hz']:.6g} Hz has zeta "
                           f"{r0['zeta']:.3g} +- {r0['zeta_std']:.2g} (relative std above {MAX_REL_ZETA_STD}); "
                           "record a longer or cleaner decay")
        if (tones | nuisance).any() and not rejected:
            ks = int(np.argmax(e_fit))
            if wander[ks]:
                cyc = fd_all[ks] * t[-1]
                raise FitError(f"the record is too short: it spans {cyc:.2g} cycles of its strongest component "
                               f"({fd_all[ks]:.4g} Hz in {t[-1]:.3g} s above the noise); at least 2 cycles are needed "
                               "(a longer record, or less damping, is needed for fn and zeta)")
            if not tones.any():
                raise FitError("no decaying mode: only baseline wander or short transients stand out of the noise")
            raise FitError(f"no decaying mode: only stationary tones at {np.round(fd_all[tones], 4).tolist()} Hz")
        raise FitError("no decaying mode" + (f" inside band={band}" if band else "") + " stands out of the noise")

    extras = {"noise_std": noise, "start_s": i0 / fsr + rec.t0, "start_found": how,
              "fit_span_s": float(t[-1]), "n_samples_used": int(w.sum()),
              "tones_hz": fd_all[tones].tolist(), "channel": rec.channels[idx].name,
              "nuisance": [{"fn_hz": fn[k], "zeta": zeta[k], "why": "baseline wander" if wander[k] else "transient"}
                           for k in np.flatnonzero(nuisance)],
              "rejected_modes": rejected, "notes": notes,
              "band_hz": None if band_asked is None else [float(band_asked[0]), float(band_asked[1])]}
    ik = np.asarray(report)
    fn_r, zeta_r = fn[ik].copy(), zeta[ik].copy()
    fn_std_r, zeta_std_r = fn_std[ik].copy(), zeta_std[ik].copy()
    # nonlinear damping checks on the strongest mode, isolated from the others
    kd = ik[int(np.argmax(amp[ik]))]
    pos = int(np.flatnonzero(ik == kd)[0])
    iso = x - model + _mode_model(p, kd, t)
    nl = _nonlinear_damping(iso, fsr, fd_all[kd], noise, t_end=t[-1])
    if nl.get("coulomb"):
        mode_flags[pos].append("coulomb_friction")
        fn_r[pos] = fd_all[kd]
        zeta_r[pos] = np.nan
        zeta_std_r[pos] = np.nan
        extras["friction_decay_per_cycle"] = nl["decay_per_cycle"]
        extras["friction_decay_per_cycle_std"] = nl["decay_per_cycle_std"]
        extras["friction_displacement"] = nl["decay_per_cycle"] / 4.0
    if nl_pre.get("amplitude_dependent"):
        nl = nl_pre
        kd_in = [j for j, k in enumerate(ik) if abs(fd_all[k] - nl_pre["fd"]) < 0.2 * nl_pre["fd"]]
        pos = kd_in[0] if kd_in else pos
    if nl.get("amplitude_dependent"):
        mode_flags[pos].append("amplitude_dependent")
    if "zeta_vs_amplitude" in nl:
        extras["zeta_vs_amplitude"] = nl["zeta_vs_amplitude"]
    resid_all = x - model
    tables = []
    for j, k in enumerate(ik):  # every reported mode, isolated from the others
        if np.isfinite(zeta_r[j]):
            tables.append(_add_backbone(extras, mode_flags[j], resid_all + _mode_model(p, k, t), fsr, fn[k], zeta[k],
                                        noise, j))
    tables = [b for b in tables if b is not None]
    if tables:
        import pandas as pd
        extras["backbone"] = pd.concat(tables, ignore_index=True)
    if np.any(fn_r >= 0.499 * fsr):
        raise FitError(f"ringdown: a mode at {float(np.max(fn_r)):.4g} Hz is at the Nyquist limit (fs/2 = {fsr / 2:g} Hz): "
                       "aliased or unresolved; sample faster (at least 10 x the frequency)")
    extras.setdefault("channel", rec.channels[idx].name)
    est = ModalEstimate(fn=fn_r, zeta=zeta_r, fn_std=fn_std_r, zeta_std=zeta_std_r, method="ml",
                        flags=tuple(flags), mode_flags=tuple(tuple(m) for m in mode_flags), amplitude=amp[ik],
                        phase=phase[ik], unit=rec.channels[idx].unit, extras=extras)
    _warn_flags(est, rejected)
    tick(1.0)
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
    from scipy.signal import welch
    n = int(w.sum())
    scale = np.ones(fd.size)
    if n < 256 or noise <= 0:
        return scale
    nper = int(min(4096, 2 ** int(np.log2(n // 8))))
    f, pxx = welch(resid, fs=fs, nperseg=nper)
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


def _nonlinear_damping(x, fs, fd, noise, t_end):
    """Coulomb (linear envelope) and amplitude-dependent damping from the cycle amplitudes."""
    out: dict = {}
    tp, ap = cycle_peaks(x, fs, fd)
    ok = ap > 10 * noise
    # only the leading run of regular half cycles: where another component (a leaked neighbour,
    # noise) takes over, the spacing of the extremes goes astray
    cut = False
    if tp.size > 2:
        dt = np.diff(tp) * 2 * fd  # in half periods; a missed extreme gives 3, a phase jump 1.5
        bad = np.flatnonzero((np.abs(dt - np.round(dt)) > 0.25) | (np.round(dt) < 1))
        bad = bad[ok[bad + 1]]
        if bad.size:
            ok[bad[0] + 1:] = False
            cut = True
    tp, ap = tp[ok], ap[ok]
    if tp.size < 8:
        return out
    # exponential vs linear envelope, both fitted to the amplitudes themselves
    lin = np.polyfit(tp, ap, 1)
    r_lin = ap - np.polyval(lin, tp)
    wts = ap  # log fit weighted by amplitude: least squares on the amplitudes to first order
    ex = np.polyfit(tp, np.log(ap), 1, w=wts)
    r_exp = ap - np.exp(np.polyval(ex, tp))
    rss_lin, rss_exp = float(r_lin @ r_lin), float(r_exp @ r_exp)
    t_zero = -lin[1] / lin[0] if lin[0] < 0 else np.inf
    after = x[int(min(x.size, np.ceil((t_zero + 1.5 / fd) * fs))):]
    # dry friction stops the motion: the linear envelope reaches zero just after the last cycle and
    # the mass then stays put (beating of close modes also looks linear for a while, but goes on)
    stuck = (not cut and tp[-1] <= t_zero <= tp[-1] + 3 / fd and after.size >= fs / fd
             and np.std(after) < 3 * noise)
    if stuck and rss_lin < 0.2 * rss_exp:
        slope_std = np.sqrt(rss_lin / max(tp.size - 2, 1) / np.sum((tp - tp.mean()) ** 2))
        out["coulomb"] = True
        out["peak_times"] = tp
        out["decay_per_cycle"] = float(-lin[0] / fd)
        out["decay_per_cycle_std"] = float(slope_std / fd)
        return out
    # local damping over groups of cycles
    g = max(3, tp.size // 8)
    rows, freqs = [], []
    for i in range(0, tp.size - g + 1, g):
        tt, aa = tp[i:i + g], ap[i:i + g]
        sl = np.polyfit(tt, np.log(aa), 1)[0]
        delta = -sl / fd
        rows.append((float(np.exp(np.mean(np.log(aa)))), float(delta / np.sqrt(4 * np.pi ** 2 + delta ** 2))))
        # the group's own frequency: half cycles counted between its first and last extreme
        halves = np.round((tt[-1] - tt[0]) * 2 * fd)
        freqs.append(halves / (2 * (tt[-1] - tt[0])) if tt[-1] > tt[0] else np.nan)
    fq = np.asarray(freqs)
    if len(rows) >= 4 and np.isfinite(fq).all():
        # frequency versus amplitude: a stiffening or softening structure chirps as it decays, and a
        # sum of close 'modes' would mimic that; the slope on log amplitude must stand out of the
        # groups' scatter (4 std) and move fn by more than 0.2 %
        amp = np.array([r[0] for r in rows])
        for X in (np.log(amp), amp ** 2):  # friction-like (log) or cubic-stiffness-like (A^2) trends
            if np.ptp(X) <= 0:
                continue
            c = np.polyfit(X, fq, 1)
            res = fq - np.polyval(c, X)
            se = np.sqrt(res @ res / max(len(rows) - 2, 1) / np.sum((X - X.mean()) ** 2)) + 1e-300
            if abs(c[0]) / se > 4 and abs(c[0]) * np.ptp(X) > 2e-3 * np.mean(fq):
                out["frequency_dependent"] = True
    if len(rows) >= 3:
        amp_g = np.array([r[0] for r in rows])
        z_g = np.array([r[1] for r in rows])
        out["zeta_vs_amplitude"] = [{"amplitude": a_, "zeta": z_} for a_, z_ in rows]
        X = np.log(amp_g)
        if np.ptp(X) > 0:
            c = np.polyfit(X, z_g, 1)
            res = z_g - np.polyval(c, X)
            se = np.sqrt(res @ res / max(len(rows) - 2, 1) / np.sum((X - X.mean()) ** 2)) + 1e-300
            change = abs(c[0]) * np.ptp(X) / max(np.mean(np.abs(z_g)), 1e-300)
            if abs(c[0]) / se > 4 and change > 0.2:
                out["amplitude_dependent"] = True
    return out


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
                 stacklevel=4)
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
                 f"({ra:.4g}, {rb:.4g} 1/s), no natural frequency is reported", stacklevel=4)
    return est


def _warn_flags(est: ModalEstimate, rejected):
    serious = [f for f in est.flags if f not in ("noise_floor", "start_detected")]
    msgs = [f"{f}: {FLAG_TEXT.get(f, f)}" for f in serious]
    if rejected:
        msgs.append(f"{len(rejected)} mode(s) left out: damping relative std above {MAX_REL_ZETA_STD}")
    if msgs:
        warn_quality("ringdown: " + "; ".join(msgs), stacklevel=4)


def ringdown_crb(*, fn: float, zeta: float, fs: float, duration: float, amplitude: float = 1.0,
                 phase: float = 0.0, noise_std: float | None = None, snr_db: float | None = None) -> dict:
    """Cramer-Rao bound on fn and zeta for one damped sinusoid in white Gaussian noise.

    The signal is ``amplitude * exp(-zeta wn t) cos(wd t + phase)`` sampled at ``fs`` for
    ``duration`` s; the noise std is given, or follows from ``snr_db`` = 10 log10(A^2 / (2 s^2)).
    The bound is the inverse Fisher information of (sigma, wd, a, b), mapped to fn and zeta.
    Use it to plan a test: the std any unbiased estimator can reach.
    Returns dict with fn_std, zeta_std (and fn, zeta).
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
