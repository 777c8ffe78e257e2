"""fit_modes' estimation machinery: LSCF poles over model orders, the stabilisation diagram, the
variable-projection maximum-likelihood polish of poles, residues and residual terms, its Fisher
covariance, the Wald screen of unsupported poles and the residual search for missed ones."""

from __future__ import annotations

import numpy as np

from ._lm import levenberg_marquardt
from ._poles import pole_to_modal
from .limits import MAX_REL_ZETA_STD

STABLE_DF = 0.01     # pole frequency within 1 % of one at the previous order
STABLE_DZ = 0.05     # and damping within 5 %
FALSE_ALARM = 0.01          # chance per fit that noise alone passes the amplitude test for a mode
DETECT_FRF = 30.0  # a mode found in the residual must lower the weighted residual sum of squares this much


def _lscf_poles(f, H, max_order):
    """Poles for every even order up to max_order (reduced normal equations, least-squares complex
    frequency domain, common denominator)."""
    w = 2 * np.pi * f
    dt = 1 / (2 * f[-1])
    Om = np.exp(-1j * w * dt)
    n = max_order
    X = Om[:, None] ** np.arange(n + 1)
    Rs, Ss, Ts = [], [], []
    for o in range(H.shape[0]):
        # each line weighted by 1/(smooth trend of |H|): the equation error becomes about relative,
        # so a weak mode (high frequency in a receptance) counts as much as a strong one, while
        # noisy anti-resonances (where |H| itself is near zero) are not blown up
        lf = np.log(f)
        trend = np.polyval(np.polyfit(lf, np.log(np.maximum(np.abs(H[o]), 1e-300)), 2), lf)
        wt = np.exp(-trend)
        Xw = X * wt[:, None]
        Y = -(H[o] * wt)[:, None] * X
        Rs.append(np.real(Xw.conj().T @ Xw))
        Ss.append(np.real(Xw.conj().T @ Y))
        Ts.append(np.real(Y.conj().T @ Y))
    out = {}
    for order in range(2, n + 1, 2):
        k = order + 1
        M = np.zeros((k, k))
        for R, S, T in zip(Rs, Ss, Ts):
            M += T[:k, :k] - S[:k, :k].T @ np.linalg.solve(R[:k, :k], S[:k, :k])
        try:
            a = np.r_[-np.linalg.solve(M[:order, :order], M[:order, order]), 1.0]
        except np.linalg.LinAlgError:
            continue
        if not np.isfinite(a).all():
            continue
        z = np.roots(a[::-1])
        z = z.astype(complex)
        z = z[np.isfinite(z) & (np.abs(z) > 0)]
        lam = -np.log(z) / dt
        lam = lam[(lam.imag > 0) & (lam.real < 0)]
        fp = np.abs(lam) / (2 * np.pi)
        keep = (fp >= f[0]) & (fp <= f[-1])
        out[order] = lam[keep]
    return out


def _stabilise(poles_by_order):
    """Label poles stable against the previous order; cluster stable poles across orders."""
    orders = sorted(poles_by_order)
    table = []  # (order, f, zeta, status) with status 'o' new, 'f' frequency, 's' stable
    stable = []
    prev = None
    for n in orders:
        lam = poles_by_order[n]
        for l in lam:
            f, z = abs(l) / (2 * np.pi), -l.real / abs(l)
            status = "o"
            if prev is not None and prev.size:
                fp = np.abs(prev) / (2 * np.pi)
                zp = -prev.real / np.abs(prev)
                j = int(np.argmin(np.abs(fp - f)))
                if abs(fp[j] - f) <= STABLE_DF * f:
                    status = "f"
                    if abs(zp[j] - z) <= STABLE_DZ * z:
                        status = "s"
                    # frequency-stable poles form the clusters: in noise a true mode's damping
                    # scatters across orders by more than 5 %, its frequency does not
                    stable.append((n, l))
            table.append((n, f, z, status))
        prev = lam
    clusters = []
    for n, l in sorted(stable, key=lambda p: abs(p[1])):
        f = abs(l) / (2 * np.pi)
        if clusters and abs(f - clusters[-1]["f"]) <= STABLE_DF * f:
            c = clusters[-1]
            c["poles"].append(l)
            c["orders"].add(n)
            c["f"] = float(np.median(np.abs(c["poles"]))) / (2 * np.pi)
        else:
            clusters.append({"f": f, "poles": [l], "orders": {n}})
    return table, clusters


