"""Continua and equivalent systems: rods, shafts, strings, Euler-Bernoulli beams, equivalent
stiffness, pendulums and the whirling shaft. Frequencies come as ModalEstimates (zeta as given)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ..core._validate import positive
from ..core.errors import ParameterError
from ..core.results import ModalEstimate

__all__ = ["Rod", "Shaft", "String", "Beam", "beta_l", "stiffness", "pendulum_period", "pendulum_gravity",
           "compound_pendulum_fn", "whirling_speed_rpm", "series", "parallel"]

_G0 = 9.80665


MAX_MODES = 200   # beyond this cosh(beta L) overflows double precision in the beam equations


def _est(fn, zeta, name, shapes=None):
    fn = np.asarray(fn, float)
    if not (np.isfinite(zeta) and 0 <= zeta < 1):
        raise ParameterError(f"zeta={zeta!r} must be in [0, 1): negative damping makes an unstable model")
    return ModalEstimate(fn=fn, zeta=np.full(fn.size, zeta), fn_std=np.zeros(fn.size), zeta_std=np.zeros(fn.size),
                         method=f"model:{name}", shapes=shapes)


def _n(n):
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ParameterError(f"n={n!r} must be an integer >= 1 (number of modes)")
    if n > MAX_MODES:
        raise ParameterError(f"n={n!r} modes: at most {MAX_MODES} (higher modes of a continuum model are beyond "
                             "double precision and beyond the slender-beam assumptions)")
    return int(n)


class Rod:
    """Axial vibration of a uniform rod: E (Pa), rho (kg/m^3), L (m); bc fixed-free, fixed-fixed,
    free-free (flexible modes)."""

    def __init__(self, *, E, rho, L, bc="fixed-free", zeta=0.0):
        self.c = np.sqrt(positive(E, "E") / positive(rho, "rho"))
        self.L = positive(L, "L")
        if bc not in ("fixed-free", "fixed-fixed", "free-free"):
            raise ParameterError(f"bc={bc!r} must be fixed-free, fixed-fixed or free-free")
        self.bc, self.zeta = bc, zeta

    def modes(self, n: int = 3) -> ModalEstimate:
        k = np.arange(1, _n(n) + 1)
        mult = (2 * k - 1) / 2 if self.bc == "fixed-free" else k
        return _est(mult * self.c / (2 * self.L), self.zeta, f"rod {self.bc}")


class Shaft(Rod):
    """Torsional vibration of a uniform shaft: G (Pa), rho (kg/m^3), L (m) (circular: the polar
    moment cancels); same boundary conditions as a rod."""

    def __init__(self, *, G, rho, L, bc="fixed-free", zeta=0.0):
        super().__init__(E=G, rho=rho, L=L, bc=bc, zeta=zeta)


class String:
    """A taut string: tension T (N), mass per length mu (kg/m), length L (m): fn = n/(2L) sqrt(T/mu)."""

    def __init__(self, *, T, mu, L, zeta=0.0):
        self.c = np.sqrt(positive(T, "T") / positive(mu, "mu"))
        self.L = positive(L, "L")
        self.zeta = zeta

    def modes(self, n: int = 3) -> ModalEstimate:
        return _est(np.arange(1, _n(n) + 1) * self.c / (2 * self.L), self.zeta, "string")


# characteristic equations divided by cosh(x), so they stay finite and pole-free
_CHAR = {
    "cantilever": lambda x: np.cos(x) + 1 / np.cosh(x),
    "clamped-clamped": lambda x: np.cos(x) - 1 / np.cosh(x),
    "free-free": lambda x: np.cos(x) - 1 / np.cosh(x),
    "clamped-pinned": lambda x: np.sin(x) - np.cos(x) * np.tanh(x),
    "simply-supported": lambda x: np.sin(x),
}


def beta_l(bc: str, n: int = 3) -> np.ndarray:
    """Roots beta_n L of an Euler-Bernoulli beam's characteristic equation (flexible modes)."""
    if bc not in _CHAR:
        raise ParameterError(f"bc={bc!r} must be one of {tuple(_CHAR)}")
    n = _n(n)
    if bc == "simply-supported":
        return np.pi * np.arange(1, n + 1)
    f = _CHAR[bc]
    roots = []
    x = 1.0  # above the rigid-body root at 0 of the free-free and clamped-clamped forms
    while len(roots) < n:
        a, b = x, x + np.pi / 4
        if f(a) * f(b) < 0:
            roots.append(brentq(f, a, b, xtol=1e-14))
        x = b
    return np.array(roots)


