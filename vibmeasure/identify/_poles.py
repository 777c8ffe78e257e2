"""From a pole's decay rate and damped frequency (and their 2x2 covariance) to fn, zeta and stds."""

from __future__ import annotations

import numpy as np


def pole_to_modal(sigma: float, wd: float, cov2=None) -> tuple[float, float, float, float]:
    """fn (Hz) = sqrt(sigma^2 + wd^2) / 2 pi, zeta = sigma / wn, and their standard deviations by
    first-order propagation of the covariance of (sigma, wd) (NaN without one)."""
    wn = float(np.hypot(sigma, wd))
    fn, zeta = wn / (2 * np.pi), sigma / wn
    if cov2 is None:
        return fn, zeta, np.nan, np.nan
    c2 = np.asarray(cov2, float)
    g_wn = np.array([sigma, wd]) / wn
    g_z = np.array([wd ** 2, -sigma * wd]) / wn ** 3
    return fn, zeta, float(np.sqrt(max(g_wn @ c2 @ g_wn, 0)) / (2 * np.pi)), float(np.sqrt(max(g_z @ c2 @ g_z, 0)))
