"""Equivalent systems: element stiffnesses, springs in series and parallel, pendulums, the whirling shaft,
an N-mass chain from storey stiffnesses and a beam with a tip mass as one mass on a spring."""

from __future__ import annotations

import numpy as np

from ..core._validate import positive
from ..core.errors import ParameterError

__all__ = ["stiffness", "series", "parallel", "pendulum_period", "pendulum_gravity", "compound_pendulum_fn",
           "whirling_speed_rpm", "chain", "tip_mass_beam"]

_G0 = 9.80665


def stiffness(kind: str, **p) -> float:
    """Equivalent stiffness of common elements (N/m, or N m/rad for torsion).

    rod EA/L, cantilever tip 3EI/L^3, simply supported midspan 48EI/L^3, clamped-clamped midspan
    192EI/L^3, guided (a column clamped at the base whose top sways without rotating, as a storey between
    rigid floors) 12EI/L^3, torsion GJ/L, coil spring G d^4 / (8 D^3 n).

    Parameters
    ----------
    kind : str
        "rod", "cantilever", "simply-supported", "clamped-clamped", "guided", "torsion" or "coil-spring".
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
        "guided": (("E", "I", "L"), lambda E, I, L: 12 * E * I / L ** 3),
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


def pendulum_period(length: float, g: float = _G0, *, amplitude: float = 0.0) -> float:
    """Period of a simple pendulum: 2 pi sqrt(L / g) for small swings, 4 sqrt(L / g) K(sin^2(theta0 / 2))
    at a swing amplitude theta0 (K the complete elliptic integral of the first kind).

    Parameters
    ----------
    length : float
        Length in m.
    g : float
        Gravity in m/s^2.
    amplitude : float
        Swing amplitude theta0 in rad (0: the small-angle period), below pi.

    Returns
    -------
    float
        s.

    Raises
    ------
    ParameterError
        For values that are not positive, or an amplitude of pi or more (the pendulum goes over the top).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(vm.models.pendulum_period(1.0), 4)
    2.0064
    >>> round(vm.models.pendulum_period(1.0, amplitude=np.pi / 2) / vm.models.pendulum_period(1.0), 5)
    1.18034
    """
    from scipy.special import ellipk
    t0 = 2 * np.pi * np.sqrt(positive(length, "length") / positive(g, "g"))
    a = positive(amplitude, "amplitude", allow_zero=True)
    if a >= np.pi:
        raise ParameterError(f"amplitude={amplitude!r} rad must be below pi: from pi the pendulum goes over the top "
                             "and does not swing")
    return float(t0 * 2 / np.pi * ellipk(np.sin(a / 2) ** 2))


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


def chain(masses, stiffnesses, *, dampers=None, modal_zeta=None):
    """An N-mass chain on the ground (a shear building, a train of masses) assembled from its storey values.

    Storey i joins mass i to mass i - 1, storey 0 joins mass 0 to the ground. A storey's stiffness adds k
    to both masses' diagonal and -k between them (a chain free of the ground has a rigid-body mode, which
    ``MDOF``'s positive definite K excludes).

    Parameters
    ----------
    masses : array_like
        N masses in kg, from the ground up.
    stiffnesses : array_like
        N storey stiffnesses in N/m (a guided column's is ``stiffness("guided", ...)``).
    dampers : array_like, optional
        Storey dampers in N s/m, assembled like the stiffnesses.
    modal_zeta : array_like or float, optional
        Modal damping instead of dampers.

    Returns
    -------
    MDOF

    Raises
    ------
    ParameterError
        For counts that do not match, or values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> three = vm.models.chain([1.0, 1.0, 1.0], [1e4, 1e4, 1e4])          # fixed-free chain of 3
    >>> fn, _ = three.undamped_modes()
    >>> round(float(fn[0]), 4)     # 2 sqrt(k/m) sin(pi / 14) / (2 pi)
    7.0831
    """
    from .mdof import MDOF
    m = np.array([positive(v, "masses") for v in np.atleast_1d(np.asarray(masses, dtype=object)).ravel()])
    n = need = m.size
    if n < 1:
        raise ParameterError("masses must hold at least one mass")

    def assemble(values, name):
        v = np.atleast_1d(np.asarray(values, dtype=object)).ravel()
        if v.size != need:
            raise ParameterError(f"{name} must hold {need} storey values for {n} masses, got {v.size}")
        v = np.array([positive(x, name, allow_zero=name == "dampers") for x in v])
        A = np.zeros((n, n))
        for s_, k in enumerate(v):
            i = s_                                  # the storey's upper mass
            A[i, i] += k
            if i > 0:
                A[i - 1, i - 1] += k
                A[i, i - 1] -= k
                A[i - 1, i] -= k
        return A

    K = assemble(stiffnesses, "stiffnesses")
    C = None if dampers is None else assemble(dampers, "dampers")
    return MDOF(np.diag(m), K, C, modal_zeta=modal_zeta)


def tip_mass_beam(*, E: float, I: float, rho: float, A: float, L: float, tip_mass: float) -> dict:
    """A cantilever with a mass at its tip as one mass on a spring (Rayleigh), and the error against the
    exact first frequency.

    Rayleigh's static-deflection shape puts 33/140 of the beam's mass at the tip: m = M + 33/140 rho A L on
    k = 3 E I / L^3. The exact first root lambda = beta L solves
    1 + cos(lambda) cosh(lambda) + mu lambda (cos(lambda) sinh(lambda) - sin(lambda) cosh(lambda)) = 0
    with mu = M / (rho A L).

    Parameters
    ----------
    E, I, rho, A, L : float
        Young's modulus (Pa), second moment of area (m^4), density (kg/m^3), section (m^2), length (m).
    tip_mass : float
        The mass at the tip in kg (0: the bare cantilever).

    Returns
    -------
    dict
        "k" (N/m), "m_equivalent" (kg), "fn_rayleigh" and "fn_exact" (Hz), "error_pct" (Rayleigh over exact,
        %: Rayleigh's estimate is an upper bound).

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> r = vm.models.tip_mass_beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0, tip_mass=0.0)
    >>> round(r["error_pct"], 2)           # the bare cantilever: Rayleigh is 1.47 % high
    1.47
    """
    from scipy.optimize import brentq
    EI = positive(E, "E") * positive(I, "I")
    mb = positive(rho, "rho") * positive(A, "A") * positive(L, "L")
    M = positive(tip_mass, "tip_mass", allow_zero=True)
    mu = M / mb

    def char(x):   # divided by cosh(x): finite for every root
        return 1 / np.cosh(x) + np.cos(x) + mu * x * (np.cos(x) * np.tanh(x) - np.sin(x))

    lam = brentq(char, 1e-6, 1.8752, xtol=1e-14)
    k = 3 * EI / L ** 3
    m_eq = M + 33 / 140 * mb
    fn_r = float(np.sqrt(k / m_eq) / (2 * np.pi))
    fn_x = float(lam ** 2 / (2 * np.pi * L ** 2) * np.sqrt(EI * L / mb))
    return {"k": float(k), "m_equivalent": float(m_eq), "fn_rayleigh": fn_r, "fn_exact": fn_x,
            "error_pct": 100 * (fn_r / fn_x - 1)}
