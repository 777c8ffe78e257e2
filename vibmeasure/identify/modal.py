"""Modal identification from FRFs: half-power (exact forms), circle fit, and fit_modes
(LSCF poles with an automatic stabilisation diagram, then a maximum-likelihood polish of poles and
residues with lower/upper residual terms, with standard deviations from the Fisher information).

Model per output o (one input): H_o(w) = sum_r [R_or / (i w - l_r) + conj(R_or) / (i w - conj(l_r))]
+ c1_o / (i w)^2 + c2_o + c3_o (i w), poles l_r = -sigma_r + i w_dr. With complex Gaussian noise of
variance s_o^2 per output, weighted least squares is maximum likelihood.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core._threads import single_threaded
from ..core._validate import check_band, name_index
from ..core.errors import FitError, ParameterError, warn_quality
from ..core.results import FRF, ModalEstimate
from ._modal_fit import (FALSE_ALARM, _astray_poles, LOCAL_LINES, MAX_REL_ZETA_STD, _covariance, _full_jacobian,  # noqa: F401 (tests, modal_crb)
                         _lam, _local_refit, _lscf_poles, _polish, _residual_search, _residual_terms, _stabilise, _unsupported,
                         synthesize_frf_from)
from ._poles import pole_to_modal

__all__ = ["fit_modes", "circle_fit", "synthesize_frf", "modal_crb"]

MIN_LINES_WINDOWED = 8


# ------------------------------------------------------------------------------------------------
def _band_lines(frf: FRF, band, inp):
    if not isinstance(frf, FRF):
        raise ParameterError(f"frf must be a vm.FRF, got {type(frf).__name__}")
    if band is None:
        raise ParameterError("band=(lo, hi) in Hz is required: the frequency range to fit")
    try:
        lo, hi = (float(b) for b in band)
    except (TypeError, ValueError):
        raise ParameterError(f"band={band!r} must be a pair (lo, hi) in Hz") from None
    if not lo < hi:
        raise ParameterError(f"band={band!r} must have lo < hi")
    if hi > frf.freq[-1] + 1e-9 or lo < frf.freq[0] - 1e-9:
        raise ParameterError(f"band={band!r} lies outside the FRF's {frf.freq[0]:g}..{frf.freq[-1]:g} Hz")
    if isinstance(inp, str) and inp == "all":
        ii = list(range(frf.n_inputs))
    elif isinstance(inp, (list, tuple)):
        ii = [name_index(frf.inputs, x, what="input") for x in inp]
        if not ii or len(set(ii)) != len(ii):
            raise ParameterError(f"input={inp!r} must name distinct inputs of {list(frf.inputs)}")
    else:
        ii = name_index(frf.inputs, inp, what="input")
    sel = (frf.freq >= lo) & (frf.freq <= hi) & (frf.freq > 0)
    # several inputs (poly-reference): every (output, input) FRF is a row sharing the poles
    H = frf.h[:, ii, sel] if isinstance(ii, int) else frf.h[:, ii, :][:, :, sel].reshape(-1, int(sel.sum()))
    bad = ~np.isfinite(H).all(axis=0)
    if bad.any() and not bad.all():
        # NaN lines at the band's ends are where the FRF has no data (a sweep's or a shaker's range): the
        # band shrinks to the measured lines between them; a NaN line inside the measured range is damage
        k = np.flatnonzero(~bad)
        inner = np.zeros_like(bad)
        inner[k[0]:k[-1] + 1] = True
        if not bad[inner].any() and k.size >= 8:
            f_in = frf.freq[sel][k]
            sel = sel & (frf.freq >= f_in[0]) & (frf.freq <= f_in[-1])
            H = H[:, k[0]:k[-1] + 1]
            bad = bad[k[0]:k[-1] + 1]
            lo, hi = max(lo, float(f_in[0])), min(hi, float(f_in[-1]))
    if bad.any():
        raise ParameterError(f"the FRF has {int(bad.sum())} NaN/inf line(s) in band={band!r} (first at "
                             f"{frf.freq[sel][bad][0]:g} Hz): cut the band or repair the data")
    if sel.sum() < 8:
        raise ParameterError(f"band={band!r} holds {int(sel.sum())} lines; at least 8 are needed")
    return frf.freq[sel], H, ii, (lo, hi)


@single_threaded
def fit_modes(frf: FRF, *, band, max_order: int = 40, n_modes: int | None = None, input=0) -> ModalEstimate:
    """Natural frequencies, damping ratios and mode shapes from FRFs in a band.

    LSCF poles for orders 2..``max_order`` build an automatic stabilisation diagram; poles stable in
    frequency (1 %) and damping (5 %) are clustered across orders. Poles, complex residues and residual
    terms are then fitted by weighted nonlinear least squares (maximum likelihood for complex Gaussian
    noise, each output weighted by its residual noise), with stds from the Fisher information. A mode
    is reported only where the data support it (Wald test of its residues at a 1 % false-alarm rate
    per fit, zeta known to 30 %); the refused poles are in ``extras["rejected_modes"]``. An exponential
    window from ``impact_frf`` is removed exactly. ``input="all"`` fits every input column at once
    (poly-reference: one set of poles).

    Parameters
    ----------
    frf : FRF
        The FRFs.
    band : tuple of float
        (lo, hi) Hz.
    max_order : int
        Highest LSCF model order.
    n_modes : int, optional
        Keep the n most persistent clusters (default: every supported mode).
    input : int, str, list or "all"
        The input column(s).

    Returns
    -------
    ModalEstimate
        fn, zeta, their stds, ``shapes`` (n_outputs, n_modes) and ``extras`` (poles, residues, the
        stabilisation table, FRAC).

    Raises
    ------
    ParameterError
        For a band outside the FRF or an unknown input.
    FitError
        When no mode is left (the candidates are named).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> freq = np.linspace(1, 100, 1000)
    >>> h = vm.synth.modal_frf(freq, fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> est = vm.fit_modes(h, band=(10, 60))
    >>> round(float(est.fn[0]), 3), round(float(est.zeta[0]), 4)
    (30.0, 0.02)
    """
    f, H, ii, band = _band_lines(frf, band, input)
    _check_orders(max_order, n_modes)
    poles = _lscf_poles(f, H, max_order)
    table, clusters = _stabilise(poles)
    lam0 = _persistent_poles(clusters, len(poles), n_modes, band)
    w = 2 * np.pi * f
    theta, coef, r, sw, lw = _weighted_polish(w, H, lam0, n_modes)
    tau = frf.params.get("exp_window_tau_s")
    theta, coef, r, cov, rejected = _screen(w, H, theta, coef, r, sw, lw, tau, band, n_modes)
    m = _modal_parameters(theta, coef, cov, sw, tau)
    keep, flags_mode, dropped = _physical_modes(frf, f, band, theta, m)
    shapes, poly = _shapes(frf, ii, m, keep)
    extras = _fit_extras(frf, f, H, ii, band, m, coef, sw, keep, table, len(poles), tau, dropped, rejected, poly)
    est = ModalEstimate(fn=m.fn[keep], zeta=m.zeta[keep], fn_std=m.fn_std[keep], zeta_std=m.zeta_std[keep],
                        method="fit_modes", mode_flags=tuple(flags_mode), shapes=shapes, extras=extras)
    warn = [fl for fl in est.flags if fl in ("resolution_limited", "low_coherence")]
    if warn:  # poles left out are not modes: they are listed in extras["dropped_poles"], no warning
        msg = ", ".join(warn)
        if "resolution_limited" in warn:
            msg += " (half-power bandwidth spans too few lines: window leakage biases zeta upwards)"
        warn_quality(f"fit_modes: {msg}", stacklevel=3)
    return est


def _check_orders(max_order, n_modes):
    if isinstance(max_order, bool) or not isinstance(max_order, (int, np.integer)) or not 4 <= max_order <= 200:
        raise ParameterError(f"max_order={max_order!r} must be an integer from 4 to 200")
    if n_modes is not None and (isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer))
                                or n_modes < 1):
        raise ParameterError(f"n_modes={n_modes!r} must be None or an integer >= 1")


def _persistent_poles(clusters, n_orders, n_modes, band):
    """Start poles: the clusters of the stabilisation diagram seen at a quarter of the orders (or the
    n_modes most persistent), each the median of its poles at the highest orders."""
    need = max(3, int(0.25 * n_orders))
    good = [c for c in clusters if len(c["orders"]) >= need]
    good.sort(key=lambda c: -len(c["orders"]))
    if n_modes is not None:
        good = (good if len(good) >= n_modes else sorted(clusters, key=lambda c: -len(c["orders"])))[:n_modes]
    if not good:
        raise FitError(f"no stable mode in band={band!r}: no pole persists across model orders (the band holds "
                       "no resonance, or only noise)")
    lam0 = np.array([np.median(np.array(c["poles"])[np.argsort(-np.array(sorted(c["orders"])))][:5]) for c in good])
    return lam0[np.argsort(np.abs(lam0))]


def _weighted_polish(w, H, lam0, n_modes):
    """Maximum likelihood: a first pass with equal relative weights, then each output weighted by its
    residual noise, modes the residual still shows added, then each line weighted by the residual's
    local level (``_local_line_weights``)."""
    sw = 1 / np.sqrt(np.mean(np.abs(H) ** 2, axis=1))
    theta, coef, r = _polish(w, H, lam0, sw)
    nf = w.size
    res = r.reshape(H.shape[0], 2 * nf)
    s_o = np.sqrt(np.sum(res ** 2, axis=1) / max(2 * nf - coef.shape[0] - 2 * lam0.size / H.shape[0], 1)) / sw
    sw = 1 / np.maximum(s_o, 1e-300)
    theta, coef, r = _polish(w, H, _lam(theta), sw)
    # missed modes first: the local line weights would whiten a missing mode's residual away
    theta, coef, r, _ = _residual_search(w, H, theta, coef, r, sw, n_modes)
    lw = _local_line_weights(r, H.shape[0], nf)
    if lw is not None and lw.max() > 1.5 * lw.min():   # near-uniform weights would change nothing
        theta, coef, r = _polish(w, H, _lam(theta), sw, lw)
    else:
        lw = None
    return theta, coef, r, sw, lw


def _local_line_weights(r, n_out, nf):
    """Each line weighted by 1 / (the residual's RMS over the +-LOCAL_LINES lines around it), normalised
    to a mean square of 1. A measured FRF's noise is not the same over a wide band (a hammer's force
    spectrum falls with frequency, a single average leaks most where |H| is high): with one weight per
    output the lines of the noisiest region decide every mode's baseline, so a mode's estimate and
    std moved with how far the band reached beyond it."""
    from scipy.ndimage import uniform_filter1d
    res = r.reshape(n_out, 2, nf)
    p = np.sum(res ** 2, axis=(0, 1))
    if nf < 4 * LOCAL_LINES or not np.any(p > 0):
        return None   # too few lines to tell a local level from the band's
    sm = uniform_filter1d(p, 2 * LOCAL_LINES + 1, mode="nearest")
    sm = np.maximum(sm, 1e-6 * np.mean(sm))
    lw = 1 / np.sqrt(sm)
    return lw / np.sqrt(np.mean(lw ** 2))


def _screen(w, H, theta, coef, r, sw, lw, tau, band, n_modes):
    """Refuse the poles the data does not support (Wald test of the residues, zeta known to 30 %, no
    stronger mode within two lines), refit without them, and again until none is refused."""
    f = w / (2 * np.pi)
    rejected: list[dict] = []
    for _round in range(theta.size // 2 + 1):
        cov, s2 = _covariance(w, theta, coef, r, sw, lw)
        theta, coef, cov, astray = _local_refit(w, H, theta, coef, cov, sw)
        out = _unsupported(theta, coef, cov, sw, tau, f.size, H.shape[0], band, float(np.median(np.diff(f))))
        out += _astray_poles(theta, cov, astray, tau, band, {k for k, _ in out})
        if not out or n_modes is not None:
            break
        rejected += [d for _, d in out]
        if theta.size // 2 - len(out) < 1:
            raise FitError(f"no mode in band={band!r} that the data supports: "
                           + "; ".join(f"{d['fn_hz']:.5g} Hz: {d['reason']}" for d in rejected))
        drop = {k for k, _ in out}
        lam_keep = np.array([l for k, l in enumerate(_lam(theta)) if k not in drop])
        theta, coef, r = _polish(w, H, lam_keep, sw, lw)
    return theta, coef, r, cov, rejected


@dataclass
class _Poles:
    lam: np.ndarray
    wd: np.ndarray
    wn: np.ndarray
    fn: np.ndarray
    zeta: np.ndarray
    fn_std: np.ndarray
    zeta_std: np.ndarray
    R: np.ndarray        # residues (n_rows, m) in the FRF's own units


def _modal_parameters(theta, coef, cov, sw, tau) -> _Poles:
    """fn, zeta and their stds from the poles (the exponential window moved every pole left by
    exactly 1/tau), and the residues with the weights undone."""
    lam = _lam(theta)
    m = lam.size
    sig = theta[0::2].copy()
    if tau:
        sig = sig - 1.0 / tau
    wd = theta[1::2]
    wn = np.hypot(sig, wd)
    stds = np.array([pole_to_modal(sig[k], wd[k], cov[2 * k:2 * k + 2, 2 * k:2 * k + 2])[2:] for k in range(m)])
    R = (coef[0:2 * m:2] + 1j * coef[1:2 * m:2]).T / sw[:, None]
    return _Poles(lam, wd, wn, wn / (2 * np.pi), sig / wn, stds[:, 0], stds[:, 1], R)


def _physical_modes(frf, f, band, theta, m: _Poles):
    """The poles that are modes (damped, under-critical, inside the band), in frequency order, with
    their flags; the others as dropped."""
    flags_mode, keep = [], []
    df = float(np.median(np.diff(f)))
    windowed = str(frf.params.get("window", "boxcar")) not in ("boxcar", "rectangular", "force+exponential",
                                                                "force", "None")
    fn, zeta = m.fn, m.zeta
    for k in range(fn.size):
        fl = []
        if not (np.isfinite(zeta[k]) and 0 < zeta[k] < 0.5 and band[0] <= fn[k] <= band[1]):
            continue  # no/negative damping, over-damped or outside the band: reported in extras, never returned
        lines = 2 * theta[2 * k] / (2 * np.pi) / df  # the measured bandwidth (before any window correction)
        if frf.estimator != "analytic" and lines < (MIN_LINES_WINDOWED if windowed else 3):
            fl.append("resolution_limited")
        if frf.coherence is not None:
            near = np.abs(frf.freq - fn[k]) <= max(zeta[k] * fn[k], df)
            if near.any() and np.mean(frf.coherence[:, near]) < 0.8:
                fl.append("low_coherence")
        flags_mode.append(fl)
        keep.append(k)
    for a, k in enumerate(keep):  # close modes among the physical ones
        if any(abs(fn[j] - fn[k]) < 3 * (zeta[j] * fn[j] + zeta[k] * fn[k]) for j in keep if j != k):
            flags_mode[a].append("close_modes")
    dropped = [{"fn_hz": float(fn[k]), "zeta": float(zeta[k])} for k in range(fn.size) if k not in keep]
    if not keep:
        raise FitError(f"no physical mode in band={band!r}: every pole found has zero, negative or very high "
                       f"damping, or lies outside the band ({dropped})")
    order = np.argsort(fn[keep], kind="stable")  # modes are listed in frequency order
    return np.array([keep[i] for i in order]), [tuple(flags_mode[i]) for i in order], dropped


def _shapes(frf, ii, m: _Poles, keep):
    """Mode shapes from the residues, unit-normalised (mass-normalised at a driving point); for a
    poly-reference fit each mode's from the input that excites it most, with each input's share."""
    R, n = m.R, m.lam.size
    poly = None
    if not isinstance(ii, int):
        Rm = R.reshape(frf.n_outputs, len(ii), n)
        size = np.linalg.norm(Rm, axis=0)                       # (n_in, m)
        ref = np.argmax(size, axis=0)
        shapes = np.stack([Rm[:, ref[k], k] for k in range(n)], axis=1)[:, keep].copy()
        dp_input = [frf.inputs[ii[ref[k]]] for k in keep]
        poly = {"participation": (size / np.maximum(size.max(axis=0, keepdims=True), 1e-300))[:, keep].tolist(),
                "reference_input": dp_input, "rows": [f"{o}/{frf.inputs[i]}" for o in frf.outputs for i in ii]}
    else:
        shapes = R[:, keep].copy()
        dp_input = [frf.inputs[ii]] * keep.size
    for j in range(keep.size):
        dp = [o for o, name in enumerate(frf.outputs) if name == dp_input[j]]
        col = shapes[:, j]
        if dp and abs(col[dp[0]]) > 0:
            # receptance residue R_pq = phi_p phi_q / (2 i wd): phi = R_pq / sqrt(R_qq 2 i wd)... normalised
            wdk = m.wd[keep[j]]
            col = col * np.sqrt(2j * wdk) / np.sqrt(col[dp[0]] * 2j * wdk) if frf.form == "receptance" \
                else col / np.sqrt(col[dp[0]])
        else:
            col = col / col[np.argmax(np.abs(col))]
        shapes[:, j] = col
    return shapes, poly


def _fit_extras(frf, f, H, ii, band, m: _Poles, coef, sw, keep, table, n_orders, tau, dropped, rejected, poly):
    """Poles, residues, the whole fitted model (residual terms and poles outside the band), FRAC, the
    stabilisation table and the test that refused poles."""
    lam, R, n = m.lam, m.R, m.lam.size
    Hs = synthesize_frf_from(f, lam, R, coef, sw, n)
    frac = [float(np.abs(np.vdot(Hs[o], H[o])) ** 2 / (np.vdot(H[o], H[o]).real * np.vdot(Hs[o], Hs[o]).real))
            for o in range(H.shape[0])]
    extras = {"poles": [[float(l.real), float(l.imag)] for l in lam[keep]],
              "residues": [[[float(x.real), float(x.imag)] for x in R[:, k]] for k in keep],
              "residual_terms": _residual_terms(coef, sw, n),
              # poles fitted but not reported (outside the band, non-physical): part of the residual model
              "residual_poles": [[float(lam[k].real), float(lam[k].imag)] for k in range(n) if k not in keep],
              "residual_residues": [[[float(x.real), float(x.imag)] for x in R[:, k]] for k in range(n)
                                    if k not in keep],
              "band_hz": list(band), "frac": frac, "noise_std_per_output": list(1 / sw),
              "stabilisation": table, "n_orders": n_orders, "exp_window_tau_s": tau,
              "exp_window_added_zeta": [float(1 / (tau * m.wn[k])) for k in keep] if tau else None,
              "dropped_poles": dropped, "rejected_modes": rejected,
              "mode_test": {"false_alarm_rate": FALSE_ALARM, "max_rel_zeta_std": MAX_REL_ZETA_STD},
              "outputs": list(frf.outputs), "form": frf.form,
              "input": [frf.inputs[i] for i in ii] if poly is not None else frf.inputs[ii]}
    if poly is not None:
        extras.update(poly)
    return extras


def synthesize_frf(est: ModalEstimate, freq, *, residuals: bool = False) -> np.ndarray:
    """FRFs synthesised from a fit_modes estimate's poles and residues.

    Parameters
    ----------
    est : ModalEstimate
        A ``fit_modes`` estimate.
    freq : array_like
        Frequency lines in Hz.
    residuals : bool
        Also the residual terms (lower 1/(iw)^2, constant, upper iw) and the poles fitted but not
        reported: the whole fitted model.

    Returns
    -------
    numpy.ndarray
        (n_rows, n_freq) complex; rows are the outputs (times inputs for a poly-reference fit, in
        ``extras["rows"]`` order).

    Raises
    ------
    ParameterError
        For an estimate without residual terms when ``residuals=True``.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> freq = np.linspace(1, 100, 1000)
    >>> h = vm.synth.modal_frf(freq, fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> est = vm.fit_modes(h, band=(10, 60))
    >>> vm.synthesize_frf(est, freq).shape
    (1, 1000)
    """
    if "poles" not in est.extras or "residues" not in est.extras:
        raise ParameterError("est must come from vm.fit_modes (it needs poles and residues)")
    try:
        w = 2 * np.pi * np.asarray(freq, float)
    except (TypeError, ValueError):
        raise ParameterError(f"freq must be frequencies in Hz, got {type(freq).__name__}") from None
    if w.ndim > 1 or not np.isfinite(w).all():
        raise ParameterError("freq must be a 1-D array of finite frequencies in Hz")
    if residuals and np.any(w <= 0):
        raise ParameterError("freq must be > 0 where the residual terms are synthesised (the lower term is 1/(iw)^2)")
    iw = 1j * w
    out = 0
    pairs = list(zip(est.extras["poles"], est.extras["residues"]))
    if residuals:
        pairs += list(zip(est.extras.get("residual_poles", []), est.extras.get("residual_residues", [])))
    for (re, im), res in pairs:
        l = re + 1j * im
        R = np.array([a + 1j * b for a, b in res])
        out = out + R[:, None] / (iw - l) + np.conj(R)[:, None] / (iw - np.conj(l))
    if residuals:
        terms = est.extras.get("residual_terms")
        if terms is None:
            raise ParameterError("this estimate carries no residual terms (it predates them): refit with vm.fit_modes")
        res = np.array([[complex(*t["lower"]), complex(*t["constant"]), complex(*t["upper"])] for t in terms])
        out = out + res[:, :1] / iw ** 2 + res[:, 1:2] + res[:, 2:3] * iw
    return np.asarray(out)


def modal_crb(freq, *, fn, zeta, residues, noise_std) -> dict:
    """Cramer-Rao bound on fn and zeta for FRFs in complex Gaussian noise.

    From the Fisher information of the modal model with complex residues (the parameters fit_modes
    estimates, residual terms included); the noise has E|n|^2 = s^2 per output.

    Parameters
    ----------
    freq : array_like
        Frequency lines in Hz.
    fn, zeta : array_like
        The modes.
    residues : array_like
        Complex residues (n_outputs, n_modes).
    noise_std : array_like
        One noise std per output.

    Returns
    -------
    dict
        fn_std, zeta_std arrays.

    Raises
    ------
    ParameterError
        For shapes that do not match or a noise std that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> b = vm.modal_crb(np.linspace(1, 100, 1000), fn=[30.0], zeta=[0.02], residues=[[1.0]], noise_std=[1e-3])
    >>> bool(b["zeta_std"][0] < 1e-3)
    True
    """
    f = np.asarray(freq, float)
    f = f[f > 0]
    w = 2 * np.pi * f
    fn = np.atleast_1d(np.asarray(fn, float))
    zeta = np.atleast_1d(np.asarray(zeta, float))
    R = np.atleast_2d(np.asarray(residues, complex))  # (n_out, m)
    s_o = np.atleast_1d(np.asarray(noise_std, float))
    if zeta.shape != fn.shape:
        raise ParameterError(f"zeta has {zeta.size} values for {fn.size} modes")
    if R.shape[1] != fn.size:
        raise ParameterError(f"residues must be (n_outputs, n_modes={fn.size}), got shape {R.shape}")
    if s_o.shape != (R.shape[0],) or np.any(~np.isfinite(s_o)) or np.any(s_o <= 0):
        raise ParameterError(f"noise_std must hold one positive std per output ({R.shape[0]}), got {s_o.tolist()}")
    wn = 2 * np.pi * fn
    sig, wd = zeta * wn, wn * np.sqrt(1 - zeta ** 2)
    theta = np.column_stack([sig, wd]).ravel()
    sw = 1 / (s_o / np.sqrt(2))  # real and imaginary parts each s / sqrt 2
    coef = np.zeros((2 * fn.size + 6, R.shape[0]))
    coef[0:2 * fn.size:2] = R.real.T
    coef[1:2 * fn.size:2] = R.imag.T
    J = _full_jacobian(w, theta, coef, sw)
    cov = np.linalg.inv(J.T @ J)
    stds = np.array([pole_to_modal(sig[k], wd[k], cov[2 * k:2 * k + 2, 2 * k:2 * k + 2])[2:] for k in range(fn.size)])
    return {"fn_std": stds[:, 0], "zeta_std": stds[:, 1]}


def _circle_angles_fit(w, ang, wn0, zeta0, a0):
    """Least squares of the angles around the circle's centre on the exact viscous-mobility law
    ang = a0 + s 2 atan((w^2 - wn^2) / (2 zeta wn w)): fn, zeta and their covariance (residual scale)."""
    from scipy.optimize import least_squares
    sgn = 1.0 if ang[-1] > ang[0] else -1.0

    def res(p):
        wn, z, a = p
        return ang - (a + sgn * 2 * np.arctan((w ** 2 - wn ** 2) / (2 * z * wn * w)))
    sol = least_squares(res, [wn0, max(zeta0, 1e-6), a0], x_scale=[wn0, max(zeta0, 1e-6), 1.0],
                        bounds=([w[0], 1e-9, -np.inf], [w[-1], 1.0, np.inf]), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    J = sol.jac
    dof = max(ang.size - 3, 1)
    s2 = float(sol.fun @ sol.fun) / dof
    try:
        cov = np.linalg.inv(J.T @ J) * s2
    except np.linalg.LinAlgError:
        cov = np.full((3, 3), np.nan)
    return float(sol.x[0]), float(sol.x[1]), float(sol.x[2]), cov


def circle_fit(frf: FRF, *, band, output=0, input=0) -> ModalEstimate:
    """SDOF circle fit (Kennedy-Pancu) on the mobility around one peak.

    The mobility of a viscously damped mode traces a circle on which the angle from the resonance point
    obeys tan(theta / 2) = (w^2 - wn^2) / (2 zeta wn w) exactly; fn, zeta and the resonance angle are
    fitted by least squares on all points, with stds from the residual scale.

    Parameters
    ----------
    frf : FRF
        The FRFs.
    band : tuple of float
        (lo, hi) Hz around one peak.
    output, input : int or str
        The FRF row and column.

    Returns
    -------
    ModalEstimate
        One mode.

    Raises
    ------
    ParameterError
        For a band with too few lines or unknown channels.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> freq = np.linspace(1, 100, 2000)
    >>> h = vm.synth.modal_frf(freq, fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> round(float(vm.circle_fit(h, band=(27, 33)).zeta[0]), 4)
    0.02
    """
    if not isinstance(frf, FRF):
        raise ParameterError(f"frf must be a vm.FRF, got {type(frf).__name__}")
    lo, hi = check_band(band, 2 * frf.freq[-1] + 1e-9)
    mob = frf.to("mobility") if frf.form in ("receptance", "accelerance") else frf
    o = name_index(frf.outputs, output, what="output")
    i = name_index(frf.inputs, input, what="input")
    sel = (frf.freq >= lo) & (frf.freq <= hi) & (frf.freq > 0)
    if sel.sum() < 6:
        raise FitError(f"circle_fit: band={band!r} holds {int(sel.sum())} lines; at least 6 are needed")
    f = frf.freq[sel]
    h = mob.h[o, i, sel]
    x, y = h.real, h.imag
    A = np.column_stack([x, y, np.ones_like(x)])
    c, *_ = np.linalg.lstsq(A, -(x ** 2 + y ** 2), rcond=None)
    xc, yc = -c[0] / 2, -c[1] / 2
    rad = np.sqrt(xc ** 2 + yc ** 2 - c[2])
    ang = np.unwrap(np.angle((x - xc) + 1j * (y - yc)))
    w = 2 * np.pi * f
    rate = np.abs(np.diff(ang) / np.diff(w ** 2))
    j = int(np.argmax(rate))
    wn = np.sqrt(0.5 * (w[j] ** 2 + w[j + 1] ** 2))
    # angle from the resonance point (diametrically opposite the circle's touch at the origin side)
    a_n = 0.5 * (ang[j] + ang[j + 1])
    zs = []
    for a_idx in range(0, j + 1):
        for b_idx in range(j + 1, f.size):
            ta, tb = abs(ang[a_idx] - a_n), abs(ang[b_idx] - a_n)
            if 0.2 < ta < 2.5 and 0.2 < tb < 2.5:
                # mobility, viscous damping: tan(theta / 2) = (w^2 - wn^2) / (2 zeta wn w), exactly
                num = (w[b_idx] ** 2 - wn ** 2) / w[b_idx] + (wn ** 2 - w[a_idx] ** 2) / w[a_idx]
                zs.append(num / (2 * wn * (np.tan(ta / 2) + np.tan(tb / 2))))
    if not zs:
        raise FitError("circle_fit: too few points on either side of the resonance in band")
    wn, zeta, a_n, cov = _circle_angles_fit(w, ang, wn, float(np.median(zs)), a_n)
    fn_std = float(np.sqrt(cov[0, 0])) / (2 * np.pi)
    return ModalEstimate(fn=[wn / (2 * np.pi)], zeta=[zeta], fn_std=[fn_std],
                         zeta_std=[float(np.sqrt(cov[1, 1]))], method="circle",
                         extras={"center": [float(xc), float(yc)], "radius": float(rad)})

