"""Beams with rotary inertia (Rayleigh) and with shear deformation too (Timoshenko), beside Euler-Bernoulli.

Their frequencies and mode shapes come from the exact frequency equation of ``_beam_solver.py``; their
forced response from modal expansion (``expansion.py``).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ..core._validate import finite_number, positive
from ..core.errors import ParameterError
from ._beam_solver import SectionModes, _Section
from .continua import _CHAR, _est, _n
from .expansion import ModalExpansion

__all__ = ["RayleighBeam", "TimoshenkoBeam", "slenderness_limit"]

class _BeamTheory(SectionModes, ModalExpansion):
    """What Rayleigh and Timoshenko beams share: properties, modes and the comparison with Euler-Bernoulli."""

    theory = ""

    def _common(self, E, I, rho, A, L, bc, zeta):
        self.E, self.I = positive(E, "E"), positive(I, "I")
        self.rho, self.A, self.L = positive(rho, "rho"), positive(A, "A"), positive(L, "L")
        if bc not in _CHAR:
            raise ParameterError(f"bc={bc!r} must be one of {tuple(_CHAR)}")
        self.bc, self.zeta = bc, zeta

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(E={self.E:g}, I={self.I:g}, rho={self.rho:g}, A={self.A:g}, L={self.L:g}, "
                f"bc={self.bc!r}; L/r={self.slenderness:.4g})")

    @property
    def slenderness(self) -> float:
        """L / r with r = sqrt(I / A) the radius of gyration of the section."""
        return self.L / np.sqrt(self.I / self.A)

    def modes(self, n: int = 3):
        """The first n modes by the exact frequency equation of this theory.

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
        >>> import vibmeasure as vm
        >>> b = vm.models.RayleighBeam(E=210e9, I=1e-8, rho=7850, A=1e-4, L=1.0)
        >>> round(float(b.modes(1).fn[0]), 2)         # slender: as Euler-Bernoulli's 28.94 Hz
        28.94
        """
        w = self._section().omegas(_n(n))
        return _est(w / (2 * np.pi), self.zeta, f"beam {self.bc} {self.theory}")

    def ratio_to_euler(self, n: int = 3) -> np.ndarray:
        """Each mode's frequency over the Euler-Bernoulli beam's of the same mode number (below 1).

        Parameters
        ----------
        n : int
            How many modes.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For n below 1.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> b = vm.models.TimoshenkoBeam(E=210e9, I=8.33e-6, rho=7850, A=0.01, L=1.0, bc="simply-supported")
        >>> round(float(b.ratio_to_euler(1)[0]), 3)          # L/r = 34.6: 1.6 % below Euler-Bernoulli
        0.984
        """
        n = _n(n)
        eb = _Section(self.E * self.I, self.rho * self.A, 0.0, None, self.L, self.bc).omegas(n)
        return self._section().omegas(n) / eb


class RayleighBeam(_BeamTheory):
    """Euler-Bernoulli beam plus the rotary inertia rho I of its sections (Rayleigh's beam theory).

    Parameters
    ----------
    E, I, rho, A, L : float
        Young's modulus (Pa), second moment of area (m^4), density (kg/m^3), section (m^2), length (m).
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
    >>> import vibmeasure as vm
    >>> b = vm.models.RayleighBeam(E=210e9, I=8.33e-6, rho=7850, A=0.01, L=1.0, bc="simply-supported")
    >>> round(float(b.slenderness), 1)
    34.6
    """

    theory = "rayleigh"

    def __init__(self, *, E, I, rho, A, L, bc="cantilever", zeta=0.0):
        self._common(E, I, rho, A, L, bc, zeta)

    def _section(self):
        return _Section(self.E * self.I, self.rho * self.A, self.rho * self.I, None, self.L, self.bc)


class TimoshenkoBeam(_BeamTheory):
    """A beam with shear deformation and rotary inertia (Timoshenko): stocky beams and high modes.

    Parameters
    ----------
    E, I, rho, A, L : float
        Young's modulus (Pa), second moment of area (m^4), density (kg/m^3), section (m^2), length (m).
    bc : {"cantilever", "simply-supported", "clamped-clamped", "free-free", "clamped-pinned"}
        Boundary conditions (free-free: the flexible modes).
    G : float, optional
        Shear modulus in Pa (default E / (2 (1 + nu))).
    nu : float
        Poisson's ratio, used when G is not given.
    kappa : float
        Shear coefficient of the section (5/6 rectangle, 0.9 solid circle, 0.5 thin-walled tube).
    zeta : float
        Modal damping ratio given to every mode.

    Raises
    ------
    ParameterError
        For values that are not positive, nu outside (-1, 0.5], or an unknown bc.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> b = vm.models.TimoshenkoBeam(E=210e9, I=8.33e-6, rho=7850, A=0.01, L=0.5, bc="cantilever")
    >>> round(float(b.ratio_to_euler(2)[1]), 3)            # a stocky beam's second mode: 17 % below
    0.833
    """

    theory = "timoshenko"

    def __init__(self, *, E, I, rho, A, L, bc="cantilever", G=None, nu=0.3, kappa=5 / 6, zeta=0.0):
        self._common(E, I, rho, A, L, bc, zeta)
        if G is None:
            nu = finite_number(nu, "nu")
            if not -1 < nu <= 0.5:
                raise ParameterError(f"nu={nu!r} must be in (-1, 0.5]")
            G = self.E / (2 * (1 + nu))
        self.G, self.kappa = positive(G, "G"), positive(kappa, "kappa")

    def _section(self):
        return _Section(self.E * self.I, self.rho * self.A, self.rho * self.I, self.kappa * self.G * self.A, self.L,
                        self.bc)


def slenderness_limit(bc: str = "cantilever", *, mode: int = 1, tolerance: float = 0.01,
                      theory: str = "timoshenko", nu: float = 0.3, kappa: float = 5 / 6) -> float:
    """The slenderness L / r below which a beam theory's frequency falls more than ``tolerance`` below
    Euler-Bernoulli's: where the slender-beam model stops being good enough.

    Parameters
    ----------
    bc : str
        Boundary conditions, as ``Beam``'s.
    mode : int
        Mode number (higher modes need more slenderness).
    tolerance : float
        Relative difference, e.g. 0.01 for 1 %.
    theory : {"timoshenko", "rayleigh"}
        Which effects: shear and rotary inertia, or rotary inertia alone.
    nu, kappa : float
        Poisson's ratio (E / G = 2 (1 + nu)) and the shear coefficient (Timoshenko only).

    Returns
    -------
    float
        L / r.

    Raises
    ------
    ParameterError
        For a tolerance outside (0, 0.5) or an unknown theory or bc.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.models.slenderness_limit("simply-supported", tolerance=0.01), 1)    # rectangle, steel
    44.7
    """
    tol = positive(tolerance, "tolerance")
    if not tol < 0.5:
        raise ParameterError(f"tolerance={tolerance!r} must be below 0.5")
    if theory not in ("timoshenko", "rayleigh"):
        raise ParameterError(f"theory={theory!r} must be 'timoshenko' or 'rayleigh'")
    mode = _n(mode)
    nu = finite_number(nu, "nu")
    if not -1 < nu <= 0.5:
        raise ParameterError(f"nu={nu!r} must be in (-1, 0.5]")
    e_kg = 2 * (1 + nu) / positive(kappa, "kappa")      # E / (kappa G)

    def shortfall(log_sr):
        r2 = np.exp(-2 * log_sr)         # unit EI, rho A and L: r^2 = I / A
        sec = _Section(1.0, 1.0, r2, None if theory == "rayleigh" else 1 / (e_kg * r2), 1.0, bc)
        eb = _Section(1.0, 1.0, 0.0, None, 1.0, bc)
        return sec.omegas(mode)[-1] / eb.omegas(mode)[-1] - (1 - tol)

    return float(np.exp(brentq(shortfall, np.log(2.0), np.log(1e5), xtol=1e-10)))
