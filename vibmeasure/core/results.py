"""Result objects: data and derived properties, no algorithms."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from .errors import ParameterError

__all__ = ["ModalEstimate", "FLAG_TEXT"]

# Every quality flag a result may carry, with the sentence a report prints for it.
FLAG_TEXT = {
    "few_cycles": "fewer than 5 cycles of decay above the noise: damping is poorly determined",
    "noise_floor": "the decay reached the noise floor before the record ended; the fit stops there",
    "resolution_limited": "sampling or frequency resolution too coarse for a sound estimate",
    "clipped": "clipped samples (3 or more in a row at the extreme) were excluded",
    "close_modes": "another mode lies within a few half-power bandwidths: estimates interact",
    "overdamped": "no oscillation: the system is critically or over damped (zeta >= 1); no frequency",
    "coulomb_friction": "the envelope decays linearly, as with dry (Coulomb) friction: viscous zeta does "
                        "not describe it; see friction decay per cycle",
    "amplitude_dependent": "damping changes with amplitude (nonlinear damping); zeta is an average",
    "colored_noise": "the noise near this mode is stronger than the broadband level: std scaled up",
    "low_snr": "the mode is weak compared with the noise",
    "start_detected": "the decay starts after the beginning of the record (trigger/impact found)",
}


def _arr(x, n, name, fill=np.nan):
    if x is None:
        return np.full(n, fill)
    a = np.atleast_1d(np.asarray(x, dtype=float))
    if a.shape != (n,):
        raise ParameterError(f"{name} must have one value per mode ({n}), got shape {a.shape}")
    return a


@dataclass(frozen=True)
class ModalEstimate:
    """Natural frequencies and damping ratios of one or more modes, with uncertainty.

    ``fn`` is the undamped natural frequency in Hz, ``zeta`` the viscous damping ratio (a ratio,
    not %), ``fn_std``/``zeta_std`` their standard deviations (NaN only when a method gives none).
    ``flags`` are quality findings for the whole estimate, ``mode_flags`` per mode. ``extras``
    holds method-specific detail (noise level, samples used, friction, damping vs amplitude...).
    """

    fn: np.ndarray
    zeta: np.ndarray
    fn_std: np.ndarray | None = None
    zeta_std: np.ndarray | None = None
    method: str = ""
    flags: tuple[str, ...] = ()
    mode_flags: tuple[tuple[str, ...], ...] | None = None
    amplitude: np.ndarray | None = None
    phase: np.ndarray | None = None
    shapes: np.ndarray | None = None
    unit: str = ""
    extras: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        fn = np.atleast_1d(np.asarray(self.fn, dtype=float))
        if fn.ndim != 1:
            raise ParameterError(f"fn must be 1-D (one value per mode), got shape {fn.shape}")
        n = fn.size
        object.__setattr__(self, "fn", fn)
        object.__setattr__(self, "zeta", _arr(self.zeta, n, "zeta"))
        object.__setattr__(self, "fn_std", _arr(self.fn_std, n, "fn_std"))
        object.__setattr__(self, "zeta_std", _arr(self.zeta_std, n, "zeta_std"))
        object.__setattr__(self, "amplitude", _arr(self.amplitude, n, "amplitude"))
        object.__setattr__(self, "phase", _arr(self.phase, n, "phase"))
        mf = self.mode_flags if self.mode_flags is not None else ((),) * n
        if len(mf) != n:
            raise ParameterError(f"mode_flags must have one entry per mode ({n}), got {len(mf)}")
        object.__setattr__(self, "mode_flags", tuple(tuple(f) for f in mf))
        allflags = list(dict.fromkeys(list(self.flags) + [f for m in self.mode_flags for f in m]))
        object.__setattr__(self, "flags", tuple(allflags))
        object.__setattr__(self, "extras", MappingProxyType(dict(self.extras)))
        for a in (self.fn, self.zeta, self.fn_std, self.zeta_std, self.amplitude, self.phase):
            a.setflags(write=False)

    @property
    def n_modes(self) -> int:
        return self.fn.size

    def __len__(self) -> int:
        return self.n_modes

    @property
    def wn(self) -> np.ndarray:
        """Undamped natural angular frequency, rad/s."""
        return 2 * np.pi * self.fn

    @property
    def fd(self) -> np.ndarray:
        """Damped natural frequency fn*sqrt(1 - zeta^2), Hz (NaN where zeta >= 1)."""
        with np.errstate(invalid="ignore"):
            return self.fn * np.sqrt(1 - self.zeta ** 2)

    @property
    def log_decrement(self) -> np.ndarray:
        """Logarithmic decrement per cycle, 2 pi zeta / sqrt(1 - zeta^2)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return 2 * np.pi * self.zeta / np.sqrt(1 - self.zeta ** 2)

    def mode(self, i: int) -> dict:
        """One mode as a dict with the documented JSON keys."""
        return {
            "fn_hz": _num(self.fn[i]), "zeta": _num(self.zeta[i]),
            "fn_std_hz": _num(self.fn_std[i]), "zeta_std": _num(self.zeta_std[i]),
            "amplitude": _num(self.amplitude[i]), "method": self.method,
            "flags": list(self.mode_flags[i]),
        }

    def to_dict(self) -> dict:
        """JSON-ready dict: ``modes`` (list of per-mode dicts), ``method``, ``flags``, ``unit``, ``extras``."""
        return {"method": self.method, "flags": list(self.flags), "unit": self.unit,
                "modes": [self.mode(i) for i in range(self.n_modes)],
                "extras": _jsonable(dict(self.extras))}

    def to_frame(self):
        """A pandas table, one row per mode."""
        import pandas as pd
        return pd.DataFrame({"fn_hz": self.fn, "fn_std_hz": self.fn_std, "zeta": self.zeta,
                             "zeta_std": self.zeta_std, "amplitude": self.amplitude,
                             "flags": [",".join(f) for f in self.mode_flags]})

    def __repr__(self) -> str:
        rows = "; ".join(f"fn={f:.6g}±{fs:.2g} Hz zeta={z:.5g}±{zs:.2g}"
                         for f, fs, z, zs in zip(self.fn, self.fn_std, self.zeta, self.zeta_std))
        fl = f" flags={list(self.flags)}" if self.flags else ""
        return f"ModalEstimate({self.method}: {rows}{fl})"


def _num(x):
    x = float(x)
    return None if not np.isfinite(x) else x


def _jsonable(obj):
    if isinstance(obj, Mapping):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [_jsonable(v) for v in obj.tolist()]
    if isinstance(obj, (float, np.floating)):
        return _num(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    return obj
