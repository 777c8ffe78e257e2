"""The textbook read backwards: damping, stiffness and motion from what a measurement reads off.

Each function inverts one closed form of the single-degree-of-freedom model exactly (not its light-damping
approximation) and refuses a reading the model cannot produce, naming the argument and the rule.
"""

from __future__ import annotations

import numpy as np

from ..core._validate import finite_number, positive
from ..core.errors import ParameterError
from ..identify.damping import zeta_from_delta

__all__ = ["zeta_from_magnification", "zeta_from_peak_frequency", "isolator_stiffness", "decrement_from_amplitudes",
           "q_factor", "amplitude_phase", "static_deflection", "fn_from_deflection",
           "harmonic_motion", "harmonic_frequency"]

G0 = 9.80665   # standard gravity, m/s^2


def zeta_from_magnification(peak: float) -> float:
    """Damping ratio from a measured peak dynamic magnification |X k / F0|max = 1 / (2 zeta sqrt(1 - zeta^2)).

    Parameters
    ----------
    peak : float
        The resonant peak of the displacement response divided by the static response (>= 1).

    Returns
    -------
    float
        zeta (the lighter of the two roots; the other is above 1/sqrt(2), where there is no peak).

    Raises
    ------
    ParameterError
        For a peak below 1: a response that never exceeds the static one has zeta >= 1/sqrt(2).

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.models.zeta_from_magnification(10.0), 5)      # a peak of 10 reads zeta just above 0.05
    0.05006
    """
    q = positive(peak, "peak")
    if q < 1:
        raise ParameterError(f"peak={peak!r} must be >= 1: a displacement response that never exceeds the static "
                             "one has no resonant peak (zeta >= 1/sqrt(2))")
    # 4 u (1 - u) = 1 / peak^2 with u = zeta^2; the smaller root is the damping that makes a peak
    u = (1 - np.sqrt(max(1 - 1 / q ** 2, 0.0))) / 2
    return float(np.sqrt(u))


def zeta_from_peak_frequency(f_peak: float, fn: float, *, form: str = "receptance") -> float:
    """Damping ratio from where a resonant peak stands against the undamped natural frequency.

    The displacement (receptance) peak stands at r = sqrt(1 - 2 zeta^2), the acceleration (accelerance)
    peak at r = 1 / sqrt(1 - 2 zeta^2); a velocity (mobility) peak stands at fn whatever the damping.
    The shift is of order zeta^2, so light damping needs fn and f_peak to many digits.

    Parameters
    ----------
    f_peak : float
        Frequency of the peak in Hz.
    fn : float
        Undamped natural frequency in Hz (from the stiffness and mass, or a model).
    form : {"receptance", "accelerance"}
        Which response peaks.

    Returns
    -------
    float
        zeta.

    Raises
    ------
    ParameterError
        For a mobility peak, or a peak on the wrong side of fn for its form.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.models.zeta_from_peak_frequency(9.0, 10.0), 4)        # peak 10 % below fn
    0.3082
    """
    r = positive(f_peak, "f_peak") / positive(fn, "fn")
    if form == "mobility":
        raise ParameterError("form='mobility': a velocity response peaks at fn whatever the damping, so its "
                             "frequency says nothing about zeta; use the half-power bandwidth")
    if form == "receptance":
        if r > 1:
            raise ParameterError(f"f_peak={f_peak!r} is above fn={fn!r}: a displacement peak stands at or below fn")
        return float(np.sqrt((1 - r ** 2) / 2))
    if form == "accelerance":
        if r < 1:
            raise ParameterError(f"f_peak={f_peak!r} is below fn={fn!r}: an acceleration peak stands at or above fn")
        return float(np.sqrt((1 - 1 / r ** 2) / 2))
    raise ParameterError(f"form={form!r} must be 'receptance' or 'accelerance'")


