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
    """Axial vibration of a uniform rod.

    Parameters
    ----------
    E : float
        Young's modulus in Pa.
    rho : float
        Density in kg/m^3.
    L : float
        Length in m.
    bc : {"fixed-free", "fixed-fixed", "free-free"}
        Boundary conditions (free-free: the flexible modes).
    zeta : float
        Modal damping ratio.

    Raises
    ------
    ParameterError
        For values that are not positive or an unknown bc.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(float(vm.models.Rod(E=210e9, rho=7850, L=1.0).modes(1).fn[0]), 0)
    1293.0
    """

    def __init__(self, *, E, rho, L, bc="fixed-free", zeta=0.0):
        self.c = np.sqrt(positive(E, "E") / positive(rho, "rho"))
        self.L = positive(L, "L")
        if bc not in ("fixed-free", "fixed-fixed", "free-free"):
            raise ParameterError(f"bc={bc!r} must be fixed-free, fixed-fixed or free-free")
        self.bc, self.zeta = bc, zeta

    def modes(self, n: int = 3) -> ModalEstimate:
        """The first n modes.

        Parameters
        ----------
        n : int
            How many modes.

        Returns
        -------
        ModalEstimate

        Raises
        ------
        ParameterError
            For n below 1.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.models.Rod(E=210e9, rho=7850, L=1.0).modes(3).n_modes
        3
        """
        k = np.arange(1, _n(n) + 1)
        mult = (2 * k - 1) / 2 if self.bc == "fixed-free" else k
        return _est(mult * self.c / (2 * self.L), self.zeta, f"rod {self.bc}")


class Shaft(Rod):
    """Torsional vibration of a uniform circular shaft (the polar moment cancels).

    Parameters
    ----------
    G : float
        Shear modulus in Pa.
    rho : float
        Density in kg/m^3.
    L : float
        Length in m.
    bc : {"fixed-free", "fixed-fixed", "free-free"}
        Boundary conditions, as a rod's.
    zeta : float
        Modal damping ratio.

    Raises
    ------
    ParameterError
        For values that are not positive or an unknown bc.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.models.Shaft(G=80e9, rho=7850, L=1.0).modes(2).n_modes
    2
    """

    def __init__(self, *, G, rho, L, bc="fixed-free", zeta=0.0):
        super().__init__(E=G, rho=rho, L=L, bc=bc, zeta=zeta)


class String:
    """A taut string: fn = n / (2 L) sqrt(T / mu).

    Parameters
    ----------
    T : float
        Tension in N.
    mu : float
        Mass per length in kg/m.
    L : float
        Length in m.
    zeta : float
        Modal damping ratio.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> float(vm.models.String(T=100.0, mu=0.01, L=0.5).modes(1).fn[0])
    100.0
    """

    def __init__(self, *, T, mu, L, zeta=0.0):
        self.c = np.sqrt(positive(T, "T") / positive(mu, "mu"))
        self.L = positive(L, "L")
        self.zeta = zeta

    def modes(self, n: int = 3) -> ModalEstimate:
        """The first n modes.

        Parameters
        ----------
        n : int
            How many modes.

        Returns
        -------
        ModalEstimate

        Raises
        ------
        ParameterError
            For n below 1.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> np.round(vm.models.String(T=100.0, mu=0.01, L=0.5).modes(2).fn, 1).tolist()
        [100.0, 200.0]
        """
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
    """Roots beta_n L of an Euler-Bernoulli beam's characteristic equation (flexible modes).

    Parameters
    ----------
    bc : str
        Boundary conditions, as ``Beam``'s.
    n : int
        How many roots.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ParameterError
        For an unknown bc.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(float(vm.models.beta_l("cantilever", 1)[0]), 4)
    1.8751
    """
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
    """Euler-Bernoulli beam: fn = (beta L)^2 / (2 pi L^2) sqrt(E I / (rho A)).

    Parameters
    ----------
    E : float
        Young's modulus in Pa.
    I : float
        Second moment of area in m^4.
    rho : float
        Density in kg/m^3.
    A : float
        Cross-section in m^2.
    L : float
        Length in m.
    bc : {"cantilever", "simply-supported", "clamped-clamped", "free-free", "clamped-pinned"}
        Boundary conditions (free-free: the flexible modes).
    zeta : float
        Modal damping ratio given to every mode.

    Raises
    ------
    ParameterError
        For values that are not positive or an unknown bc.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> b = vm.models.Beam(E=210e9, I=1e-8, rho=7850, A=1e-4, L=1.0, bc="cantilever")
    >>> round(float(b.modes(1).fn[0]), 2)
    28.94
    """

    def __init__(self, *, E, I, rho, A, L, bc="cantilever", zeta=0.0):
        self.EI = positive(E, "E") * positive(I, "I")
        self.m = positive(rho, "rho") * positive(A, "A")
        self.L = positive(L, "L")
        if bc not in _CHAR:
            raise ParameterError(f"bc={bc!r} must be one of {tuple(_CHAR)}")
        self.bc, self.zeta = bc, zeta

    def modes(self, n: int = 3) -> ModalEstimate:
        """The first n modes.

        Parameters
        ----------
        n : int
            How many modes.

        Returns
        -------
        ModalEstimate
            fn in Hz (std 0), zeta as given.

        Raises
        ------
        ParameterError
            For n below 1.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.models.Beam(E=210e9, I=1e-8, rho=7850, A=1e-4, L=1.0).modes(2).n_modes
        2
        """
        bl = beta_l(self.bc, n)
        fn = bl ** 2 / (2 * np.pi * self.L ** 2) * np.sqrt(self.EI / self.m)
        return _est(fn, self.zeta, f"beam {self.bc}")

    def shape(self, mode: int, x) -> np.ndarray:
        """Mode shape (unit maximum) at positions x.

        Parameters
        ----------
        mode : int
            The 1-based mode number.
        x : array_like
            Positions along the beam in m.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For a mode below 1 or positions outside the beam.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> b = vm.models.Beam(E=210e9, I=1e-8, rho=7850, A=1e-4, L=1.0, bc="cantilever")
        >>> round(float(abs(b.shape(1, [1.0])[0])), 3)      # the free tip moves most
        1.0
        """
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
    """Equivalent stiffness of common elements (N/m, or N m/rad for torsion).

    rod EA/L, cantilever tip 3EI/L^3, simply supported midspan 48EI/L^3, clamped-clamped midspan
    192EI/L^3, torsion GJ/L, coil spring G d^4 / (8 D^3 n).

    Parameters
    ----------
    kind : str
        "rod", "cantilever", "simply-supported", "clamped-clamped", "torsion" or "coil".
    **p : float
        The element's parameters by name (E, A, I, L, G, J, d, D, n).

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        For an unknown kind, or a parameter missing or not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.models.stiffness("cantilever", E=210e9, I=1e-8, L=1.0)
    6300.0
    """
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
    """Springs in series: 1 / sum(1/k).

    Parameters
    ----------
    *k : float
        Stiffnesses.

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        For a stiffness that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.models.series(2e3, 2e3)
    1000.0
    """
    return float(1 / sum(1 / positive(x, "k") for x in k))


