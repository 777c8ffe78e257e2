"""Ring-down start values and model order: subspace (ESPRIT) poles, spectral-peak poles, and the
linear amplitudes with each candidate's share of the fit (steps of :func:`vibmeasure.ringdown`)."""

from __future__ import annotations

import numpy as np

from ..core.errors import FitError

SUBSAMPLE = 100_000  # longer records are first fitted on every q-th sample, then polished in full


def start_poles(x: np.ndarray, c0: int, fsr: float, max_modes: int, n_modes: int | None) -> np.ndarray:
    """Start poles of a decay from sample ``c0`` on (after the last clipped one): ESPRIT's oscillating
    poles, plus the spectrum's peaks ESPRIT missed. They see the oscillation without its offset and
    drift (the fit models both): a drift of a few % of the peak took the subspace's leading
    directions and lost a real beam's fundamental."""
    from ._decay import detrend_linear
    xs = detrend_linear(x[c0:])
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
    return osc


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
    # one SVD gives both the least-squares amplitudes (singular values below eps max(M, N) of the
    # largest dropped, as lstsq) and the pseudo-inverse of the normal matrix (its eigenvalues
    # sv^2 below 1e-15 of the largest dropped, as pinv)
    U, sv, Vt = np.linalg.svd(Aw, full_matrices=False)
    keep = sv > np.finfo(float).eps * max(Aw.shape) * sv[0]
    coef = Vt[keep].T @ ((U[:, keep].T @ (x * w)) / sv[keep])
    res = (x - A @ coef) * w
    k = sig.size
    # each mode's share of the fit: the rise in the residual sum of squares if it were left out
    # (Wald form b' inv(cov_bb) b), in full-record units; unlike its energy this stays small for
    # collinear look-alikes (sidelobes) that cancel each other
    kg = sv ** 2 > 1e-15 * sv[0] ** 2
    G = (Vt[kg].T / sv[kg] ** 2) @ Vt[kg]
    drss = np.empty(k)
    for i in range(k):
        idx = [i, k + i]
        bb = coef[idx]
        try:
            drss[i] = float(bb @ np.linalg.solve(G[np.ix_(idx, idx)], bb))
        except np.linalg.LinAlgError:
            drss[i] = 0.0
    return coef, float(np.sqrt(res @ res / max(w.sum() - A.shape[1], 1))), drss * q

