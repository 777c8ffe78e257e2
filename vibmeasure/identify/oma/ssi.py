"""``oma_ssi``: covariance-driven stochastic subspace identification with a stabilisation diagram,
pole clustering and block-jackknife standard deviations."""

from __future__ import annotations

import numpy as np

from ...core._threads import single_threaded
from ...core._validate import check_band
from ...core.errors import FitError, ParameterError, warn_quality
from ...core.results import ModalEstimate
from ..limits import MAX_REL_ZETA_STD
from ..shapes import mac_pair, mpc, mpd
from ._common import (CLUSTER_DF, CLUSTER_MAC, MAX_ZETA, MIN_CYCLES, MIN_MPC, STAB_DF, STAB_DZ, STAB_MAC, TONE_KURTOSIS,
                      OutputSpectra, _check_duration, _normalise, _outputs, band_kurtosis,
                      harmonic_by_kurtosis)


# --- SSI-cov ------------------------------------------------------------------------------------
def _decimate(Y, fs, band, q_max):
    """Low-pass and decimate so that the band's top sits near 0.4 fs (SSI resolves the band with fewer
    block rows), at most by q_max (the covariances' blocks must keep their samples); the continuous
    poles are unchanged."""
    if band is None:
        return Y, fs, 1
    q = min(int(np.floor(0.4 * fs / band[1])), int(q_max))
    if q < 2:
        return Y, fs, 1
    from scipy.signal import resample_poly
    return resample_poly(Y, 1, q, axis=1), fs / q, q


def _covariances(Y, n_lags, n_blocks):
    """Per block b, sums of y_{k+i} y_k^T over k in the block (i = 0..n_lags) and the counts:
    (n_blocks, n_lags+1, l, l) and (n_blocks, n_lags+1)."""
    l, n = Y.shape
    edges = np.linspace(0, n, n_blocks + 1).astype(int)
    S = np.zeros((n_blocks, n_lags + 1, l, l))
    cnt = np.zeros((n_blocks, n_lags + 1))
    for b in range(n_blocks):
        k0, k1 = edges[b], edges[b + 1]
        for i in range(n_lags + 1):
            k_end = min(k1, n - i)
            if k_end <= k0:
                continue
            S[b, i] = Y[:, k0 + i:k_end + i] @ Y[:, k0:k_end].T
            cnt[b, i] = k_end - k0
    return S, cnt


def _toeplitz(R, s):
    """Block Toeplitz matrix of R_1..R_(2s-1): block (i, j) = R_(s + i - j); R is (2s+1, l, l), or a
    stack (..., 2s+1, l, l) giving a stack of matrices."""
    l = R.shape[-1]
    i, j = np.indices((s, s))
    blocks = R[..., s + i - j, :, :]                         # (..., s, s, l, l)
    return np.swapaxes(blocks, -3, -2).reshape(R.shape[:-3] + (s * l, s * l))


def _poles_at(U, sv, order, l, fs, O=None):
    """Continuous poles (Im > 0) and shapes at one model order from the Toeplitz SVD (or from a given
    observability matrix O)."""
    if O is None:
        O = U[:, :order] * np.sqrt(sv[:order])
    A = np.linalg.lstsq(O[:-l], O[l:], rcond=None)[0]
    mu, psi = np.linalg.eig(A)
    ok = (np.abs(mu) > 0) & (np.abs(mu) < 1) & (mu.imag > 0)
    lam = np.log(mu[ok]) * fs
    phi = (O[:l] @ psi[:, ok])
    return lam, phi


def _modal(lam):
    wn = np.abs(lam)
    return wn / (2 * np.pi), -lam.real / wn