def isolator_stiffness(m: float, f_force: float, transmissibility: float, *, zeta: float = 0.0) -> float:
    """Mount stiffness that transmits ``transmissibility`` of a harmonic force at ``f_force`` to the ground.

    Solves sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2) = T for the frequency ratio r above
    sqrt(2) (the isolation region), then k = m (2 pi f_force / r)^2.

    Parameters
    ----------
    m : float
        Isolated mass in kg.
    f_force : float
        Forcing frequency in Hz.
    transmissibility : float
        Target force (or motion) transmissibility, between 0 and 1.
    zeta : float
        The mount's damping ratio.

    Returns
    -------
    float
        k in N/m.

    Raises
    ------
    ParameterError
        For a target not below 1 (a mount only isolates above sqrt(2) fn) or values out of range.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.models.isolator_stiffness(100.0, 25.0, 0.1))     # 10 % on an undamped mount: r^2 = 11
    224309
    """
    m, f = positive(m, "m"), positive(f_force, "f_force")
    T = positive(transmissibility, "transmissibility")
    z = positive(zeta, "zeta", allow_zero=True)
    if T >= 1:
        raise ParameterError(f"transmissibility={transmissibility!r} must be below 1: a mount transmits less than "
                             "it receives only above sqrt(2) times its natural frequency")
    # T^2 R^2 + (4 zeta^2 T^2 - 2 T^2 - 4 zeta^2) R + (T^2 - 1) = 0 with R = r^2: one positive root
    a, b, c = T ** 2, 4 * z ** 2 * T ** 2 - 2 * T ** 2 - 4 * z ** 2, T ** 2 - 1
    R = (-b + np.sqrt(b ** 2 - 4 * a * c)) / (2 * a)
    return float(m * (2 * np.pi * f) ** 2 / R)


def decrement_from_amplitudes(a0: float, an: float, cycles: float = 1) -> float:
    """Logarithmic decrement delta = ln(a0 / an) / n from two amplitudes read n cycles apart.

    Parameters
    ----------
    a0 : float
        The first peak amplitude (any unit).
    an : float
        The peak amplitude ``cycles`` later, in the same unit.
    cycles : float
        Whole cycles between the two peaks.

    Returns
    -------
    float
        delta.

    Raises
    ------
    ParameterError
        For amplitudes that are not positive or do not decrease.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> d = vm.models.decrement_from_amplitudes(1.0, 0.5, cycles=5)     # halved in five cycles
    >>> round(d, 5), round(float(vm.zeta_from_delta(d)), 5)
    (0.13863, 0.02206)
    """
    a0, an, n = positive(a0, "a0"), positive(an, "an"), positive(cycles, "cycles")
    if an >= a0:
        raise ParameterError(f"an={an!r} must be below a0={a0!r}: a free decay's amplitudes fall (one that grows "
                             "is driven, not decaying)")
    return float(np.log(a0 / an) / n)


def q_factor(*, zeta: float | None = None, loss_factor: float | None = None, log_decrement: float | None = None,
             fn: float | None = None, bandwidth: float | None = None) -> float:
    """Quality factor from any one damping estimate: Q = 1 / (2 zeta) = 1 / eta = fn / bandwidth.

    A decrement is first turned into zeta exactly, so Q = sqrt(4 pi^2 + delta^2) / (2 delta) (pi / delta
    when light).

    Parameters
    ----------
    zeta : float, optional
        Damping ratio.
    loss_factor : float, optional
        Loss factor eta (equivalent zeta = eta / 2 at resonance).
    log_decrement : float, optional
        Logarithmic decrement.
    fn, bandwidth : float, optional
        Resonance frequency and its half-power bandwidth, in the same unit (give both).

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        For none or more than one estimate, or a value that is not positive.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> vm.models.q_factor(fn=100.0, bandwidth=2.0)
    50.0
    """
    given = {k: v for k, v in (("zeta", zeta), ("loss_factor", loss_factor), ("log_decrement", log_decrement),
                               ("bandwidth", bandwidth)) if v is not None}
    if len(given) != 1:
        raise ParameterError(f"give exactly one of zeta, loss_factor, log_decrement or fn with bandwidth; got "
                             f"{sorted(given) or 'none'}")
    if "zeta" in given:
        return float(1 / (2 * positive(zeta, "zeta")))
    if "loss_factor" in given:
        return float(1 / positive(loss_factor, "loss_factor"))
    if "log_decrement" in given:
        return float(1 / (2 * zeta_from_delta(positive(log_decrement, "log_decrement"))))
    if fn is None:
        raise ParameterError("bandwidth needs fn: Q = fn / bandwidth")
    return float(positive(fn, "fn") / positive(bandwidth, "bandwidth"))