def parallel(*k) -> float:
    """Springs in parallel: sum(k).

    Parameters
    ----------
    *k : float
        Stiffnesses.

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        For a stiffness that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.models.parallel(1e3, 2e3)
    3000.0
    """
    return float(sum(positive(x, "k") for x in k))


def pendulum_period(length: float, g: float = _G0) -> float:
    """Small-angle period of a simple pendulum, 2 pi sqrt(L / g).

    Parameters
    ----------
    length : float
        Length in m.
    g : float
        Gravity in m/s^2.

    Returns
    -------
    float
        s.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(vm.models.pendulum_period(1.0), 3)
    2.006
    """
    return float(2 * np.pi * np.sqrt(positive(length, "length") / positive(g, "g")))


def pendulum_gravity(length: float, period: float) -> float:
    """Gravity from a simple pendulum's length and measured period: 4 pi^2 L / T^2.

    Parameters
    ----------
    length : float
        Length in m.
    period : float
        Measured period in s.

    Returns
    -------
    float
        m/s^2.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(vm.models.pendulum_gravity(1.0, 2.006), 2)
    9.81
    """
    return float(4 * np.pi ** 2 * positive(length, "length") / positive(period, "period") ** 2)


def compound_pendulum_fn(*, mass: float, inertia_pivot: float, distance: float, g: float = _G0) -> float:
    """Natural frequency of a compound pendulum: sqrt(m g d / I_pivot) / 2 pi.

    Parameters
    ----------
    mass : float
        Mass in kg.
    inertia_pivot : float
        Moment of inertia about the pivot in kg m^2.
    distance : float
        Pivot to centre of mass in m.
    g : float
        Gravity in m/s^2.

    Returns
    -------
    float
        Hz.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(vm.models.compound_pendulum_fn(mass=1.0, inertia_pivot=1.0, distance=1.0), 3)
    0.498
    """
    return float(np.sqrt(positive(mass, "mass") * positive(g, "g") * positive(distance, "distance")
                         / positive(inertia_pivot, "inertia_pivot")) / (2 * np.pi))


def whirling_speed_rpm(*, k: float, m: float) -> float:
    """Critical (whirling) speed of a disc on a shaft, in rpm.

    Parameters
    ----------
    k : float
        Lateral stiffness of the shaft in N/m.
    m : float
        Mass of the disc in kg.

    Returns
    -------
    float
        rpm.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(vm.models.whirling_speed_rpm(k=3947.84, m=1.0), 0)
    600.0
    """
    return float(np.sqrt(positive(k, "k") / positive(m, "m")) * 60 / (2 * np.pi))