def _basis(w, lam):
    """Complex basis columns (n_lines, 2 m + 6) for real coefficients: modes (u, v) and residuals."""
    iw = 1j * w
    cols = []
    for l in lam:
        a = 1 / (iw - l)
        b = 1 / (iw - np.conj(l))
        cols += [a + b, 1j * (a - b)]
    cols += [1 / iw ** 2, 1j / iw ** 2, np.ones_like(iw), 1j * np.ones_like(iw), iw, 1j * iw]
    return np.column_stack(cols)


def _real(B):
    return np.vstack([B.real, B.imag])


def _lam(theta):
    return -theta[0::2] + 1j * theta[1::2]


def _line_weights(lw, nf):
    """The per-line weights as a column for the stacked (real; imaginary) rows (ones by default)."""
    return np.ones((2 * nf, 1)) if lw is None else np.r_[lw, lw][:, None]


def _varpro(theta, w, Hw, lw=None):
    """Weighted residual of the best linear fit for fixed poles (all outputs share the basis)."""
    lw2 = _line_weights(lw, w.size)
    A = _real(_basis(w, _lam(theta))) * lw2
    Y = np.vstack([Hw.real.T, Hw.imag.T]) * lw2  # (2 nf, n_out), divided by each output's and line's noise std
    coef, *_ = np.linalg.lstsq(A, Y, rcond=None)
    return (Y - A @ coef).ravel(order="F"), coef


def _full_jacobian(w, theta, coef, sw, lw=None):
    """Jacobian of the weighted real residual model w.r.t. (sigma, wd per mode) and all linear
    coefficients (``coef`` unweighted, one column per output); rows stacked as in _varpro."""
    lam = _lam(theta)
    m = lam.size
    iw = 1j * w
    B = _basis(w, lam)
    n_out = coef.shape[1]
    P_nl = 2 * m
    P_lin = B.shape[1]
    nf = w.size
    J = np.zeros((2 * nf * n_out, P_nl + P_lin * n_out))
    for o in range(n_out):
        rows = slice(2 * nf * o, 2 * nf * (o + 1))
        c = coef[:, o]
        for r, l in enumerate(lam):
            R = c[2 * r] + 1j * c[2 * r + 1]
            da = R / (iw - l) ** 2          # d/d lambda
            db = np.conj(R) / (iw - np.conj(l)) ** 2
            d_sigma = -(da + db)             # lambda = -sigma + i wd
            d_wd = 1j * da - 1j * db
            J[rows, 2 * r] = np.r_[d_sigma.real, d_sigma.imag] * sw[o]
            J[rows, 2 * r + 1] = np.r_[d_wd.real, d_wd.imag] * sw[o]
        J[rows, P_nl + P_lin * o:P_nl + P_lin * (o + 1)] = _real(B) * sw[o]
        J[rows] *= _line_weights(lw, nf)
    return J


def _fisher_information(w, theta, coef, sw, lw=None):
    """J^T J of ``_full_jacobian`` built block by block, without the (rows x parameters) Jacobian: each
    output's linear coefficients touch only that output's rows, so their block is sw_o^2 A^T A of the
    one shared basis A, the pole-pole block sums the outputs' pole columns, and the cross blocks are
    each output's pole columns against A. Equal to J.T @ J to round-off."""
    lam = _lam(theta)
    m, n_out = lam.size, coef.shape[1]
    lw2 = _line_weights(lw, w.size)
    A = _real(_basis(w, lam)) * lw2
    p_nl, p_lin = 2 * m, A.shape[1]
    F = np.zeros((p_nl + p_lin * n_out,) * 2)
    AtA = A.T @ A
    iw = (1j * w)[:, None]
    da = 1 / (iw - lam[None, :]) ** 2
    db = 1 / (iw - np.conj(lam)[None, :]) ** 2
    for o in range(n_out):
        R = coef[0:p_nl:2, o] + 1j * coef[1:p_nl:2, o]
        a, b = da * R[None, :], db * np.conj(R)[None, :]
        d = np.empty((w.size, p_nl), complex)
        d[:, 0::2] = -(a + b)           # d/d sigma (lambda = -sigma + i wd)
        d[:, 1::2] = 1j * (a - b)       # d/d wd
        Jn = _real(d) * (lw2 * sw[o])
        lin = slice(p_nl + p_lin * o, p_nl + p_lin * (o + 1))
        F[:p_nl, :p_nl] += Jn.T @ Jn
        F[:p_nl, lin] = Jn.T @ A * sw[o]
        F[lin, :p_nl] = F[:p_nl, lin].T
        F[lin, lin] = AtA * sw[o] ** 2
    return F


