"""Two output-only estimates of the same record checked against each other: SSI (time domain) and
FDD/EFDD (frequency domain) rest on different assumptions, so a mode both find with fn and zeta
within their stds is confirmed, and one they place apart is biased in at least one of them."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...core.errors import ParameterError, warn_quality
from ...core.results import ModalEstimate
from ..shapes import mac_pair

__all__ = ["oma_cross_check"]

DISAGREE_SIGMA = 3.0   # fn or zeta further apart than this many combined stds: the methods disagree
MATCH_REL = 0.01       # modes within 1 % in fn (or 3 combined stds, if wider) are the same mode
MATCH_MAC = 0.8        # ... when their shapes agree this well (where both have shapes)


def _match(a: ModalEstimate, b: ModalEstimate, k: int):
    """Index of b's mode that is a's mode k (nearest in fn, within MATCH_REL or 3 stds, shapes alike), or None."""
    best, best_d = None, np.inf
    for j in range(b.n_modes):
        d = abs(a.fn[k] - b.fn[j])
        s = np.hypot(np.nan_to_num(a.fn_std[k]), np.nan_to_num(b.fn_std[j]))
        if d > max(MATCH_REL * a.fn[k], DISAGREE_SIGMA * s):
            continue
        if a.shapes is not None and b.shapes is not None and a.shapes.shape[0] == b.shapes.shape[0]:
            if mac_pair(a.shapes[:, k], b.shapes[:, j]) < MATCH_MAC:
                continue
        if d < best_d:
            best, best_d = j, d
    return best


def _sigmas(a, b, k, j):
    """How many combined stds apart a's mode k and b's mode j are, in fn and in zeta."""
    out = []
    for va, vb, sa, sb in ((a.fn, b.fn, a.fn_std, b.fn_std), (a.zeta, b.zeta, a.zeta_std, b.zeta_std)):
        s = np.hypot(sa[k], sb[j])
        out.append(float(abs(va[k] - vb[j]) / s) if np.isfinite(s) and s > 0 else float("nan"))
    return out


def oma_cross_check(est: ModalEstimate, other: ModalEstimate) -> ModalEstimate:
    """``est`` with each mode checked against a second output-only estimate of the same record.

    A mode the other estimate also finds (fn within 1 % or three combined stds, shapes with MAC >= 0.8)
    is compared: where fn or zeta lie more than three combined standard deviations apart the mode is
    flagged ``methods_disagree`` (one of the methods is biased there: close modes, leakage into the
    FDD bell, a harmonic); a mode the other does not find is flagged ``not_confirmed``. The pairs and
    their separations in stds are in ``extras["cross_check"]``. Both estimates come from the same
    data, so their errors are correlated and the test is conservative: a flag means a real bias.

    Parameters
    ----------
    est : ModalEstimate
        The estimate to report (usually ``vm.oma_ssi``'s).
    other : ModalEstimate
        A second estimate of the same record (usually ``vm.oma_fdd``'s).

    Returns
    -------
    ModalEstimate
        ``est`` with the flags added and ``extras["cross_check"]``: per mode the other's fn and zeta
        (None when not found) and the separations ``fn_sigma``, ``zeta_sigma``.

    Raises
    ------
    ParameterError
        When either argument is not a ModalEstimate.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> chain = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), modal_zeta=[0.02, 0.02])
    >>> amb = vm.synth.ambient(chain, fs=100.0, duration=300.0, noise=0.05, seed=1)
    >>> both = vm.oma_cross_check(vm.oma_ssi(amb), vm.oma_fdd(amb))
    >>> [c["other_fn_hz"] is not None for c in both.extras["cross_check"]]
    [True, True]
    """
    for name, e in (("est", est), ("other", other)):
        if not isinstance(e, ModalEstimate):
            raise ParameterError(f"oma_cross_check: {name} must be a ModalEstimate (from vm.oma_ssi or vm.oma_fdd), "
                                 f"got {type(e).__name__}")
    rows, flags = [], []
    for k in range(est.n_modes):
        j = _match(est, other, k)
        fl = list(est.mode_flags[k])
        if j is None:
            fl.append("not_confirmed")
            rows.append({"fn_hz": float(est.fn[k]), "other_fn_hz": None, "other_zeta": None, "fn_sigma": None,
                         "zeta_sigma": None})
        else:
            sf, sz = _sigmas(est, other, k, j)
            if sf > DISAGREE_SIGMA or sz > DISAGREE_SIGMA:
                fl.append("methods_disagree")
            rows.append({"fn_hz": float(est.fn[k]), "other_fn_hz": float(other.fn[j]),
                         "other_zeta": float(other.zeta[j]), "fn_sigma": sf, "zeta_sigma": sz})
        flags.append(tuple(dict.fromkeys(fl)))
    extras = dict(est.extras, cross_check=rows, cross_check_method=other.method)
    out = dataclasses.replace(est, mode_flags=tuple(flags), flags=tuple(f for f in est.flags), extras=extras)
    bad = [r["fn_hz"] for r, fl in zip(rows, flags) if "methods_disagree" in fl]
    if bad:
        warn_quality(f"{est.method} and {other.method} disagree beyond {DISAGREE_SIGMA:g} combined stds at "
                     f"{', '.join(f'{x:.4g}' for x in bad)} Hz (extras['cross_check']): at least one is biased "
                     "there (close modes, a harmonic, a bell cut short)", stacklevel=2)
    return out