def amplitude_phase(x0: float, v0: float, fn: float, zeta: float = 0.0) -> tuple[float, float]:
    """Amplitude A and phase phi of a free vibration from its initial conditions:
    x(t) = A exp(-zeta wn t) cos(wd t - phi).

    Parameters
    ----------
    x0 : float
        Initial displacement.
    v0 : float
        Initial velocity (displacement unit per s).
    fn : float
        Undamped natural frequency in Hz.
    zeta : float
        Damping ratio, below 1.

    Returns
    -------
    tuple of float
        (A, phi in rad, in (-pi, pi]).

    Raises
    ------
    ParameterError
        For zeta >= 1 (no oscillation) or values out of range.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> A, phi = vm.models.amplitude_phase(0.0, 2 * np.pi, 1.0)    # released through zero at 1 unit/rad
    >>> round(A, 6), round(phi, 6)
    (1.0, 1.570796)
    """
    x0, v0 = finite_number(x0, "x0"), finite_number(v0, "v0")
    wn, z = 2 * np.pi * positive(fn, "fn"), positive(zeta, "zeta", allow_zero=True)
    if z >= 1:
        raise ParameterError(f"zeta={zeta!r} must be below 1: a critically or over-damped system does not oscillate")
    wd = wn * np.sqrt(1 - z ** 2)
    s = (v0 + z * wn * x0) / wd
    return float(np.hypot(x0, s)), float(np.arctan2(s, x0))


def static_deflection(fn: float, g: float = G0) -> float:
    """Static deflection under gravity of a spring-mass with natural frequency fn: delta = g / wn^2.

    Parameters
    ----------
    fn : float
        Natural frequency in Hz.
    g : float
        Gravity in m/s^2.

    Returns
    -------
    float
        m.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.models.static_deflection(5.0) * 1e3, 3)     # a 5 Hz mount sags 9.9 mm
    9.936
    """
    return float(positive(g, "g") / (2 * np.pi * positive(fn, "fn")) ** 2)


def fn_from_deflection(delta: float, g: float = G0) -> float:
    """Natural frequency from the static deflection a mass causes: wn = sqrt(g / delta).

    Parameters
    ----------
    delta : float
        Static deflection in m.
    g : float
        Gravity in m/s^2.

    Returns
    -------
    float
        fn in Hz.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.models.fn_from_deflection(0.01), 3)         # 10 mm of sag: about 5 Hz
    4.984
    """
    return float(np.sqrt(positive(g, "g") / positive(delta, "delta")) / (2 * np.pi))


def _one_motion(displacement, velocity, acceleration, need: int) -> dict:
    given = {k: positive(v, k) for k, v in (("displacement", displacement), ("velocity", velocity),
                                            ("acceleration", acceleration)) if v is not None}
    if len(given) != need:
        raise ParameterError(f"give exactly {need} of displacement, velocity and acceleration; got "
                             f"{sorted(given) or 'none'}")
    return given


def harmonic_motion(freq: float, *, displacement: float | None = None, velocity: float | None = None,
                    acceleration: float | None = None) -> dict:
    """Peak displacement, velocity and acceleration of x = X sin(2 pi f t) from any one of them:
    V = w X, A = w^2 X.

    Parameters
    ----------
    freq : float
        Frequency in Hz.
    displacement, velocity, acceleration : float, optional
        One peak value, in SI units (m, m/s, m/s^2).

    Returns
    -------
    dict
        "displacement" (m), "velocity" (m/s), "acceleration" (m/s^2): peaks (rms = peak / sqrt(2)).

    Raises
    ------
    ParameterError
        For none or several values, or one that is not positive.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> m = vm.models.harmonic_motion(50.0, acceleration=9.80665)     # 1 g at 50 Hz
    >>> round(m["displacement"] * 1e6, 1), round(m["velocity"] * 1e3, 2)
    (99.4, 31.22)
    """
    w = 2 * np.pi * positive(freq, "freq")
    (kind, v), = _one_motion(displacement, velocity, acceleration, 1).items()
    X = v / w ** {"displacement": 0, "velocity": 1, "acceleration": 2}[kind]
    return {"displacement": float(X), "velocity": float(w * X), "acceleration": float(w ** 2 * X)}


def harmonic_frequency(*, displacement: float | None = None, velocity: float | None = None,
                       acceleration: float | None = None) -> float:
    """Frequency of a harmonic motion from two of its peaks: w = V / X = A / V = sqrt(A / X).

    Parameters
    ----------
    displacement, velocity, acceleration : float, optional
        Two peak values in SI units (or any consistent pair: both peaks or both rms).

    Returns
    -------
    float
        Hz.

    Raises
    ------
    ParameterError
        For other than two values, or one that is not positive.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.models.harmonic_frequency(displacement=1e-3, acceleration=39.478), 3)   # 1 mm at 39.5 m/s^2
    31.623
    """
    g = _one_motion(displacement, velocity, acceleration, 2)
    if "velocity" not in g:
        w = np.sqrt(g["acceleration"] / g["displacement"])
    elif "displacement" in g:
        w = g["velocity"] / g["displacement"]
    else:
        w = g["acceleration"] / g["velocity"]
    return float(w / (2 * np.pi))