def _stabilisation(U, sv, orders, l, fs, band):
    """Poles of every order with their status against the previous order: 'o' new, 'f' frequency
    stable, 'd' also damping, 's' also shape (MAC); the stable ones ('s' with MPC above MIN_MPC)."""
    table, stable, prev = [], [], None
    for n in orders:
        lam, phi = _poles_at(U, sv, n, l, fs)
        f, z = _modal(lam)
        keep = (f >= band[0]) & (f <= band[1]) & (z > 0) & (z < MAX_ZETA)
        lam, phi, f, z = lam[keep], phi[:, keep], f[keep], z[keep]
        m = mpc(phi) if phi.size else np.array([])
        for k in range(lam.size):
            st = "o"
            if prev is not None and prev[0].size:
                fp, zp, php = prev
                j = int(np.argmin(np.abs(fp - f[k])))
                if abs(fp[j] - f[k]) <= STAB_DF * f[k]:
                    st = "f"
                    if abs(zp[j] - z[k]) <= STAB_DZ * z[k]:
                        st = "d"
                        if mac_pair(php[:, j], phi[:, k]) >= STAB_MAC:
                            st = "s"
            table.append((n, float(f[k]), float(z[k]), st, float(m[k])))
            if st == "s" and m[k] >= MIN_MPC:
                stable.append({"order": n, "lam": lam[k], "f": f[k], "z": z[k], "phi": phi[:, k]})
        prev = (f, z, phi)
    return table, stable


def _cluster(stable, n_orders):
    """Group stable poles into modes, from the highest order down: each pole joins the nearest cluster
    (frequency within CLUSTER_DF, shape MAC >= CLUSTER_MAC) that has no pole of its order yet, else
    starts one, so two close modes seen at one order stay two. Clusters seen at 20 % of the orders
    (at least 3) are modes."""
    clusters = []
    by_order = {}
    for p in stable:
        by_order.setdefault(p["order"], []).append(p)
    for n in sorted(by_order, reverse=True):
        pairs = []
        for i, p in enumerate(by_order[n]):
            for j, c in enumerate(clusters):
                df = abs(p["f"] - c["f"]) / c["f"]
                mac = mac_pair(p["phi"], c["phi"])
                if df <= CLUSTER_DF and mac >= CLUSTER_MAC:
                    pairs.append((df + (1 - mac), i, j))
        used_p, used_c = set(), set()
        for _, i, j in sorted(pairs):
            if i in used_p or j in used_c:
                continue
            used_p.add(i)
            used_c.add(j)
            c = clusters[j]
            c["members"].append(by_order[n][i])
            c["f"] = float(np.median([q["f"] for q in c["members"]]))
        for i, p in enumerate(by_order[n]):
            if i not in used_p:
                clusters.append({"f": p["f"], "phi": p["phi"], "members": [p]})
    need = max(3, int(np.ceil(0.2 * n_orders)))
    modes = [c for c in clusters if len(c["members"]) >= need]
    return sorted(modes, key=lambda c: c["f"]), need


