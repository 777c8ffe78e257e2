"""Models described in TOML files, every parameter with its unit (the format: core/model_format.py,
which `vibmeasure model --help` prints)."""

from __future__ import annotations

import re

import numpy as np

from ..core._validate import regular_input
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
    "L": ("length",), "T": ("force",), "mu": ("linear_density",), "J": ("second_moment",),
}
_PLAIN = {"zeta", "loss_factor", "modal_zeta", "rayleigh", "bc", "n_modes", "nu", "kappa"}
_TYPES = {"sdof", "mdof", "beam", "rayleigh_beam", "timoshenko_beam", "rod", "shaft", "string"}


def _quantity(name, v, src):
    if name in _PLAIN:
        if name == "bc":
            return v
        if isinstance(v, bool):
            raise ParameterError(f"{src}: parameter {name} = {str(v).lower()} must be a number, not a truth value")
        try:
            ok = np.all(np.isfinite(np.asarray(v, float)))
        except (TypeError, ValueError, OverflowError):
            ok = False
        if not ok:
            raise ParameterError(f"{src}: parameter {name} = {str(v)[:40]!r} must be a finite number (or list of them)")
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
        try:
            value, unit = float(m.group(1)), m.group(2)
        except ValueError:
            raise ParameterError(f"{src}: parameter {name} = {v!r}: {m.group(1)!r} is not a number") from None
    else:
        raise ParameterError(f"{src}: parameter {name} = {v!r} has no unit; write e.g. {name} = \"{v} "
                             f"{ {'mass': 'kg', 'stiffness': 'N/m'}.get(_NEEDS[name][0], 'SI-unit') }\"")
    if unit not in _U:
        raise ParameterError(f"{src}: unit {unit!r} of {name!r} is not known")
    dim, f = _U[unit]
    if dim not in _NEEDS[name]:
        raise ParameterError(f"{src}: {name!r} must be a {' or '.join(_NEEDS[name])}, not {dim} ({unit!r})")
    try:
        arr = np.asarray(value, float)
    except (TypeError, ValueError):
        raise ParameterError(f"{src}: parameter {name!r}: its value must be a number or a matrix of numbers") from None
    if arr.size > MAX_MATRIX or arr.ndim > 2 or not np.all(np.isfinite(arr)):
        raise ParameterError(f"{src}: parameter {name!r} has shape {arr.shape}: at most a {MAX_DOF} x {MAX_DOF} "
                             "matrix of finite numbers")
    return arr * f


MAX_DOF = 500                 # an MDOF model beyond this is an FE model: use a dedicated FE tool
MAX_MATRIX = MAX_DOF * MAX_DOF
MAX_BYTES = 4_000_000            # three 500 x 500 matrices of ~8-digit numbers fit; tomllib parses 4 MB in < 1 s


def _depth(v, limit: int, level: int = 0) -> int:
    """Nesting depth of lists and tables, stopping past the limit (no recursion blow-up)."""
    stack = [(v, level)]
    deepest = 0
    while stack:
        x, d = stack.pop()
        deepest = max(deepest, d)
        if deepest > limit:
            return deepest
        if isinstance(x, dict):
            stack.extend((y, d + 1) for y in x.values())
        elif isinstance(x, list):
            stack.extend((y, d + 1) for y in x)
    return deepest


def load(path) -> object:
    """A model from a TOML file: every parameter with its unit (``vibmeasure model --help`` prints the format).

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file.

    Returns
    -------
    SDOF, MDOF, Beam, RayleighBeam, TimoshenkoBeam, Rod, Shaft or String

    Raises
    ------
    ParameterError
        For a missing file, invalid TOML, an unknown type, or a parameter without its unit.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "beam.toml"
    >>> _ = p.write_text(chr(10).join(['type = "sdof"', '[parameters]', 'm = "1.2 kg"', 'k = "26.6 kN/m"',
    ...                                'zeta = 0.012', '']))
    >>> round(vm.models.load(p).fn, 1)
    23.7
    """
    import tomllib
    from .beams import RayleighBeam, TimoshenkoBeam
    from .continua import Beam, Rod, Shaft, String
    from .mdof import MDOF
    from .sdof import SDOF
    src = f"model file {str(path)!r}"
    p = regular_input(path, "path")
    if p.stat().st_size > MAX_BYTES:
        raise ParameterError(f"{src} is {p.stat().st_size:,} bytes: larger than any model this loader takes "
                             f"(at most {MAX_DOF} degrees of freedom)")
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, RecursionError, ValueError) as exc:
        raise ParameterError(f"{src} is not valid TOML: {str(exc)[:200] or type(exc).__name__}") from None
    if _depth(doc, 6) > 6:
        raise ParameterError(f"{src}: values are nested deeper than a model needs (tables and matrices, 6 levels)")
    kind = doc.get("type")
    if kind not in _TYPES:
        raise ParameterError(f"{src}: type={kind!r} must be one of {sorted(_TYPES)}")
    raw = doc.get("parameters", {})
    if not isinstance(raw, dict) or not raw:
        raise ParameterError(f"{src}: a [parameters] table is required")
    par = {k: _quantity(k, v, src) for k, v in raw.items()}
    if kind not in ("mdof",) and not {"zeta", "c", "loss_factor"} & set(par) or \
            kind == "mdof" and not {"C", "rayleigh", "modal_zeta"} & set(par):
        import warnings
        from ..core.errors import QualityWarning
        warnings.warn(f"{src} gives no damping (zeta, c, loss_factor; or C, rayleigh, modal_zeta for mdof): the model "
                      "is undamped (zeta = 0)", QualityWarning, stacklevel=2)
    try:
        if kind == "sdof":
            return SDOF(**{k: float(v) for k, v in par.items()})
        if kind == "mdof":
            return MDOF(**par)
        beams = {"beam": Beam, "rayleigh_beam": RayleighBeam, "timoshenko_beam": TimoshenkoBeam}
        if kind in beams:
            return beams[kind](**{k: (v if k == "bc" else float(v)) for k, v in par.items()})
        if kind == "rod":
            return Rod(**{k: (v if k == "bc" else float(v)) for k, v in par.items()})
        if kind == "shaft":
            return Shaft(**{k: (v if k == "bc" else float(v)) for k, v in par.items()})
        return String(**{k: float(v) for k, v in par.items()})
    except (TypeError, ValueError, OverflowError) as exc:
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError(f"{src}: parameters do not fit a {kind} model: {str(exc)[:200]}") from None