def _polish(w, H, lam0, sw, lw=None):
    """Poles by variable projection (residues and residual terms solved linearly inside), with the
    decay rate as exp(q) so it stays positive; Levenberg-Marquardt (``_lm``) on Kaufman's Jacobian.

    One QR of the basis per pole set serves both the residual and the Jacobian (MINPACK asks for
    both at each accepted point), and the evaluations are capped at 15 per parameter: a well-posed
    fit from the stabilisation's start converges in far fewer; a pole that runs away (towards zero
    or huge damping, out of the band) is pruned by the caller instead of being chased."""
    from scipy.linalg import solve_triangular
    Hw = H * sw[:, None]
    lw2 = _line_weights(lw, w.size)
    Y = np.vstack([Hw.real.T, Hw.imag.T]) * lw2  # (2 nf, n_out)
    sig0 = np.maximum(-lam0.real, 1e-6 * np.abs(lam0.imag))
    q0 = np.column_stack([np.log(sig0), lam0.imag]).ravel()

    q_hi = np.log(10 * w[-1])

    def theta_of(q):
        th = q.copy()
        th[0::2] = np.exp(np.clip(q[0::2], -40.0, q_hi))  # a decay rate between ~0 and 10 w_max
        th[1::2] = np.clip(q[1::2], 1e-3 * w[0], 10 * w[-1])
        return th

    cache: dict = {}

    def at(q):
        key = q.tobytes()
        if cache.get("key") != key:
            th = theta_of(q)
            A = _real(_basis(w, _lam(th))) * lw2
            Q, R = np.linalg.qr(A)
            QtY = Q.T @ Y
            d = np.abs(np.diag(R))
            if d.min() > 1e-12 * d.max():
                coef = solve_triangular(R, QtY)
            else:  # (nearly) collinear basis: the minimum-norm solution
                coef = np.linalg.lstsq(A, Y, rcond=None)[0]
            cache.update(key=key, th=th, Q=Q, coef=coef, r=(Y - Q @ QtY).ravel(order="F"))
        return cache

    def fun(q):
        return at(q)["r"]

    def normal(q):
        c = at(q)
        A, g = _kaufman_normal(c["th"], w, c["Q"], c["coef"], lw2, c["r"])
        d = np.ones(q.size)
        d[0::2] = c["th"][0::2]       # d/dq = sigma d/dsigma
        return A * np.outer(d, d), g * d
    scale = np.column_stack([np.ones(lam0.size), np.maximum(sig0, w[1] - w[0])]).ravel()
    q, _ = levenberg_marquardt(fun, normal, q0, scale, max_nfev=15 * (q0.size + 1))
    c = at(q)
    return c["th"], c["coef"], c["r"]


def _kaufman_normal(theta, w, Q, coef, lw2, r):
    """The normal equations (J^T J, J^T r) of Kaufman's variable-projection Jacobian J = -P_perp
    (dA/dtheta) c, over (sigma, wd) per mode, without forming J (rows x 2m for every output).

    The derivative columns of a mode's two basis columns do not depend on the output: with D (2 nf x
    4m: per mode and parameter, the derivatives of the u and v columns), G = D^T P_perp D = D^T D -
    (Q^T D)^T (Q^T D) serves every output, J^T J = sum over outputs of C_o^T G C_o with each output's
    residue coefficients C_o, and J^T r = -C^T D^T r since the residual already lies in P_perp's range."""
    lam = _lam(theta)
    m, n_out, nf = lam.size, coef.shape[1], w.size
    iw = (1j * w)[:, None]
    da = 1 / (iw - lam[None, :]) ** 2
    db = 1 / (iw - np.conj(lam)[None, :]) ** 2
    s, d = da + db, da - db
    Dc = np.empty((nf, m, 2, 2), complex)   # line, mode, parameter (sigma, wd), column (u, v)
    Dc[:, :, 0, 0], Dc[:, :, 0, 1] = -s, -1j * d      # d/d sigma, lambda = -sigma + i wd
    Dc[:, :, 1, 0], Dc[:, :, 1, 1] = 1j * d, -s       # d/d wd
    D = np.concatenate([Dc.real.reshape(nf, -1), Dc.imag.reshape(nf, -1)]) * lw2
    QtD = Q.T @ D
    G = (D.T @ D - QtD.T @ QtD).reshape(m, 2, 2, m, 2, 2)
    C = coef[:2 * m].reshape(m, 2, n_out)
    A = np.einsum("rko,rpksql,slo->rpsq", C, G, C).reshape(2 * m, 2 * m)
    DtR = (D.T @ r.reshape(n_out, 2 * nf).T).reshape(m, 2, 2, n_out)
    g = -np.einsum("rko,rpko->rp", C, DtR).reshape(2 * m)
    return A, g


