"""Physical quantities and explicit unit conversion.

Each quantity has an SI base unit; every other unit of it is a factor times that base.
Conversions are explicit (:func:`convert`); a unit that does not belong to the quantity
raises :class:`UnitError`.
"""

from __future__ import annotations

import numpy as np

from .errors import ParameterError, UnitError

__all__ = ["QUANTITIES", "SI_UNIT", "STANDARD_GRAVITY", "convert", "factor", "quantity_of", "check_unit",
           "normalize_unit", "derivative_quantity", "integral_quantity"]

STANDARD_GRAVITY = 9.80665  # m/s^2, CGPM 1901 (exact by definition)

# unit -> (quantity, factor to the SI unit of that quantity)
_UNITS: dict[str, tuple[str, float]] = {
    # displacement
    "m": ("displacement", 1.0), "mm": ("displacement", 1e-3), "um": ("displacement", 1e-6),
    "in": ("displacement", 0.0254), "mil": ("displacement", 0.0254e-3),
    # velocity
    "m/s": ("velocity", 1.0), "mm/s": ("velocity", 1e-3), "um/s": ("velocity", 1e-6),
    "in/s": ("velocity", 0.0254),
    # acceleration
    "m/s^2": ("acceleration", 1.0), "mm/s^2": ("acceleration", 1e-3), "g": ("acceleration", STANDARD_GRAVITY),
    "in/s^2": ("acceleration", 0.0254),
    # force
    "N": ("force", 1.0), "kN": ("force", 1e3), "lbf": ("force", 4.4482216152605),
    # electrical signal before calibration
    "V": ("voltage", 1.0), "mV": ("voltage", 1e-3),
    # signals with no physical unit (counts, full scale)
    "": ("unknown", 1.0),
}

_ALIASES = {
    "m/s2": "m/s^2", "m/s**2": "m/s^2", "m s^-2": "m/s^2", "ms^-2": "m/s^2", "mm/s2": "mm/s^2",
    "in/s2": "in/s^2", "µm": "um", "μm": "um", "micron": "um", "µm/s": "um/s", "μm/s": "um/s",
    "ips": "in/s", "G": "g", "gn": "g", "newton": "N", "n": "N", "meter": "m", "metre": "m",
    "inch": "in", "mils": "mil",
}

QUANTITIES = ("displacement", "velocity", "acceleration", "force", "voltage", "unknown")
SI_UNIT = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2", "force": "N",
           "voltage": "V", "unknown": ""}

_DERIVATIVE = {"displacement": "velocity", "velocity": "acceleration"}
_INTEGRAL = {v: k for k, v in _DERIVATIVE.items()}


def normalize_unit(unit: str | None) -> str:
    """Return the canonical spelling of ``unit`` (``"m/s2"`` -> ``"m/s^2"``); unknown units raise."""
    if unit is None:
        return ""
    u = str(unit).strip()
    u = _ALIASES.get(u, u)
    if u not in _UNITS:
        raise UnitError(f"unit={unit!r} is not known; known units: {sorted(k for k in _UNITS if k)}")
    return u


def quantity_of(unit: str) -> str:
    """The quantity a unit measures (``"g"`` -> ``"acceleration"``)."""
    return _UNITS[normalize_unit(unit)][0]


def factor(unit: str) -> float:
    """The factor that turns a value in ``unit`` into the SI unit of its quantity."""
    return _UNITS[normalize_unit(unit)][1]


def check_unit(quantity: str, unit: str) -> str:
    """Check that ``unit`` measures ``quantity``; return the canonical unit.

    A quantity of ``"unknown"`` accepts any known unit; an empty unit is accepted for any quantity
    (the data are then uncalibrated).
    """
    if quantity not in QUANTITIES:
        raise ParameterError(f"quantity={quantity!r} is not one of {QUANTITIES}")
    u = normalize_unit(unit)
    if u == "" or quantity == "unknown":
        return u
    q = _UNITS[u][0]
    if q != quantity:
        raise UnitError(f"unit={unit!r} measures {q}, not quantity={quantity!r}")
    return u


def convert(values, from_unit: str, to_unit: str):
    """Convert ``values`` from one unit to another of the same quantity (``"g"`` -> ``"m/s^2"``)."""
    fu, tu = normalize_unit(from_unit), normalize_unit(to_unit)
    fq, tq = _UNITS[fu][0], _UNITS[tu][0]
    if fq != tq:
        raise UnitError(f"cannot convert {from_unit!r} ({fq}) to {to_unit!r} ({tq}): different quantities")
    f = _UNITS[fu][1] / _UNITS[tu][1]
    return np.asarray(values) * f if f != 1.0 else np.asarray(values)


def derivative_quantity(quantity: str) -> str:
    if quantity not in _DERIVATIVE:
        raise ParameterError(f"quantity={quantity!r} has no time derivative among {tuple(_DERIVATIVE.values())}")
    return _DERIVATIVE[quantity]


def integral_quantity(quantity: str) -> str:
    if quantity not in _INTEGRAL:
        raise ParameterError(f"quantity={quantity!r} cannot be integrated: the rule is velocity -> displacement,"
                             " acceleration -> velocity")
    return _INTEGRAL[quantity]
