"""Models described in TOML files, every parameter with its unit.

    type = "sdof"                       # sdof | mdof | beam | rod | shaft | string
    [parameters]
    m = "200 kg"
    k = "40 N/mm"
    zeta = 0.22                         # dimensionless parameters are plain numbers

    type = "mdof"
    [parameters]
    M = { value = [[2, 0], [0, 1]], unit = "kg" }
    K = { value = [[3000, -1000], [-1000, 1000]], unit = "N/m" }
    modal_zeta = [0.02, 0.02]
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError

# unit -> (dimension, factor to SI)
_U = {
    "kg": ("mass", 1.0), "g": ("mass", 1e-3), "t": ("mass", 1e3), "lb": ("mass", 0.45359237),
    "N/m": ("stiffness", 1.0), "N/mm": ("stiffness", 1e3), "kN/m": ("stiffness", 1e3), "kN/mm": ("stiffness", 1e6),
    "lbf/in": ("stiffness", 175.126835),
    "N s/m": ("damping", 1.0), "Ns/m": ("damping", 1.0), "N*s/m": ("damping", 1.0), "kN s/m": ("damping", 1e3),
    "m": ("length", 1.0), "mm": ("length", 1e-3), "cm": ("length", 1e-2), "in": ("length", 0.0254),
    "Pa": ("pressure", 1.0), "kPa": ("pressure", 1e3), "MPa": ("pressure", 1e6), "GPa": ("pressure", 1e9),
    "kg/m^3": ("density", 1.0), "kg/m3": ("density", 1.0), "g/cm^3": ("density", 1e3),
    "m^2": ("area", 1.0), "mm^2": ("area", 1e-6), "m^4": ("second_moment", 1.0), "mm^4": ("second_moment", 1e-12),
    "N": ("force", 1.0), "kg/m": ("linear_density", 1.0), "g/m": ("linear_density", 1e-3),
    "kg m^2": ("inertia", 1.0), "kg*m^2": ("inertia", 1.0), "N m/rad": ("torsional_stiffness", 1.0),
    "N m s/rad": ("torsional_damping", 1.0),
}
_NEEDS = {  # parameter -> dimensions it may have
    "m": ("mass", "inertia"), "k": ("stiffness", "torsional_stiffness"), "c": ("damping", "torsional_damping"),
    "M": ("mass", "inertia"), "K": ("stiffness", "torsional_stiffness"), "C": ("damping", "torsional_damping"),
    "E": ("pressure",), "G": ("pressure",), "rho": ("density",), "A": ("area",), "I": ("second_moment",),
    "L": ("length",), "T": ("force",), "mu": ("linear_density",),
}
_PLAIN = {"zeta", "loss_factor", "modal_zeta", "rayleigh", "bc", "n_modes"}
_TYPES = {"sdof", "mdof", "beam", "rod", "shaft", "string"}


def _quantity(name, v, src):
    if name in _PLAIN:
        return v
    if name not in _NEEDS:
        raise ParameterError(f"{src}: parameter {name!r} is not known; known: {sorted(set(_NEEDS) | _PLAIN)}")
    if isinstance(v, dict):
        if "value" not in v or "unit" not in v:
            raise ParameterError(f"{src}: parameter {name!r} needs value and unit")
        value, unit = v["value"], str(v["unit"]).strip()
    elif isinstance(v, str):
        m = re.match(r"^\s*([-+0-9.eE]+)\s*(.+?)\s*$", v)
        if not m:
            raise ParameterError(f"{src}: parameter {name} = {v!r} must be 'number unit', e.g. '40 N/mm'")
        value, unit = float(m.group(1)), m.group(2)
    else:
        raise ParameterError(f"{src}: parameter {name} = {v!r} has no unit; write e.g. {name} = \"{v} "
                             f"{ {'mass': 'kg', 'stiffness': 'N/m'}.get(_NEEDS[name][0], 'SI-unit') }\"")
    if unit not in _U:
        raise ParameterError(f"{src}: unit {unit!r} of {name!r} is not known")
    dim, f = _U[unit]
    if dim not in _NEEDS[name]:
        raise ParameterError(f"{src}: {name!r} must be a {' or '.join(_NEEDS[name])}, not {dim} ({unit!r})")
    return np.asarray(value, float) * f


def load(path) -> object:
    """A model from a TOML file (see the module docstring for the format)."""
    import tomllib
    from .continua import Beam, Rod, Shaft, String
    from .mdof import MDOF
    from .sdof import SDOF
    p = Path(path)
    src = f"model file {str(path)!r}"
    if not p.exists():
        raise ParameterError(f"path={str(path)!r} does not exist")
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ParameterError(f"{src} is not valid TOML: {exc}") from None
    kind = doc.get("type")
    if kind not in _TYPES:
        raise ParameterError(f"{src}: type={kind!r} must be one of {sorted(_TYPES)}")
    raw = doc.get("parameters", {})
    if not isinstance(raw, dict) or not raw:
        raise ParameterError(f"{src}: a [parameters] table is required")
    par = {k: _quantity(k, v, src) for k, v in raw.items()}
    try:
        if kind == "sdof":
            return SDOF(**{k: float(v) for k, v in par.items()})
        if kind == "mdof":
            return MDOF(**par)
        if kind == "beam":
            return Beam(**{k: (v if k == "bc" else float(v)) for k, v in par.items()})
        if kind == "rod":
            return Rod(**{k: (v if k == "bc" else float(v)) for k, v in par.items()})
        if kind == "shaft":
            return Shaft(**{k: (v if k == "bc" else float(v)) for k, v in par.items()})
        return String(**{k: float(v) for k, v in par.items()})
    except TypeError as exc:
        raise ParameterError(f"{src}: parameters do not fit a {kind} model: {exc}") from None