LOCAL_LINES = 20     # a mode's neighbourhood: +-this many lines, or
LOCAL_SIGMAS = 60.0  # +-this many decay rates (12.5 half-power bandwidths), if wider: where its information lies


def _covariance(w, theta, coef, r, sw, lw=None):
    """Parameter covariance (poles, then each output's linear coefficients, unweighted) and the
    residual variance, from the Fisher information of the weighted fit.

    A mode's parameters are scaled by the residual variance near it (``_local_variance``), not the
    band's: its information comes from the lines around it, and misfit or noise far away (another
    mode's nonlinearity, a band edge) must not move its std, nor its acceptance, with the band."""
    JtJ = _fisher_information(w, theta, coef / sw[None, :], sw, lw)
    dof = max(r.size - JtJ.shape[0], 1)
    s2 = float(r @ r) / dof
    try:
        cov = np.linalg.inv(JtJ)
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(JtJ)
    d = np.full(cov.shape[0], np.sqrt(s2))
    m, n_out = theta.size // 2, coef.shape[1]
    p_lin = 2 * m + 6
    for j, s2_j in enumerate(_local_variance(w, theta, r, n_out, r.size / dof)):
        d[2 * j:2 * j + 2] = np.sqrt(s2_j)
        for o in range(n_out):
            d[2 * m + p_lin * o + 2 * j:2 * m + p_lin * o + 2 * j + 2] = np.sqrt(s2_j)
    return cov * np.outer(d, d), s2


def _local_variance(w, theta, r, n_out, dof_factor):
    """Each mode's residual variance: the weighted residual over the lines within LOCAL_LINES (or
    LOCAL_SIGMAS decay rates, if wider) of its frequency, with the band's degrees-of-freedom correction."""
    nf = w.size
    res = r.reshape(n_out, 2, nf)
    p = np.sum(res ** 2, axis=(0, 1))   # per line, real and imaginary parts of every output
    dw = float(np.median(np.diff(w))) if nf > 1 else 1.0
    out = []
    for sigma, wd in zip(theta[0::2], theta[1::2]):
        near = np.abs(w - wd) <= max(LOCAL_LINES * dw, LOCAL_SIGMAS * sigma)
        out.append(float(np.mean(p[near]) / (2 * n_out) * dof_factor) if near.any() else
                   float(np.mean(p) / (2 * n_out) * dof_factor))
    return out


