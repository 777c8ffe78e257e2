"""The ring-down estimator for decays that are linear by construction, as EFDD builds them (the
correlation function of a singular-value bell): the fit without the nonlinear checks
(:func:`linear_decay`), and a jackknife replicate's point estimate (:func:`replicate_decay`). Steps
of :mod:`vibmeasure.identify.ringdown`."""

from __future__ import annotations

import numpy as np

from ..core._threads import single_threaded
from ..core.errors import FitError, ParameterError
from ..core.results import ModalEstimate
from ._rd_ml import _lm, _pack
from .ringdown import _numerical_failure, _prepare, _ringdown, _start_values, _trim_to_noise_floor


@single_threaded
def linear_decay(rec, n_modes=1, poles=None) -> ModalEstimate:
    """The ring-down estimator without its nonlinear checks (dry friction, amplitude-dependent damping,
    backbone), for a decay that is linear by construction: EFDD's correlation function of a bell is an
    average over amplitudes, where those checks have no meaning, and it is fitted a dozen times per
    mode (bias steps, jackknife). The same fit, stds and mode flags as ``ringdown(rec, start=0)``;
    ``extras["fitted_poles"]`` holds every fitted component's pole. ``poles`` (such a list from a fit
    of a nearby decay, as a jackknife replicate's full-data fit) replaces the subspace and spectral
    start values."""
    try:
        return _ringdown(rec, None, n_modes, None, 0.0, 8, None, None, linear=True, poles=poles)
    except np.linalg.LinAlgError as exc:   # a fit gone to NaN or singular: said as the fit's failure
        raise _numerical_failure(exc) from None


@single_threaded
def replicate_decay(rec, poles, mode_hz: float) -> tuple[float, float] | None:
    """(fn, zeta) of the mode (the component whose damped frequency is nearest ``mode_hz``) of
    ``linear_decay(rec, 1, poles)``, for a jackknife replicate: the same preparation, start amplitudes,
    trim and Levenberg-Marquardt fit to the same convergence rule, without what a replicate's caller
    never reads (stds, the coloured-noise scale, classification, the estimate object: a fifth of a
    short decay's fit, 1.16 -> 0.90 ms per call on pyOMA2's example). None when the replicate cannot be fitted or its mode does not decay (a replicate the
    full estimator refuses as too uncertain is kept: its spread widens the jackknife std).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure.identify._rd_linear import linear_decay, replicate_decay
    >>> t = np.arange(2000) / 100.0
    >>> x = np.exp(-0.02 * 2 * np.pi * 3 * t) * np.cos(2 * np.pi * 3 * t)
    >>> x = x + 1e-3 * np.random.default_rng(0).normal(size=t.size)
    >>> rec = vm.Record.from_array(x, fs=100.0)
    >>> est = linear_decay(rec, 1)
    >>> fn, zeta = replicate_decay(rec, est.extras["fitted_poles"], 3.0)
    >>> bool(abs(fn - est.fn[0]) < 1e-9 and abs(zeta - est.zeta[0]) < 1e-9)
    True
    """
    try:
        d = _prepare(rec, None, 1, None, 0.0, 8, None, None)
        d.linear, d.poles = True, poles
        s = _start_values(d)
        if s is None:
            return None
        _trim_to_noise_floor(d, s)
        p, _, _ = _lm(_pack(s.sig, s.om, s.a, s.b), d.x, d.w, d.t, d.tn, s.sig.size)
    except (FitError, ParameterError, np.linalg.LinAlgError):
        return None
    k = int(np.argmin(np.abs(p[1:-2:4] / (2 * np.pi) - mode_hz)))
    sig, om = p[4 * k], p[4 * k + 1]
    if not (np.isfinite(sig) and np.isfinite(om) and sig > 0):
        return None
    wn = float(np.hypot(om, sig))
    return wn / (2 * np.pi), float(sig) / wn
