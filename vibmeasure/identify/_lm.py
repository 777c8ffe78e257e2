"""Levenberg-Marquardt for variable-projection fits: few nonlinear parameters, many residuals.

The step solves the normal equations (J^T J + mu S^-2) dq = -J^T r, a p x p system for p parameters,
where a QR of J (MINPACK, scipy's ``least_squares(method="lm")``) costs rows x p^2 per iteration and
copies J into Fortran order: with 50,000 residual rows and 10-20 parameters that QR was most of
fit_modes' polish time. The globalisation is MINPACK's (J. J. More, "The Levenberg-Marquardt
algorithm: implementation and theory", 1978): a trust region of radius delta in the caller's
parameter scales S, the Gauss-Newton step when it fits inside, else the mu that puts the step on the
region's edge; the region shrinks after a poor prediction and grows after a good one. A parameter
the data hardly constrains (a pole with no resonance under it) thus moves by bounded steps instead
of running away in one.
"""

from __future__ import annotations

import numpy as np

FACTOR = 100.0   # MINPACK's initial step bound, in units of |q0 / S|
# Creeping: accepted steps that each lower the cost by less than STALL of itself, STALL_STEPS in a row,
# while the model over-predicts the decrease (ratio under 0.75). Along the flat valley of a pole with no
# resonance under it (a heavily damped pole standing in for the baseline) Kaufman's Jacobian predicts
# about 3x the decrease each step gives, and MINPACK's tests (ftol 1e-10) let the fit creep for a
# hundred evaluations, 2e-7 of the cost each; the poles that matter have converged long before.
STALL, STALL_STEPS = 1e-6, 3


def _step(lam, V, g, delta):
    """(step, mu) of the damped normal equations in eigen-coordinates of J^T J: the Gauss-Newton step
    when it fits within ``delta``, else the one of norm delta (within 10 %, MINPACK's tolerance)."""
    b = V.T @ g
    lam = np.maximum(lam, 0.0)
    floor = 1e-14 * max(float(lam.max()), 1e-300)

    def norm(mu):
        return float(np.linalg.norm(b / np.maximum(lam + mu, floor)))
    if norm(0.0) <= 1.1 * delta:
        mu = 0.0
    else:   # |p(mu)| falls monotonically in mu: bracket the edge, then bisect on log mu
        lo, hi = 0.0, max(float(np.linalg.norm(b)) / delta, floor)
        while norm(hi) > delta:
            lo, hi = hi, 4 * hi
        for _ in range(60):
            mid = 0.5 * (lo + hi) if lo == 0.0 else np.sqrt(lo * hi)
            n = norm(mid)
            if abs(n - delta) <= 0.1 * delta:
                break
            lo, hi = (mid, hi) if n > delta else (lo, mid)
        mu = mid
    return -V @ (b / np.maximum(lam + mu, floor)), mu


def levenberg_marquardt(fun, normal, q0, scale, *, max_nfev: int, ftol: float = 1e-10, xtol: float = 1e-10,
                        gtol: float = 1e-10):
    """Minimise |fun(q)|^2 from q0. ``fun(q)`` returns the residual vector r, ``normal(q)`` the normal
    equations' (J^T J, J^T r) at a point ``fun`` was called with (a variable-projection fit forms them
    without the rows x p Jacobian; the caller may cache); ``scale`` is each parameter's typical
    change. Stops as MINPACK does: relative decrease of the cost, actual and predicted, under
    ``ftol``; trust region under ``xtol`` relative to the scaled q; scaled gradient (cosine to the
    residual) under ``gtol``; or ``max_nfev`` residual evaluations. Returns (q, nfev)."""
    s = np.asarray(scale, float)
    q = np.asarray(q0, float).copy()
    r = fun(q)
    cost, nfev = float(r @ r), 1
    A, g = normal(q)
    A, g = A * np.outer(s, s), g * s            # in scaled parameters z = q / s
    delta = FACTOR * (float(np.linalg.norm(q / s)) or 1.0)
    creeping = 0
    while nfev < max_nfev:
        cn = np.sqrt(np.maximum(np.diag(A), 1e-300))
        if float(np.max(np.abs(g) / cn)) <= gtol * np.sqrt(max(cost, 1e-300)):
            break
        lam, V = np.linalg.eigh(A)
        step, mu = _step(lam, V, g, delta)
        pnorm = float(np.linalg.norm(step))
        if nfev == 1:
            delta = min(delta, pnorm)
        pAp = float(step @ A @ step)
        pred = (pAp + 2 * mu * pnorm ** 2) / cost            # relative predicted decrease (MINPACK's prered)
        r_new = fun(q + step * s)
        nfev += 1
        cost_new = float(r_new @ r_new)
        actred = 1 - cost_new / cost if cost_new < 100 * cost else -1.0
        ratio = actred / pred if pred > 0 else 0.0
        if ratio <= 0.25:   # a poor prediction: shrink the region (by up to 10x when the cost rose)
            dirder = -(pAp + mu * pnorm ** 2) / cost
            temp = 0.5 if actred >= 0 else 0.5 * dirder / (dirder + 0.5 * actred)
            if cost_new >= 100 * cost or temp < 0.1:
                temp = 0.1
            delta = temp * min(delta, pnorm / 0.1)
        elif mu == 0.0 or ratio >= 0.75:
            delta = pnorm / 0.5
        accepted = ratio >= 1e-4
        if accepted:
            q, r, cost = q + step * s, r_new, cost_new
            creeping = creeping + 1 if actred <= STALL and ratio < 0.75 else 0
            if creeping >= STALL_STEPS:
                break
        if (abs(actred) <= ftol and pred <= ftol and 0.5 * ratio <= 1) or delta <= xtol * float(np.linalg.norm(q / s)):
            break
        if accepted:
            A, g = normal(q)
            A, g = A * np.outer(s, s), g * s
    return q, nfev