def _representative(c):
    """The member at the cluster's median order (its shape represents the mode) and the cluster's
    estimate: the median fn and zeta over its orders. The median, not the mean: at high orders an
    order now and then carries a pole the noise has pulled, in the data as in a jackknife replicate;
    the median over the orders passes over it, where a mean takes it in and the delete-one jackknife
    (which multiplies each replicate's deviation by n_blocks - 1) inflates it: on the OMA benchmark
    the mean's stated zeta std was 1.4-1.9x its actual error on the three upper modes."""
    orders = sorted(q["order"] for q in c["members"])
    mid = orders[len(orders) // 2]
    rep = dict(next(q for q in c["members"] if q["order"] == mid))
    rep["orders"] = orders
    rep["lam_at"] = {q["order"]: q["lam"] for q in c["members"]}
    rep["fn"] = float(np.median([q["f"] for q in c["members"]]))
    rep["zeta"] = float(np.median([q["z"] for q in c["members"]]))
    return rep


def _replicate_poles(T, V, sv, l, fs, orders):
    """Every replicate's poles at each order, all replicates at once: {order: (lam, phi, ok)} with lam
    (n_b, order), phi (n_b, l, order) and ok marking the physical poles (|mu| < 1, Im > 0). A
    replicate's observability matrix is taken on the full data's right singular vectors, T_b V_n
    S_n^-1/2 (first-order equal to its own SVD's, without the order swaps of near-equal singular
    values that make a re-computed SVD jump). One QR of the largest order's shifted rows serves every
    order: the least-squares A_n = R_n^-1 (Q^T O_down)_n, since the first n columns of O_up are
    Q_n R_n."""
    O = T @ (V[:, :orders[-1]] / np.sqrt(sv[:orders[-1]]))          # (n_b, s l, n_max)
    Q, Rq = np.linalg.qr(O[:, :-l])
    M = np.swapaxes(Q, 1, 2) @ O[:, l:]
    out = {}
    for n in orders:
        try:
            A = np.linalg.solve(Rq[:, :n, :n], M[:, :n, :n])
        except np.linalg.LinAlgError:    # a rank-deficient replicate: the slower least squares
            A = np.array([np.linalg.lstsq(O[b, :-l, :n], O[b, l:, :n], rcond=None)[0] for b in range(O.shape[0])])
        mu, psi = np.linalg.eig(A)
        ok = (np.abs(mu) > 0) & (np.abs(mu) < 1) & (mu.imag > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            lam = np.where(ok, np.log(np.where(ok, mu, 0.5)) * fs, np.nan)
        out[n] = (lam, O[:, :l, :n] @ psi, ok)
    return out


def _replicates(T, V, sv, l, fs, reps):
    """Each replicate's fn and zeta of each mode at every order of its cluster: (n_b, n_modes, n_orders,
    2), NaN where the replicate has no pole within CLUSTER_DF of the full data's pole at that order,
    with shape MAC >= CLUSTER_MAC. A replicate is a small perturbation of the full data, so each
    order's pole is matched to the full data's pole at the same order, not to the cluster."""
    orders = sorted({n for rp in reps for n in rp["orders"]})
    poles = _replicate_poles(T, V, sv, l, fs, orders)
    n_b = T.shape[0]
    width = max(len(rp["orders"]) for rp in reps)
    out = np.full((n_b, len(reps), width, 2), np.nan)
    rows = np.arange(n_b)
    for m, rp in enumerate(reps):
        ref = np.asarray(rp["phi"], complex)
        for a, n in enumerate(rp["orders"]):
            lam, phi, ok = poles[n]
            lam0 = rp["lam_at"][n]
            d = np.where(ok, np.abs(lam - lam0) / abs(lam0), np.inf)
            k = np.argmin(d, axis=1)
            v = phi[rows, :, k]                                   # (n_b, l)
            mac = np.abs(v.conj() @ ref) ** 2 / (np.sum(np.abs(v) ** 2, axis=1) * np.vdot(ref, ref).real)
            hit = (d[rows, k] <= CLUSTER_DF) & (mac >= CLUSTER_MAC)
            wn = np.abs(lam[rows, k])
            out[hit, m, a, 0] = wn[hit] / (2 * np.pi)
            out[hit, m, a, 1] = -lam[rows, k].real[hit] / wn[hit]
    return out


def _jackknife(S, cnt, s, l, fs, reps, V, sv):
    """Block jackknife of the output covariances: the identification repeated with each block left
    out. Each replicate's estimate is, like the full data's, the median over the cluster's orders of
    its poles (a replicate that holds the mode at fewer than 80 % of those orders has lost it); the
    std follows from the replicates' estimates, NaN when more than 20 % of them lost the mode."""
    n_b = S.shape[0]
    tot, ctot = S.sum(axis=0), cnt.sum(axis=0)
    R = (tot[None] - S) / np.maximum(ctot[None] - cnt, 1)[:, :, None, None]
    vals = _replicates(_toeplitz(R, s), V, sv, l, fs, reps)    # (n_b, n_modes, n_orders, 2)
    n_ord = np.array([len(rp["orders"]) for rp in reps])
    import warnings
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # modes a replicate lost: NaN, by design
        # each replicate's estimate is the median over the cluster's orders, like the full-data one
        est = np.nanmedian(vals, axis=2)                    # (n_b, n_modes, 2)
        est[np.isfinite(vals[..., 0]).sum(axis=2) < 0.8 * n_ord] = np.nan
        found = np.isfinite(est[..., 0]).sum(axis=0)
        mean = np.nanmean(est, axis=0)
        out = np.sqrt((n_b - 1) / np.maximum(found, 1)[:, None] * np.nansum((est - mean) ** 2, axis=0))
        out[found < 0.8 * n_b] = np.nan
    return out[:, 0], out[:, 1]


def _tones_near(Y, fs, f_psd, p_psd, fn, zeta, phi) -> list:
    """Harmonics beside a pole: peaks of the mean output PSD within max(5 zeta fn, 5 lines) of it that
    stand 10 dB above the PSD at the pole and whose band is a sinusoid (band kurtosis below
    TONE_KURTOSIS). A pole in the valley between strong harmonics is likely fitted to them; a mode
    under random excitation is itself the peak of its band."""
    df = f_psd[1]
    reach = max(5 * zeta * fn, 5 * df)
    sel = np.flatnonzero(np.abs(f_psd - fn) <= reach)
    if sel.size < 3:
        return []
    at_pole = float(np.interp(fn, f_psd, p_psd))
    out = []
    for i in sel:
        if 0 < i < p_psd.size - 1 and p_psd[i] >= p_psd[i - 1] and p_psd[i] >= p_psd[i + 1] \
                and p_psd[i] >= 10 * at_pole:
            k = band_kurtosis(Y, fs, f_psd[i], max(df, 10 * fs / Y.shape[1]), phi)
            if k < TONE_KURTOSIS:
                out.append({"f_hz": float(f_psd[i]), "kurtosis": float(k),
                            "above_pole_db": float(10 * np.log10(p_psd[i] / at_pole))})
    return out


def _psd_overlay(Y, fs):
    """Mean auto-PSD of the outputs, for the stabilisation plot."""
    from scipy.signal import welch
    nper = int(min(Y.shape[1], 2 ** int(np.log2(max(Y.shape[1] // 8, 64)))))
    f, P = welch(Y, fs=fs, nperseg=nper)
    return f, P.mean(axis=0)


@single_threaded
def oma_ssi(rec, *, band=None, max_order: int = 40, block_rows: int | None = None, channels=None,
            n_blocks: int = 20) -> ModalEstimate:
    """Modes from output-only data by covariance-driven stochastic subspace identification (SSI-cov).

    Poles at every even order up to ``max_order`` that are stable in frequency (1 %), damping (5 %) and
    shape (MAC 0.98, MPC 0.7) are clustered; a cluster seen at a fifth of the orders is a mode (fn and
    zeta the medians over its orders), with stds from a block jackknife of the covariances. A mode
    whose damping's relative std exceeds 0.3, or whose band is a sinusoid (kurtosis below 2.2), is
    refused (``extras["rejected_modes"]``); one beside strong harmonics is flagged ``near_harmonic``
    (docs/methods/oma.md).

    Parameters
    ----------
    rec : Record
        Responses of two or more sensors.
    band : tuple of float, optional
        (lo, hi) Hz: the record is decimated so the band's top sits near 0.4 fs.
    max_order : int
        Highest model order.
    block_rows : int, optional
        Covariance lags 1..2s-1 (default: enough for the order and at least 30).
    channels : list, optional
        Output channels (default every channel that is not a force).
    n_blocks : int
        Blocks of the jackknife.

    Returns
    -------
    ModalEstimate
        fn, zeta, stds, complex shapes (n_out, n_modes) scaled to 1 at their largest component; MPC and
        MPD in ``extras``.

    Raises
    ------
    ParameterError
        For fewer than two outputs or too short a record.
    FitError
        When no mode is left.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> chain = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), modal_zeta=[0.02, 0.02])
    >>> amb = vm.synth.ambient(chain, fs=100.0, duration=300.0, noise=0.05, seed=1)
    >>> est = vm.oma_ssi(amb, band=(1, 40))
    >>> bool(np.allclose(est.fn, chain.modes().fn, rtol=0.01))   # 9.84 and 25.75 Hz, within 2 stds
    True
    """
    Y, names = _outputs(rec, channels, "oma_ssi", 2)
    l = Y.shape[0]
    band = check_band(band, rec.fs) or (0.0, rec.fs / 2)
    orders, s, n_blocks = _ssi_sizes(max_order, block_rows, n_blocks, l)
    _check_duration(Y.shape[1], rec.fs, band[1], "oma_ssi")
    # a narrow low band would decimate a record below what the blocks need: decimate less instead
    Yd, fs_d, q = _decimate(Y, rec.fs, band if band[1] < rec.fs / 2 else None, Y.shape[1] // (8 * n_blocks * s))
    if Yd.shape[1] < 8 * n_blocks * s:
        # each jackknife block must hold several times the 2 s lags of the covariances
        raise ParameterError(f"oma_ssi: {Yd.shape[1]} samples (after decimation by {q}) are too few for "
                             f"block_rows={s} and n_blocks={n_blocks}: at least {8 * n_blocks * s} are needed "
                             f"(a record of {8 * n_blocks * s * q / rec.fs:.4g} s); record longer or lower them")
    S, cnt = _covariances(Yd, 2 * s, n_blocks)
    R = S.sum(axis=0) / cnt.sum(axis=0)[:, None, None]
    U, sv, Vt = np.linalg.svd(_toeplitz(R, s))
    table, stable = _stabilisation(U, sv, orders, l, fs_d, band)
    modes, need = _cluster(stable, len(orders))
    if not modes:
        raise FitError(f"oma_ssi: no mode is stable across model orders 2..{orders[-1]} in band={band}: the "
                       "record holds no resonance there, or too little of it (record longer, or raise max_order)")
    reps = [_representative(c) for c in modes]
    fn_std, zeta_std = _jackknife(S, cnt, s, l, fs_d, reps, Vt.T, sv)
    hw = [max(3 * rp["zeta"] * rp["fn"], 10 * rec.fs / Y.shape[1]) for rp in reps]
    spectra = OutputSpectra(Y)
    kurt = [band_kurtosis(spectra, rec.fs, rp["fn"], h, rp["phi"]) for rp, h in zip(reps, hw)]
    tone = [harmonic_by_kurtosis(k, h, Y.shape[1] / rec.fs) for k, h in zip(kurt, hw)]
    keep, rejected = _screen(reps, fn_std, zeta_std, kurt, tone)
    if not keep:
        raise FitError(f"oma_ssi: no mode in band={band} that the data supports: "
                       + "; ".join(f"{d['fn_hz']:.5g} Hz: {d['reason']}" for d in rejected))
    return _ssi_estimate(rec, spectra, names, [modes[k] for k in keep], [reps[k] for k in keep], fn_std[keep],
                         zeta_std[keep], table, dict(
                             block_rows=s, orders=[orders[0], orders[-1]], n_blocks=n_blocks, decimation=q,
                             min_cluster=need, band_hz=list(band), rejected_modes=rejected))


def _screen(reps, fn_std, zeta_std, kurt, tone):
    """Modes whose damping the blocks reproduce (relative std <= the limit of
    ringdown and fit_modes) and whose band is a random response, not a harmonic (``tone``: band
    kurtosis below TONE_KURTOSIS and below a random band's 0.1 % quantile); the others are listed with
    the reason."""
    keep, rejected = [], []
    for k, rp in enumerate(reps):
        rel = zeta_std[k] / rp["zeta"]
        rp["kurtosis"] = kurt[k]
        if tone[k]:
            why = (f"a harmonic, not a mode: the response in its band has kurtosis {kurt[k]:.2f} (a sinusoid gives "
                   "1.5, a mode's random response 3)")
        elif not np.isfinite(rel):
            why = "lost in more than 20 % of the jackknife replicates: not a stable mode of the data"
        elif rel > MAX_REL_ZETA_STD:
            why = f"damping relative std {rel:.2f} > {MAX_REL_ZETA_STD}: the data does not support the mode"
        else:
            keep.append(k)
            continue
        rejected.append({"fn_hz": rp["fn"], "zeta": rp["zeta"], "fn_std_hz": float(fn_std[k]),
                         "zeta_std": float(zeta_std[k]), "kurtosis": kurt[k], "reason": why})
    return keep, rejected


def _ssi_sizes(max_order, block_rows, n_blocks, l):
    if isinstance(max_order, bool) or not isinstance(max_order, (int, np.integer)) or not 4 <= max_order <= 400:
        raise ParameterError(f"max_order={max_order!r} must be an integer from 4 to 400")
    s_min = int(np.ceil(max_order / l)) + 1
    if block_rows is None:
        s = max(s_min, 30)
    elif isinstance(block_rows, bool) or not isinstance(block_rows, (int, np.integer)) or block_rows < s_min:
        raise ParameterError(f"block_rows={block_rows!r} must be an integer >= {s_min}: block_rows x outputs "
                             f"({l}) must exceed max_order={max_order}")
    else:
        s = int(block_rows)
    if isinstance(n_blocks, bool) or not isinstance(n_blocks, (int, np.integer)) or not 5 <= n_blocks <= 200:
        raise ParameterError(f"n_blocks={n_blocks!r} must be an integer from 5 to 200")
    return list(range(2, max_order + 1, 2)), s, int(n_blocks)


def _ssi_estimate(rec, spectra, names, modes, reps, fn_std, zeta_std, table, info):
    fn = np.array([rp["fn"] for rp in reps])
    zeta = np.array([rp["zeta"] for rp in reps])
    lam = -zeta * 2 * np.pi * fn + 1j * 2 * np.pi * fn * np.sqrt(1 - zeta ** 2)
    phi = _normalise(np.column_stack([rp["phi"] for rp in reps]))
    spread_f = [float(np.std([q["f"] for q in c["members"]])) for c in modes]
    spread_z = [float(np.std([q["z"] for q in c["members"]])) for c in modes]
    flags = []
    for k in range(fn.size):
        fl = []
        if fn[k] * spectra.shape[1] / rec.fs < MIN_CYCLES:
            fl.append("few_cycles")
        near = [j for j in range(fn.size) if j != k and abs(fn[j] - fn[k]) < 3 * (zeta[j] * fn[j] + zeta[k] * fn[k])]
        if near:
            fl.append("close_modes")
        flags.append(tuple(fl))
    f_psd, p_psd = _psd_overlay(spectra.Y, rec.fs)
    near = [_tones_near(spectra, rec.fs, f_psd, p_psd, fn[k], zeta[k], reps[k]["phi"]) for k in range(fn.size)]
    for k, tones in enumerate(near):
        if tones:
            flags[k] = flags[k] + ("near_harmonic",)
    extras = dict(info, stabilisation=table, near_harmonics=near, kurtosis=[rp["kurtosis"] for rp in reps], mpc=mpc(phi).tolist(), mpd=mpd(phi).tolist(), outputs=names,
                  cluster_size=[len(c["members"]) for c in modes], cluster_spread_fn_hz=spread_f,
                  cluster_spread_zeta=spread_z, model_order=[rp["order"] for rp in reps],
                  poles=[[float(l.real), float(l.imag)] for l in lam],
                  std_method=f"block jackknife of the output covariances ({info['n_blocks']} blocks)",
                  psd={"freq": f_psd, "values": p_psd, "unit": f"({rec.channels[0].unit})^2/Hz"},
                  criteria={"stable_df": STAB_DF, "stable_dzeta": STAB_DZ, "stable_mac": STAB_MAC,
                            "min_mpc": MIN_MPC, "cluster_df": CLUSTER_DF, "cluster_mac": CLUSTER_MAC,
                            "max_zeta": MAX_ZETA})
    est = ModalEstimate(fn=fn, zeta=zeta, fn_std=fn_std, zeta_std=zeta_std, method="oma_ssi", mode_flags=tuple(flags),
                        shapes=phi, unit=rec.channels[0].unit, extras=extras)
    for k, tones in enumerate(near):
        if tones:
            warn_quality(f"oma_ssi: the mode at {fn[k]:.5g} Hz sits among harmonics (sinusoids at "
                         + ", ".join(f"{t['f_hz']:.5g} Hz (kurtosis {t['kurtosis']:.2f})" for t in tones)
                         + ") that stand 10 dB or more above the spectrum at the pole: it may be a pole fitted to "
                         "them, not a mode; flagged near_harmonic", stacklevel=3)
    if "few_cycles" in est.flags:
        warn_quality(f"oma_ssi: mode(s) with fewer than {MIN_CYCLES} cycles in the record: damping is poorly "
                     "determined; record longer", stacklevel=3)
    return est
