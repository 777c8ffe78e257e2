"""Model updating: fit model parameters to measured fn and zeta, carrying the uncertainty through."""

from __future__ import annotations

import numpy as np

from ..core._validate import positive
from ..core.errors import ParameterError
from ..core.results import ModalEstimate

__all__ = ["update_sdof", "update_mdof"]


def update_sdof(est: ModalEstimate, *, m: float, mode: int = 0) -> dict:
    """k and c of an SDOF with known mass from a measured mode: k = m wn^2, c = 2 zeta sqrt(k m), with
    stds by first-order propagation.

    Parameters
    ----------
    est : ModalEstimate
        The measured mode(s).
    m : float
        The known mass in kg.
    mode : int
        Which mode.

    Returns
    -------
    dict
        model, k, k_std, c, c_std.

    Raises
    ------
    ParameterError
        For a mode the estimate does not hold or a mass that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> meas = vm.ModalEstimate(fn=[10.0], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001])
    >>> round(vm.models.update_sdof(meas, m=1.0)["k"], 1)
    3947.8
    """
    from .sdof import SDOF
    if not isinstance(est, ModalEstimate):
        raise ParameterError(f"est must be a vm.ModalEstimate, got {type(est).__name__}")
    m = positive(m, "m")
    if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) or not 0 <= mode < est.n_modes:
        raise ParameterError(f"mode={mode!r} must be an index of the estimate's {est.n_modes} mode(s)")
    fn, z = float(est.fn[mode]), float(est.zeta[mode])
    fs, zs = float(np.nan_to_num(est.fn_std[mode])), float(np.nan_to_num(est.zeta_std[mode]))
    if not (np.isfinite(fn) and fn > 0 and np.isfinite(z) and z >= 0):
        raise ParameterError(f"mode {mode} has no usable fn/zeta ({fn}, {z})")
    wn = 2 * np.pi * fn
    k = m * wn ** 2
    k_std = 2 * m * wn * 2 * np.pi * fs
    c = 2 * z * np.sqrt(k * m)
    # c = 2 zeta m wn: relative variances add
    c_std = c * np.hypot(zs / z if z > 0 else 0.0, fs / fn)
    return {"model": SDOF(m=m, k=k, c=c), "k": k, "k_std": k_std, "c": c, "c_std": c_std}


def update_mdof(model, est: ModalEstimate) -> dict:
    """One stiffness scale s (K -> s K) fitted to measured frequencies by weighted least squares on w^2
    (weights 1/var), with its std; modes paired in order of frequency.

    Parameters
    ----------
    model : MDOF
        The model.
    est : ModalEstimate
        The measured modes with their stds.

    Returns
    -------
    dict
        model (the updated MDOF), k_scale, k_scale_std.

    Raises
    ------
    ParameterError
        For an estimate without stds or more modes than the model.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> m = vm.models.MDOF(np.eye(1), np.array([[1e4]]))
    >>> meas = vm.ModalEstimate(fn=[m.modes().fn[0] * 1.1], zeta=[0.01], fn_std=[0.01], zeta_std=[0.001])
    >>> round(vm.models.update_mdof(m, meas)["k_scale"], 2)
    1.21
    """
    pred = model.modes()
    n = min(pred.n_modes, est.n_modes)
    wp2 = (2 * np.pi * pred.fn[:n]) ** 2
    wm2 = (2 * np.pi * est.fn[:n]) ** 2
    var = (2 * (2 * np.pi) ** 2 * est.fn[:n] * np.nan_to_num(est.fn_std[:n], nan=0.0)) ** 2
    w = 1 / np.where(var > 0, var, np.max(var) if np.any(var > 0) else 1.0)
    s = float(np.sum(w * wm2 * wp2) / np.sum(w * wp2 ** 2))
    s_std = float(np.sqrt(1 / np.sum(w * wp2 ** 2))) if np.any(var > 0) else float("nan")
    return {"model": model.scaled(k_scale=s), "k_scale": s, "k_scale_std": s_std}