class Beam:
    """Euler-Bernoulli beam: E (Pa), I (m^4), rho (kg/m^3), A (m^2), L (m), bc cantilever,
    simply-supported, clamped-clamped, free-free (flexible modes), clamped-pinned.
    fn = (beta L)^2 / (2 pi L^2) sqrt(E I / (rho A))."""

    def __init__(self, *, E, I, rho, A, L, bc="cantilever", zeta=0.0):
        self.EI = positive(E, "E") * positive(I, "I")
        self.m = positive(rho, "rho") * positive(A, "A")
        self.L = positive(L, "L")
        if bc not in _CHAR:
            raise ParameterError(f"bc={bc!r} must be one of {tuple(_CHAR)}")
        self.bc, self.zeta = bc, zeta

    def modes(self, n: int = 3) -> ModalEstimate:
        bl = beta_l(self.bc, n)
        fn = bl ** 2 / (2 * np.pi * self.L ** 2) * np.sqrt(self.EI / self.m)
        return _est(fn, self.zeta, f"beam {self.bc}")

    def shape(self, mode: int, x) -> np.ndarray:
        """Mode shape (unit maximum) at positions x (m) for the 1-based mode number."""
        b = beta_l(self.bc, mode)[-1] / self.L
        x = np.asarray(x, float)
        if self.bc == "simply-supported":
            y = np.sin(b * x)
        else:
            bl = b * self.L
            if self.bc in ("cantilever",):
                s = (np.cos(bl) + np.cosh(bl)) / (np.sin(bl) + np.sinh(bl))
                y = np.cosh(b * x) - np.cos(b * x) - s * (np.sinh(b * x) - np.sin(b * x))
            elif self.bc == "free-free":
                s = (np.cos(bl) - np.cosh(bl)) / (np.sin(bl) - np.sinh(bl))
                y = np.cosh(b * x) + np.cos(b * x) - s * (np.sinh(b * x) + np.sin(b * x))
            else:  # clamped-clamped, clamped-pinned
                s = (np.cos(bl) - np.cosh(bl)) / (np.sin(bl) - np.sinh(bl))
                y = np.cosh(b * x) - np.cos(b * x) - s * (np.sinh(b * x) - np.sin(b * x))
        return y / np.max(np.abs(y))


def stiffness(kind: str, **p) -> float:
    """Equivalent stiffness (N/m, or N m/rad for torsion) of common elements:
    rod EA/L, cantilever tip 3EI/L^3, simply supported midspan 48EI/L^3, clamped-clamped midspan
    192EI/L^3, torsion GJ/L, coil spring G d^4 / (8 D^3 n)."""
    forms = {
        "rod": (("E", "A", "L"), lambda E, A, L: E * A / L),
        "cantilever": (("E", "I", "L"), lambda E, I, L: 3 * E * I / L ** 3),
        "simply-supported": (("E", "I", "L"), lambda E, I, L: 48 * E * I / L ** 3),
        "clamped-clamped": (("E", "I", "L"), lambda E, I, L: 192 * E * I / L ** 3),
        "torsion": (("G", "J", "L"), lambda G, J, L: G * J / L),
        "coil-spring": (("G", "d", "D", "n"), lambda G, d, D, n: G * d ** 4 / (8 * D ** 3 * n)),
    }
    if kind not in forms:
        raise ParameterError(f"kind={kind!r} must be one of {tuple(forms)}")
    names, f = forms[kind]
    missing = [nm for nm in names if nm not in p]
    extra = [nm for nm in p if nm not in names]
    if missing or extra:
        raise ParameterError(f"stiffness {kind!r} needs exactly {names}; missing {missing}, unknown {extra}")
    return float(f(*(positive(p[nm], nm) for nm in names)))


def series(*k) -> float:
    """Springs in series: 1 / sum(1/k)."""
    return float(1 / sum(1 / positive(x, "k") for x in k))


def parallel(*k) -> float:
    """Springs in parallel: sum(k)."""
    return float(sum(positive(x, "k") for x in k))


def pendulum_period(length: float, g: float = _G0) -> float:
    """Small-angle period of a simple pendulum, 2 pi sqrt(L / g)."""
    return float(2 * np.pi * np.sqrt(positive(length, "length") / positive(g, "g")))


def pendulum_gravity(length: float, period: float) -> float:
    """Gravity from a simple pendulum's length and measured period: 4 pi^2 L / T^2."""
    return float(4 * np.pi ** 2 * positive(length, "length") / positive(period, "period") ** 2)


def compound_pendulum_fn(*, mass: float, inertia_pivot: float, distance: float, g: float = _G0) -> float:
    """Natural frequency (Hz) of a compound pendulum: sqrt(m g d / I_pivot) / 2 pi."""
    return float(np.sqrt(positive(mass, "mass") * positive(g, "g") * positive(distance, "distance")
                         / positive(inertia_pivot, "inertia_pivot")) / (2 * np.pi))


def whirling_speed_rpm(*, k: float, m: float) -> float:
    """Critical (whirling) speed of a disc of mass m on a shaft of lateral stiffness k, in rpm."""
    return float(np.sqrt(positive(k, "k") / positive(m, "m")) * 60 / (2 * np.pi))
