"""ModalEstimate: natural frequencies and damping ratios with their uncertainty."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from ..errors import ParameterError
from ._common import _arr, _num, jsonable


@dataclass(frozen=True)
class ModalEstimate:
    """Natural frequencies and damping ratios of one or more modes, with their uncertainty.

    Parameters
    ----------
    fn : array_like
        Undamped natural frequencies in Hz.
    zeta : array_like
        Viscous damping ratios (a ratio, not %).
    fn_std, zeta_std : array_like, optional
        Standard deviations (NaN only where a method gives none).
    method : str
        The method that made it.
    flags : tuple of str
        Quality findings for the whole estimate (``FLAG_TEXT`` says what each means).
    mode_flags : tuple of tuple of str, optional
        Findings per mode.
    amplitude, phase : array_like, optional
        Per mode (ring-downs).
    shapes : array_like, optional
        Mode shapes (n_outputs, n_modes).
    unit : str
        The amplitude's unit.
    extras : mapping
        Method-specific detail (noise level, backbone, stabilisation table, rejected modes, ...).

    Raises
    ------
    ParameterError
        For arrays of different lengths.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> est = vm.ModalEstimate(fn=[10.0], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001])
    >>> est.n_modes, est.mode(0)["fn_hz"]
    (1, 10.0)
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
        """One mode as a dict with the documented JSON keys.

        Parameters
        ----------
        i : int
            The mode.

        Returns
        -------
        dict
            fn_hz, fn_std_hz, zeta, zeta_std, amplitude, phase, flags, ...

        Raises
        ------
        ParameterError
            For a mode out of range.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.ModalEstimate(fn=[10.0], zeta=[0.02]).mode(0)["zeta"]
        0.02
        """
        return {
            "fn_hz": _num(self.fn[i]), "zeta": _num(self.zeta[i]),
            "fn_std_hz": _num(self.fn_std[i]), "zeta_std": _num(self.zeta_std[i]),
            "amplitude": _num(self.amplitude[i]), "method": self.method,
            "flags": list(self.mode_flags[i]),
        }

    def to_dict(self) -> dict:
        """JSON-ready dict: ``modes`` (per-mode dicts), ``method``, ``flags``, ``unit``, ``extras``.

        Returns
        -------
        dict

        Raises
        ------
        ParameterError
            Never for a valid estimate.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> sorted(vm.ModalEstimate(fn=[10.0], zeta=[0.02]).to_dict())[:3]
        ['extras', 'flags', 'method']
        """
        return {"method": self.method, "flags": list(self.flags), "unit": self.unit,
                "modes": [self.mode(i) for i in range(self.n_modes)],
                "extras": jsonable(dict(self.extras))}

    def to_frame(self):
        """A pandas table, one row per mode.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for a valid estimate.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.ModalEstimate(fn=[10.0, 20.0], zeta=[0.02, 0.01]).to_frame()["fn_hz"].tolist()
        [10.0, 20.0]
        """
        import pandas as pd
        return pd.DataFrame({"fn_hz": self.fn, "fn_std_hz": self.fn_std, "zeta": self.zeta,
                             "zeta_std": self.zeta_std, "amplitude": self.amplitude,
                             "flags": [",".join(f) for f in self.mode_flags]})

    def __repr__(self) -> str:
        from ..rounding import with_std
        rows = "; ".join("fn={}±{} Hz zeta={}±{}".format(*with_std(f, fs), *with_std(z, zs))
                         for f, fs, z, zs in zip(self.fn, self.fn_std, self.zeta, self.zeta_std))
        fl = f" flags={list(self.flags)}" if self.flags else ""
        return f"ModalEstimate({self.method}: {rows}{fl})"
