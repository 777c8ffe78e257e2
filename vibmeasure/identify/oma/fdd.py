"""Output-only modal analysis by frequency-domain decomposition (FDD) and enhanced FDD (EFDD):
the SVD of the outputs' cross-spectral matrix at every line, peaks by a stated rule, EFDD damping
from the singular-value bell fitted as a free decay, stds from a jackknife over segment groups.
The shared checks and shape measures are in :mod:`vibmeasure.identify.oma`."""

from __future__ import annotations

import functools

import numpy as np

from ...core._threads import single_threaded
from ...core._validate import check_band
from ...core.errors import FitError, ParameterError, warn_quality
from ...core.record import Record
from ...core.results import ModalEstimate
from ..limits import MAX_REL_ZETA_STD
from ..shapes import mac_pair, mpc
from ._common import (MIN_CYCLES, N_GROUPS, OutputSpectra, _check_duration, _normalise, _outputs, band_kurtosis,
                      harmonic_by_kurtosis)

__all__ = ["oma_fdd"]


# --- FDD / EFDD ---------------------------------------------------------------------------------
SEG_BATCH = 16   # segments transformed in one call by _csd_matrix


def _csd_matrix(Y, fs, nperseg):
    """Output cross-spectral matrix G (n_freq, l, l), Hann-windowed segments with 50 % overlap, each
    zero-padded to 2 nperseg so that the inverse transform of a bell is a linear (not circular)
    correlation; one-sided PSD units."""
    l, n = Y.shape
    w = np.hanning(nperseg + 1)[:-1] if nperseg > 1 else np.ones(1)
    step = nperseg // 2
    starts = range(0, n - nperseg + 1, step)
    nf = nperseg + 1
    n_seg = len(starts)
    # the jackknife needs at least 3 groups of 2 segments: fewer segments (a long nperseg) get fewer groups,
    # never a std from the white-error fit alone (which let noise peaks of a 4-segment average pass)
    n_g = min(N_GROUPS, n_seg // 2)
    n_g = n_g if n_g >= 3 and nf * l * l * 16 * n_g < 5e8 else 0
    Gg = np.zeros((max(n_g, 1), nf, l, l), complex)
    group = np.array([j * n_g // n_seg if n_g else 0 for j in range(n_seg)])
    # the segments of a group transformed together (at most SEG_BATCH at a time: memory stays bounded)
    for g in range(Gg.shape[0]):
        idx = np.flatnonzero(group == g)
        for c0 in range(0, idx.size, SEG_BATCH):
            ks = [starts[j] for j in idx[c0:c0 + SEG_BATCH]]
            seg = np.stack([Y[:, k0:k0 + nperseg] for k0 in ks]) * w       # (segments, l, nperseg)
            X = np.fft.rfft(seg, n=2 * nperseg, axis=2)                     # (segments, l, nf)
            Gg[g] += np.einsum("sif,sjf->fij", X, X.conj())
    scale = 2.0 / (fs * np.sum(w ** 2) * n_seg)
    Gg *= scale
    Gg[:, 0] /= 2
    G = Gg.sum(axis=0)
    return np.fft.rfftfreq(2 * nperseg, 1 / fs), G, w, n_seg, (Gg if n_g else None)


def _psd_svd(G):
    """Singular values (descending) and left vectors of stacked Hermitian positive semi-definite
    matrices, by their eigen-decomposition: for such a matrix the two coincide, and LAPACK's Hermitian
    solver takes half the time of the general SVD (8 against 16 ms for 2049 lines of 5 outputs).
    Round-off below zero is clipped: a cross-spectral matrix has no negative power."""
    lam, V = np.linalg.eigh(G)
    return V[..., ::-1], np.maximum(lam[..., ::-1], 0.0)


def _fdd_nperseg(nperseg, n):
    if nperseg is None:
        nper = 2 ** int(np.log2(max(n // 8, 16)))
        return int(min(nper, 2 ** 16))
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or not 16 <= nperseg <= n // 4:
        raise ParameterError(f"nperseg={nperseg!r} must be an integer from 16 to a quarter of the record ({n // 4}): "
                             "the decomposition averages at least 7 segments, in at least 3 groups for the "
                             "jackknife std (fewer leave the singular values too noisy to tell a mode from noise)")
    return int(nperseg)


def _fdd_peaks(f, S, U, sel, min_prom_db, df_seg, n_modes, Y, fs):
    """Candidate modes: peaks of the first (and second) singular value in the band that stand
    ``min_prom_db`` above their surroundings (prominence), whose singular vector is coherent around
    the peak (MAC >= 0.9 with the lines two either side) and whose band is a random response (band
    kurtosis >= TONE_KURTOSIS; a harmonic or an electrical line gives 1.5)."""
    from scipy.signal import find_peaks
    idx = np.flatnonzero(sel)
    picked, rejected = [], []
    floor = float(np.median(S[idx, -1])) if S.shape[1] > 1 else 0.0   # the noise: the last singular value
    for j in range(min(2, S.shape[1])):
        s_db = 10 * np.log10(np.maximum(S[idx, j], 1e-300))
        pk, props = find_peaks(s_db, prominence=min_prom_db)
        if not pk.size:
            continue
        for p, prom in zip(pk, props["prominences"]):
            wdt = _half_power_width(s_db, p)
            i = idx[p]
            u = U[i, :, j]
            near = [U[k, :, j] for k in (i - 2, i + 2) if 0 <= k < U.shape[0]]
            coh = min(mac_pair(u, v) for v in near) if near else 1.0
            cand = {"line": int(i), "sv": j, "f": float(f[i]), "prominence_db": float(prom),
                    "width_bins": float(wdt * (f[1] - f[0]) / df_seg), "coherence_mac": coh}
            hw = max(0.5 * wdt * (f[1] - f[0]), 10 * fs / Y.shape[1])
            kurt = band_kurtosis(Y, fs, f[i], hw, u)
            cand["kurtosis"] = kurt
            if harmonic_by_kurtosis(kurt, hw, Y.shape[1] / fs):
                rejected.append(dict(cand, reason=f"a harmonic, not a mode: kurtosis {kurt:.2f} in its band (a "
                                                  "sinusoid gives 1.5, a mode's random response 3)"))
            elif coh < 0.9 and floor > 0 and S[i, 0] >= UNRESOLVED_DB_OVER_FLOOR * floor:
                # a resonance far above the noise whose singular vector turns within +-2 lines: more
                # than one mode shares these lines, closer than the resolution separates
                rejected.append(dict(cand, unresolved=True, reason=(
                    f"two or more close modes share this peak: it stands {10 * np.log10(S[i, 0] / floor):.0f} dB "
                    f"over the noise but its singular vector turns within +-2 lines (MAC {coh:.2f} < 0.9); the "
                    f"resolution ({df_seg:.3g} Hz) does not separate them: oma_ssi resolves close modes")))
            elif coh < 0.9:
                rejected.append(dict(cand, reason="singular vector not coherent around the peak (MAC < 0.9)"))
            elif j > 0 and any(abs(c["line"] - i) <= 2 or mac_pair(U[c["line"], :, c["sv"]], u) >= 0.8 for c in picked):
                continue  # the second singular value's peak belongs to a mode already found
            else:
                picked.append(cand)
    picked.sort(key=lambda c: -c["prominence_db"])
    if n_modes is not None:
        rejected += [dict(c, reason=f"beyond n_modes={n_modes}") for c in picked[n_modes:]]
        picked = picked[:n_modes]
    return sorted(picked, key=lambda c: c["f"]), rejected


def _half_power_width(s_db, p):
    """Width (lines, interpolated) of the peak at p where it stays within 3 dB of its top."""
    lvl = s_db[p] - 3.0
    lo = p
    while lo > 0 and s_db[lo - 1] > lvl:
        lo -= 1
    hi = p
    while hi < s_db.size - 1 and s_db[hi + 1] > lvl:
        hi += 1
    left = lo - (s_db[lo] - lvl) / (s_db[lo] - s_db[lo - 1]) if lo > 0 else lo
    right = hi + (s_db[hi] - lvl) / (s_db[hi] - s_db[hi + 1]) if hi < s_db.size - 1 else hi
    return float(right - left)


def _bell(S, U, cand, mac_bell):
    """The SDOF bell of one mode: at each line the singular value whose vector matches the peak's
    (MAC >= mac_bell), contiguous from the peak; zero elsewhere."""
    ref = U[cand["line"], :, cand["sv"]]
    # MAC of every line's singular vectors with the peak's, (n_lines, n_sv), in one step
    num = np.abs(np.einsum("j,ijk->ik", ref.conj(), U)) ** 2
    den = np.maximum(np.einsum("ijk,ijk->ik", U.conj(), U).real * np.vdot(ref, ref).real, 1e-300)
    mac = num / den
    best = np.argmax(mac, axis=1)
    ok = mac[np.arange(mac.shape[0]), best] >= mac_bell
    bell = np.zeros(S.shape[0])
    at = cand["line"]
    stop = np.flatnonzero(~ok[at:])                  # the first line from the peak up that does not match
    hi = at + (int(stop[0]) if stop.size else ok.size - at)
    start = np.flatnonzero(~ok[:at])                 # the last line below the peak that does not match
    lo = int(start[-1]) + 1 if start.size else 0
    lines = np.arange(lo, hi)
    bell[lines] = S[lines, best[lines]]
    return bell, lines.tolist()


UNRESOLVED_DB_OVER_FLOOR = 100.0   # 20 dB: an incoherent peak this far over the noise is close modes, not noise
BIAS_ITERATIONS = 4   # fixed-point steps of the bell-cut bias correction (exact 57 Hz, 2 % bell: zeta to 0.011 %)
POWER = {"displacement": 0, "velocity": 2, "acceleration": 4}   # an SDOF bell of each quantity: f^p |H|^2


def _efdd(bell, w, fs, nperseg, power=0):
    """EFDD of one bell: its correlation function fitted as a free decay, then corrected for the bias
    that cutting the bell at its edges leaves. Cutting the bell multiplies the spectrum by a box, which
    smears the correlation function in time with a sinc as wide as 1 / (bell width) and rounds its
    peak: the fitted decay is slower than the mode's, the more so the wider the mode is against its
    bell (on the OMA benchmark zeta was 5 % low on the 2 % mode). The same cut and fit on the exact SDOF
    bell at the estimate (f^power / |fn^2 - f^2 + 2i zeta fn f|^2, power 4 for accelerations) gives
    that bias; the (fn, zeta) whose cut-and-fitted exact bell reproduces the data's fit is found by a
    few fixed-point steps. Returns (estimate, fitted samples, (dfn, dzeta) removed, or None when
    the bias exceeds half of zeta or the exact bell cannot be fitted: then the fit is kept as it is,
    and the caller flags it)."""
    import dataclasses
    est, end = _efdd_fit(bell, w, fs, nperseg)
    k = np.flatnonzero(bell)
    fk = k * fs / (2 * (bell.size - 1))
    fn0, z0 = float(est.fn[0]), float(est.zeta[0])
    fn, z = fn0, z0
    last = None
    for _ in range(BIAS_ITERATIONS):
        # the (fn, zeta) whose exact bell, cut and fitted the same way, gives what the data gave
        exact = np.zeros(bell.size)
        exact[k] = fk ** power / ((fn ** 2 - fk ** 2) ** 2 + (2 * z * fn * fk) ** 2)
        wn = 2 * np.pi * fn
        sim, _ = _efdd_fit(exact, w, fs, nperseg, poles=[complex(-z * wn, wn * np.sqrt(1 - z * z))], mode_hz=fn)
        if sim is None:
            return est, end, None   # the exact bell's decay cannot be fitted: keep the fit, flagged
        step_f, step_z = fn0 - sim[0], z0 - sim[1]
        fn, z = fn + step_f, z + step_z
        if not (z > 0 and abs(z - z0) <= 0.5 * z0):
            return est, end, None   # not a small correction: keep the fit, the caller flags it
        # converged when what is left moves fn and zeta by under 1 % of the fit's own std (a lower
        # bound of the jackknife's) or round-off-level amounts, whichever is larger
        tol_f, tol_z = max(1e-6 * fn, 0.01 * float(est.fn_std[0])), max(1e-3 * z, 0.01 * float(est.zeta_std[0]))
        if abs(step_z) < tol_z and abs(step_f) < tol_f:
            break
        if last is not None and _remaining(step_z, last[1]) < tol_z and _remaining(step_f, last[0]) < tol_f:
            break   # the steps contract: what is left is below the tolerance without another fit
        last = (step_f, step_z)
    return dataclasses.replace(est, fn=np.array([fn]), zeta=np.array([z])), end, (fn0 - fn, z0 - z)


def _remaining(step, previous):
    """What a fixed-point iteration has still to go after ``step``: with the contraction rho =
    |step / previous| < 1 the error is at most rho / (1 - rho) |step| (inf when the steps do not
    contract)."""
    rho = abs(step) / abs(previous) if previous else np.inf
    return rho / (1 - rho) * abs(step) if rho < 1 else np.inf


def _correlation(bell, w, nperseg):
    """The bell's correlation function (lags 0..nperseg-1) with the window's own correlation divided
    out, and the window's correlation."""
    r = np.fft.irfft(bell)[:nperseg]
    wac = _window_autocorrelation(np.ascontiguousarray(w, float).tobytes())
    return r / np.maximum(wac, 1e-12), wac


def _efdd_fit(bell, w, fs, nperseg, end=None, poles=None, mode_hz=None):
    """Fit the bell's correlation function (a free decay) with the ring-down estimator, over ``end``
    samples (default: until its envelope falls to a tenth, or the window's own correlation to 0.3).
    With ``mode_hz`` (a jackknife replicate, the exact bell of a bias step) only the point estimate of
    the mode nearest it is taken, (fn, zeta) or None: the same fit without the stds
    (``_rd_linear.replicate_decay``)."""
    from .._rd_linear import linear_decay, replicate_decay
    r, wac = _correlation(bell, w, nperseg)
    r0 = r[0]
    if end is None:
        env = np.abs(_analytic(r[: nperseg // 2]))
        low = np.flatnonzero(env[4:] < 0.1 * r0)
        end = int(low[0]) + 4 if low.size else nperseg // 2
        end = max(min(end, int(np.argmax(wac < 0.3)) or nperseg // 2), 64)
    corr = Record.from_array(r[:end] / r0, fs=fs, name="correlation") if np.isfinite(r0) and r0 > 0 else None
    if mode_hz is not None:
        return (None if corr is None else replicate_decay(corr, poles, mode_hz)), end
    if corr is None:
        raise FitError("the bell holds no power: its correlation function is zero at lag 0")
    import warnings

    from ...core.errors import QualityWarning
    with warnings.catch_warnings():   # the ring-down's own findings stay in its flags, read by the caller
        warnings.simplefilter("ignore", QualityWarning)
        est = linear_decay(corr, n_modes=1, poles=poles)
    return est, end


@functools.lru_cache(maxsize=8)
def _window_autocorrelation(key: bytes) -> np.ndarray:
    """The window's autocorrelation at lags 0..n-1, normalised to 1 at lag 0 (by FFT: the direct sum
    took 9 ms per call at 8192 samples, called for every bell and jackknife replicate)."""
    w = np.frombuffer(key, float)
    n = w.size
    W = np.fft.rfft(w, 2 * n)
    wac = np.fft.irfft(np.abs(W) ** 2, 2 * n)[:n]
    return wac / wac[0]


def _analytic(x):
    from scipy.signal import hilbert
    return hilbert(x)


@single_threaded
def oma_fdd(rec, *, band=None, nperseg: int | None = None, channels=None, n_modes: int | None = None,
            min_prominence_db: float = 6.0, mac_bell: float = 0.8) -> ModalEstimate:
    """Modes from output-only data by frequency-domain decomposition, damping by EFDD.

    The outputs' cross-spectral matrix is decomposed by SVD at every line; a peak of the first (or, for
    close modes, the second) singular value is a mode when it stands ``min_prominence_db`` above its
    surroundings, its singular vector is coherent around it and its band is a random response. EFDD
    takes each mode's bell (lines whose singular vector matches, MAC >= ``mac_bell``) back to a free
    decay, fitted by ``vm.ringdown``, with the bias of cutting the bell removed; stds from a jackknife
    over segment groups. Refused peaks are in ``extras["rejected_modes"]`` with the reason, as for
    oma_ssi and fit_modes (``extras["rejected_peaks"]`` is the same list). A mode the record holds fewer
    than 100 cycles of is flagged ``few_cycles`` (docs/methods/oma.md).

    Parameters
    ----------
    rec : Record
        Responses of one or more sensors.
    band : tuple of float, optional
        (lo, hi) Hz (default the whole range, as ``oma_ssi``).
    nperseg : int, optional
        Segment length of the cross-spectra.
    channels : list, optional
        Output channels (default every channel that is not a force).
    n_modes : int, optional
        Keep the most prominent.
    min_prominence_db : float
        How far a peak must stand above its surroundings.
    mac_bell : float
        MAC a line's singular vector needs with the peak's to belong to its bell.

    Returns
    -------
    ModalEstimate
        fn, zeta, stds and shapes (the singular vectors at the peaks).

    Raises
    ------
    ParameterError
        For bad parameters or too short a record.
    FitError
        When no mode is left (every refused peak listed).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> chain = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), modal_zeta=[0.02, 0.02])
    >>> amb = vm.synth.ambient(chain, fs=100.0, duration=300.0, noise=0.05, seed=1)
    >>> est = vm.oma_fdd(amb, band=(1, 40))
    >>> est.n_modes
    2
    """
    Y, names = _outputs(rec, channels, "oma_fdd", 1)
    try:
        min_prominence_db, mac_bell = float(min_prominence_db), float(mac_bell)
    except (TypeError, ValueError):
        raise ParameterError(f"min_prominence_db={min_prominence_db!r} and mac_bell={mac_bell!r} must be numbers") \
            from None
    if not (np.isfinite(min_prominence_db) and min_prominence_db > 0):
        raise ParameterError(f"min_prominence_db={min_prominence_db!r} must be a positive number of dB")
    band = check_band(band, rec.fs) or (0.0, rec.fs / 2)   # the same default as oma_ssi: the whole range
    _check_duration(Y.shape[1], rec.fs, band[1], "oma_fdd")
    nper = _fdd_nperseg(nperseg, Y.shape[1])
    if n_modes is not None and (isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer))
                                or n_modes < 1):
        raise ParameterError(f"n_modes={n_modes!r} must be None or an integer >= 1")
    if not 0 < mac_bell < 1:
        raise ParameterError(f"mac_bell={mac_bell!r} must be between 0 and 1")
    f, G, w, n_seg, Gg = _csd_matrix(Y, rec.fs, nper)
    U, S = _psd_svd(G)
    sel = (f >= band[0]) & (f <= band[1])
    picked, rejected = _fdd_peaks(f, S, U, sel, float(min_prominence_db), rec.fs / nper, n_modes, OutputSpectra(Y),
                                  rec.fs)
    if not picked:
        raise FitError(f"oma_fdd: no peak in band={band} stands {min_prominence_db} dB out of the singular values "
                       f"as a resonance (rejected: {[(round(c['f'], 3), c['reason']) for c in rejected]})")
    return _fdd_estimate(rec, names, f, S, U, picked, rejected, w, nper, mac_bell, band, n_seg, Gg)


def _efdd_jackknife(Gg, c, lines, U, mac_bell, w, fs, nper, end, poles, mode_hz):
    """Leave-one-group-out EFDD of one mode (the segments in N_GROUPS groups): jackknife std of fn
    and zeta of the plain fit, or None when fewer than all but one replicate succeed. (The bell-cut
    bias correction shifts every replicate alike; the caller scales the std by its slope.) Every
    replicate fits the decay over the full data's ``end`` samples, from the full data's ``poles``, by
    the ring-down fit without the stds it never reads (``_rd_linear.replicate_decay``): the jackknife
    needs an estimator that moves smoothly with the data, and a decay length chosen again per
    replicate jumps (one replicate of eight cut at 261 samples instead of 420 tripled a std)."""
    lo, hi = max(lines[0] - 5, 0), min(lines[-1] + 6, Gg.shape[1])
    tot = Gg[:, lo:hi].sum(axis=0)
    ref = U[c["line"], :, c["sv"]]
    vals = []
    U_all, S_all = _psd_svd(tot[None] - Gg[:, lo:hi])     # every replicate in one call
    for g in range(Gg.shape[0]):
        Ur, Sr = U_all[g], S_all[g]
        k = int(np.argmax([mac_pair(Ur[c["line"] - lo, :, j], ref) for j in range(Sr.shape[1])]))
        sub, sub_lines = _bell(Sr, Ur, dict(c, line=c["line"] - lo, sv=k), mac_bell)
        bell = np.zeros(Gg.shape[1])
        bell[lo:hi] = sub
        got, _ = _efdd_fit(bell, w, fs, nper, end, poles, mode_hz)
        if got is not None:
            vals.append(got)
    n = Gg.shape[0]
    if len(vals) < n - 1:
        return None
    v = np.array(vals)
    return np.sqrt((n - 1) / len(v) * np.sum((v - v.mean(axis=0)) ** 2, axis=0))


def _efdd_mode(c, bell, lines, U, Gg, w, fs, nper, mac_bell, power):
    """EFDD of one peak's bell with its jackknife std: ((fn, zeta, fn_std, zeta_std), flags, bias, decay
    samples), or a reason string when the peak is refused (a harmonic, damping the data does not
    determine)."""
    fl, bias = [], None
    try:
        e, end, bias = _efdd(bell, w, fs, nper, power)
        plain_hz = float(e.fn[0]) + (bias[0] if bias is not None else 0.0)   # the fit before the bias step
        jk = (_efdd_jackknife(Gg, c, lines, U, mac_bell, w, fs, nper, end, e.extras["fitted_poles"], plain_hz)
              if Gg is not None else None)
        if bias is None:
            fl.append("bias_uncorrected")
        elif jk is not None:
            # the corrected estimate moves with the plain fit by about zeta / zeta_plain (the bias
            # grows with zeta): the plain replicates' spread scaled by that slope
            jk = (jk[0], jk[1] * e.zeta[0] / (e.zeta[0] + bias[1]))
        stds = (e.fn_std[0], e.zeta_std[0]) if jk is None else (max(jk[0], e.fn_std[0]), max(jk[1], e.zeta_std[0]))
        vals = (e.fn[0], e.zeta[0], *stds)
        fl += [x for x in e.flags if x in ("few_cycles", "low_snr")]
    except (FitError, ParameterError) as err:
        if getattr(err, "tones_hz", None):
            # the bell's correlation function does not decay: a harmonic, which the kurtosis test
            # passed because noise shares its band
            return (f"a harmonic, not a mode: the EFDD correlation function does not decay (a stationary tone "
                    f"at {err.tones_hz[0]:.6g} Hz)")
        vals, end = (c["f"], np.nan, np.nan, np.nan), 0
        fl.append("efdd_failed")
        c["efdd_error"] = str(err)
    if np.isfinite(vals[1]) and vals[3] > MAX_REL_ZETA_STD * vals[1]:
        c.update(zeta=float(vals[1]), zeta_std=float(vals[3]))
        return f"damping relative std {vals[3] / vals[1]:.2f} > {MAX_REL_ZETA_STD}: the data does not support the mode"
    if len(lines) < 5:
        fl.append("resolution_limited")
    return vals, fl, bias, end


def _fdd_estimate(rec, names, f, S, U, picked, rejected, w, nper, mac_bell, band, n_seg, Gg):
    fn, zeta, fn_std, zeta_std, flags, bells = [], [], [], [], [], []
    power = POWER.get(rec.channels[0].quantity, 0)
    kept, kept_lines = [], []
    for c in sorted(picked, key=lambda c: -c["prominence_db"]):
        bell, lines = _bell(S, U, c, mac_bell)
        same = next((k for k, ln in zip(kept, kept_lines) if ln[0] <= c["line"] <= ln[-1]), None)
        if same is not None:
            # a lesser peak inside a kept mode's bell is that mode again (a noisy top has several)
            rejected.append(dict(c, reason=f"the same mode as the {same['f']:.6g} Hz peak (inside its bell)"))
            continue
        got = _efdd_mode(c, bell, lines, U, Gg, w, rec.fs, nper, mac_bell, power)
        if isinstance(got, str):
            rejected.append(dict(c, reason=got))
            continue
        vals, fl, bias, end = got
        if "few_cycles" not in fl and vals[0] * rec.n_samples / rec.fs < MIN_CYCLES:
            fl.append("few_cycles")   # its damping rests on fewer cycles than the rule asks
        for lst, v in zip((fn, zeta, fn_std, zeta_std), vals):
            lst.append(float(v))
        flags.append(tuple(fl))
        bells.append({"f_lo": float(f[lines[0]]), "f_hi": float(f[lines[-1]]), "n_lines": len(lines),
                      "decay_samples": int(end), "singular_value": c["sv"] + 1,
                      "bias_removed_fn_hz": None if bias is None else bias[0],
                      "bias_removed_zeta": None if bias is None else bias[1]})
        kept.append(c)
        kept_lines.append(lines)
    if not kept:
        raise FitError(f"oma_fdd: no mode in band={list(band)} that the data supports "
                       f"(rejected: {[(round(c['f'], 3), c['reason']) for c in rejected]})")
    order = np.argsort([c["f"] for c in kept], kind="stable")
    picked = [kept[k] for k in order]
    fn, zeta, fn_std, zeta_std, flags, bells = ([lst[k] for k in order] for lst in (fn, zeta, fn_std, zeta_std,
                                                                                   flags, bells))
    phi = _normalise(np.column_stack([U[c["line"], :, c["sv"]] for c in picked]))
    show = (f >= max(0.0, band[0] - 0.1 * (band[1] - band[0]))) & (f <= band[1] + 0.1 * (band[1] - band[0]))
    extras = {"peaks": picked, "rejected_modes": rejected, "rejected_peaks": rejected, "bells": bells, "band_hz": list(band), "nperseg": nper,
              "n_segments": n_seg, "outputs": names, "mpc": mpc(phi).tolist(), "mac": np.abs(_mac_matrix(phi)).tolist(),
              "singular_values": {"freq": f[show], "values": S[show].T, "unit": f"({rec.channels[0].unit})^2/Hz"},
              "rule": "peaks of the singular values standing min_prominence_db out, coherent singular vector "
                      "(MAC >= 0.9 over +-2 lines), band kurtosis not below min(2.2, a random band's 0.1 % quantile) "
                      "(not a harmonic); an incoherent peak 20 dB over the noise is close modes, reported",
              "std_method": f"jackknife over {0 if Gg is None else Gg.shape[0]} groups of segments (each left out, EFDD repeated); the "
                            "ring-down fit's own std where larger" if Gg is not None else
                            "ring-down fit of the EFDD correlation function (white-error assumption: a lower bound)"}
    unresolved = [c["f"] for c in rejected if c.get("unresolved")]
    extras["unresolved_close_modes_hz"] = unresolved
    est = ModalEstimate(fn=fn, zeta=zeta, fn_std=fn_std, zeta_std=zeta_std, method="oma_fdd", mode_flags=tuple(flags),
                        flags=("unresolved_close_modes",) if unresolved else (), shapes=phi,
                        unit=rec.channels[0].unit, extras=extras)
    if unresolved:
        warn_quality(f"oma_fdd: close modes near {', '.join(f'{x:.4g}' for x in unresolved)} Hz are not resolved at "
                     f"this resolution and are left out (extras['rejected_modes']): run oma_ssi, which separates "
                     "them, or give a longer record", stacklevel=3)
    if "bias_uncorrected" in est.flags:
        warn_quality("oma_fdd: the bias of cutting the bell could not be removed for some mode(s) (it would exceed "
                     "half of zeta: the bell is too narrow for the damping, or the exact bell's decay could not be "
                     "fitted): zeta is the plain EFDD fit, biased low; lower mac_bell or use oma_ssi", stacklevel=3)
    if "efdd_failed" in est.flags:
        warn_quality("oma_fdd: EFDD could not fit the decay of some mode(s): their damping is NaN (see "
                     "extras['peaks'][k]['efdd_error'])", stacklevel=3)
    return est


def _mac_matrix(phi):
    return np.array([[mac_pair(a, b) for b in phi.T] for a in phi.T])