def _unsupported(theta, coef, cov, sw, tau, n_lines, n_out, band, df):
    """Poles the data does not support, as (index, reason dict).

    A mode is kept when (1) its residues are significant: the Wald statistic of its 2 n_out real
    residue coefficients exceeds the chi-square level whose false-alarm chance is FALSE_ALARM
    divided by the lines searched (the pole's place was chosen among them: Bonferroni); and (2)
    its zeta is known to better than MAX_REL_ZETA_STD (relative std); (3) no stronger mode lies
    within two lines of it. Poles outside the band
    or with zero, negative or over-critical damping are left to the physical screen."""
    from scipy.stats import chi2
    m = theta.size // 2
    P_nl = 2 * m
    P_lin = coef.shape[0]
    level = float(chi2.isf(FALSE_ALARM / max(n_lines, 1), 2 * n_out))
    cu = coef / sw[None, :]
    out, tested = [], []
    for k in range(m):
        sig = theta[2 * k] - (1.0 / tau if tau else 0.0)
        wd = theta[2 * k + 1]
        wn = np.hypot(sig, wd)
        fn, zeta = wn / (2 * np.pi), sig / wn
        if not (band[0] <= fn <= band[1]) or not 0 < zeta < 0.5:
            continue
        idx = [P_nl + P_lin * o + 2 * k + j for o in range(n_out) for j in (0, 1)]
        c = np.array([cu[2 * k + j, o] for o in range(n_out) for j in (0, 1)])
        try:
            wald = float(c @ np.linalg.solve(cov[np.ix_(idx, idx)], c))
        except np.linalg.LinAlgError:
            wald = 0.0
        zeta_std = pole_to_modal(sig, wd, cov[2 * k:2 * k + 2, 2 * k:2 * k + 2])[3]
        why = None
        if not wald > level:
            why = (f"amplitude not significant: Wald {wald:.3g} <= {level:.3g} (chi-square, {2 * n_out} dof, "
                   f"false-alarm {FALSE_ALARM:g} per fit over {n_lines} lines)")
        elif not zeta_std <= MAX_REL_ZETA_STD * zeta:
            why = f"damping too uncertain: zeta {zeta:.3g} +- {zeta_std:.2g} (relative std above {MAX_REL_ZETA_STD})"
        if why:
            out.append((k, {"fn_hz": float(fn), "zeta": float(zeta), "zeta_std": float(zeta_std),
                            "wald": wald, "reason": why}))
        else:
            tested.append((k, fn, zeta, float(zeta_std), wald))
    # two poles less than two lines apart cannot be told apart by the measurement: the one with the
    # weaker residue is a distortion of the other's peak (leakage, a window), not a second mode
    for k, fk, zk, zsk, wk in tested:
        rival = [(w2, f2) for k2, f2, _, _, w2 in tested if k2 != k and abs(f2 - fk) < 2 * df and w2 > wk]
        if rival:
            w2, f2 = max(rival)
            out.append((k, {"fn_hz": float(fk), "zeta": float(zk), "zeta_std": zsk, "wald": wk,
                            "reason": f"unresolved: {abs(f2 - fk):.3g} Hz from the stronger mode at {f2:.6g} Hz, "
                                      f"under two lines ({2 * df:.3g} Hz)"}))
    return out


def _astray_poles(theta, cov, astray, tau, band, refused) -> list:
    """The in-band poles (not yet refused) whose own neighbourhood does not hold them (``_local_refit``:
    fitted alone on the lines around them, the other modes subtracted, they leave their peak), as
    (index, reason dict). A mode is a peak of its own; a pole the band fit keeps only as a share of the
    baseline (a misfit spread over the band, a runaway pole's company) is not one."""
    out = []
    for k in astray:
        if k in refused:
            continue
        sig = theta[2 * k] - (1.0 / tau if tau else 0.0)
        wd = theta[2 * k + 1]
        wn = np.hypot(sig, wd)
        fn, zeta = wn / (2 * np.pi), sig / wn
        if not (band[0] <= fn <= band[1]) or not 0 < zeta < 0.5:
            continue   # left to the physical screen
        zeta_std = pole_to_modal(sig, wd, cov[2 * k:2 * k + 2, 2 * k:2 * k + 2])[3]
        out.append((k, {"fn_hz": float(fn), "zeta": float(zeta), "zeta_std": float(zeta_std), "wald": float("nan"),
                        "reason": "not held by its own neighbourhood: fitted alone on the lines around it (the "
                                  "other modes subtracted), the pole leaves its peak"}))
    return out


def _residual_search(w, H, theta, coef, r, sw, n_modes, max_add=4, lw=None):
    """Add modes that the stabilisation missed (weak ones, near the noise): where the weighted
    residual, summed over outputs and a few lines, stands out of its chi-square level, start a pole
    there and keep it if the fit improves by more than DETECT_FRF (or while n_modes asks for more)."""
    n_out, nf = H.shape
    added = 0
    signal = float(np.sum(np.abs(H * sw[:, None] * (1.0 if lw is None else lw)) ** 2))
    for _ in range(max_add):
        m = theta.size // 2
        if n_modes is not None and m >= n_modes:
            break
        if float(r @ r) < 1e-16 * signal:  # the fit is exact to round-off: nothing is missing
            break
        res = r.reshape(n_out, 2, nf)
        e = np.sum(res[:, 0] ** 2 + res[:, 1] ** 2, axis=0)  # per line, about 2 n_out / 2 = n_out on average
        s2 = float(np.mean(e)) / n_out if np.mean(e) > 0 else 1.0
        e = e / s2
        win = 5
        ms = np.convolve(e, np.ones(win), mode="same")
        edge = max(win, int(0.03 * nf))  # the band's ends belong to the residual terms, not to new modes
        ms[:edge] = ms[-edge:] = 0.0
        k = int(np.argmax(ms))
        expect = n_out * win
        if n_modes is None and ms[k] < expect + 5 * np.sqrt(expect):
            break
        wk = w[k]
        if np.any(np.abs(theta[1::2] - wk) < 2 * (w[1] - w[0])):
            break
        z0 = max(2 * (w[1] - w[0]) / wk, 0.005)
        lam_new = np.r_[_lam(theta), -z0 * wk + 1j * wk]
        rss_old = float(r @ r)
        th2, c2, r2 = _polish(w, H, lam_new, sw, lw)
        gain = (rss_old - float(r2 @ r2)) / (rss_old / max(r.size - coef.size - theta.size, 1))
        if n_modes is None and gain < DETECT_FRF:
            break
        theta, coef, r = th2, c2, r2
        added += 1
    return theta, coef, r, added


