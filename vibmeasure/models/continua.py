"""Continua: rods, shafts, strings and Euler-Bernoulli beams. Frequencies come as ModalEstimates (zeta as
given); shear and rotary inertia (Timoshenko, Rayleigh) are in ``beams.py``."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ..core._validate import positive
from ..core.errors import ParameterError
from ..core.results import ModalEstimate
from ._beam_solver import SectionModes, _Section
from .expansion import ModalExpansion

__all__ = ["Rod", "Shaft", "String", "Beam", "beta_l"]


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


class Rod(ModalExpansion):
    """Axial vibration of a uniform rod; with its section A, its forced response by modal expansion.

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
    A : float, optional
        Section in m^2 (needed for modal masses and the FRF).

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

    def __init__(self, *, E, rho, L, bc="fixed-free", zeta=0.0, A=None):
        self.c = np.sqrt(positive(E, "E") / positive(rho, "rho"))
        self.rho, self.L = float(rho), positive(L, "L")
        self._section_area = None if A is None else positive(A, "A")
        if bc not in ("fixed-free", "fixed-fixed", "free-free"):
            raise ParameterError(f"bc={bc!r} must be fixed-free, fixed-fixed or free-free")
        self.bc, self.zeta = bc, zeta

    def _modal_set(self, n):
        if self._section_area is None:
            raise ParameterError(f"{type(self).__name__} needs its section ({'J' if isinstance(self, Shaft) else 'A'}) "
                                 "for modal masses and forced response")
        mu, L = self.rho * self._section_area, self.L
        k = np.arange(1, n + 1)
        w = 2 * np.pi * self.modes(n).fn
        if self.bc == "fixed-free":
            shape = lambda r, x: np.sin((2 * k[r] - 1) * np.pi * x / (2 * L))   # noqa: E731
        elif self.bc == "fixed-fixed":
            shape = lambda r, x: np.sin(k[r] * np.pi * x / L)   # noqa: E731
        else:
            shape = lambda r, x: np.cos(k[r] * np.pi * x / L)   # noqa: E731

        def fields(r, x):
            return shape(r, np.asarray(x, float)), np.zeros(np.shape(x))

        def rigid(xo, xi):
            t = 1 / np.sqrt(mu * L)
            return [(t, t)] if self.bc == "free-free" else []

        return w, fields, mu, 0.0, rigid

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
    J : float, optional
        Polar moment of the section in m^4 (needed for modal inertias and the FRF, then in rad/(N m)).

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

    def __init__(self, *, G, rho, L, bc="fixed-free", zeta=0.0, J=None):
        super().__init__(E=G, rho=rho, L=L, bc=bc, zeta=zeta, A=J)


class String(ModalExpansion):
    """A taut string: fn = n / (2 L) sqrt(T / mu); its forced response by modal expansion.

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
        self.mu, self.L = float(mu), positive(L, "L")
        self.zeta = zeta

    def _modal_set(self, n):
        k = np.arange(1, n + 1)

        def fields(r, x):
            return np.sin(k[r] * np.pi * np.asarray(x, float) / self.L), np.zeros(np.shape(x))

        return 2 * np.pi * self.modes(n).fn, fields, self.mu, 0.0, lambda xo, xi: []

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


class Beam(SectionModes, ModalExpansion):
    """Euler-Bernoulli beam: fn = (beta L)^2 / (2 pi L^2) sqrt(E I / (rho A)); its forced response by modal
    expansion (``RayleighBeam`` and ``TimoshenkoBeam`` add rotary inertia and shear).

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

    def _section(self):
        return _Section(self.EI, self.m, 0.0, None, self.L, self.bc)

    def __repr__(self) -> str:
        return f"Beam(EI={self.EI:g}, rho A={self.m:g}, L={self.L:g}, bc={self.bc!r})"

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
        """Mode shape at positions x, scaled to a largest displacement of 1 over the whole beam.

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
        x = np.asarray(x, float)
        if np.any((x < 0) | (x > self.L)) or not np.all(np.isfinite(x)):
            raise ParameterError(f"x must lie on the beam (0 .. L = {self.L:g} m)")
        w = 2 * np.pi * self.modes(_n(mode)).fn[-1]
        return self._section().fields(w, x)[0]