def synthesize_frf_from(f, lam, R, coef, sw, m):
    w = 2 * np.pi * f
    B = _basis(w, lam)
    return (B @ coef).T / sw[:, None]


def _residual_terms(coef, sw, m) -> list[dict]:
    """Per FRF row, the fitted residual terms in the FRF's units: H_res = lower/(iw)^2 + constant + upper iw."""
    c = coef[2 * m:2 * m + 6] / sw[None, :]
    return [{"lower": [float(c[0, r]), float(c[1, r])], "constant": [float(c[2, r]), float(c[3, r])],
             "upper": [float(c[4, r]), float(c[5, r])]} for r in range(c.shape[1])]



def _local_refit(w, H, theta, coef, cov, sw):
    """Each mode again from its own neighbourhood: the lines within LOCAL_LINES (or LOCAL_SIGMAS decay
    rates) of it, the other modes' fitted contributions subtracted and a local set of residual
    terms fitted beside it. Its pole, residues and their covariance replace the band fit's (cross
    terms with other parameters set to 0). The band fit shares its residual terms over the whole band,
    so a wide band bends a weak mode's baseline and its zeta and std moved with the band's reach
    (case1's 34 Hz mode: zeta 2.1e-4 +- 2e-5 in 20-50 Hz, refused in 10-600 Hz); the local fit is the
    same whatever the band holds beyond the neighbourhood. A local fit that fails or runs out of
    the neighbourhood leaves the band fit's values; the modes whose local pole left their own peak
    are returned too (``astray``: the screen asks whether the data supports them)."""
    m, n_out = theta.size // 2, H.shape[0]
    astray: list = []
    if m == 0:
        return theta, coef, cov, astray
    theta, coef, cov = theta.copy(), coef.copy(), cov.copy()
    dw = float(np.median(np.diff(w)))
    B = _basis(w, _lam(theta))
    p_lin = B.shape[1]
    for k in range(m):
        sig, wd = theta[2 * k], theta[2 * k + 1]
        half = max(LOCAL_LINES * dw, LOCAL_SIGMAS * sig)
        near = np.abs(w - wd) <= half
        if near.sum() < 16 or near.mean() > 0.8:
            continue   # too few lines, or the neighbourhood is most of the band: the band fit is local
        others = [c for c in range(2 * m) if c // 2 != k]
        Hk = (H * sw[:, None])[:, near] - (B[near][:, others] @ coef[others]).T
        try:
            # uniform weights inside the neighbourhood: the band's line weights come from the band's
            # residual, and the mode's fit must not depend on what lies beyond its neighbourhood
            th, c, r = _polish(w[near], Hk / sw[:, None], _lam(theta[2 * k:2 * k + 2]), sw)
            ck, _ = _covariance(w[near], th, c, r, sw)
        except (np.linalg.LinAlgError, ValueError):
            continue
        if not (abs(th[1] - wd) < max(2 * sig, 2 * dw) and 0 < th[0] < 3 * sig + dw):
            astray.append(k)   # the local fit moved the pole out of the mode's own peak: the band fit stands
            continue
        idx = [2 * k, 2 * k + 1] + [2 * m + p_lin * o + 2 * k + j for o in range(n_out) for j in (0, 1)]
        loc = [0, 1] + [2 + 8 * o + j for o in range(n_out) for j in (0, 1)]
        theta[2 * k:2 * k + 2] = th
        coef[2 * k:2 * k + 2] = c[0:2]
        cov[idx, :] = 0.0
        cov[:, idx] = 0.0
        cov[np.ix_(idx, idx)] = ck[np.ix_(loc, loc)]
    return theta, coef, cov, astray
