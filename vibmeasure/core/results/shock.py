"""Shock response spectra and measured transmissibility."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np


@dataclass(frozen=True)
class ShockSpectrum:
    """Peak responses per natural frequency: ``fn`` (Hz), ``values`` (one row per kind: maximax,
    primary, residual: positive and negative peaks' largest magnitude), ``output`` and its ``unit``,
    ``zeta``, the input channel and its peak, and per-kind positive/negative peaks in extras."""

    fn: np.ndarray
    values: Mapping[str, np.ndarray]
    output: str
    unit: str
    zeta: float
    channel: str
    input_peak: float
    duration: float
    extras: Mapping[str, Any] = field(default_factory=dict)

    def __getitem__(self, kind: str) -> np.ndarray:
        return self.values[kind]

    def to_frame(self):
        import pandas as pd
        d = {"fn_hz": self.fn}
        d.update({f"{k}_{self.output}": v for k, v in self.values.items()})
        return pd.DataFrame(d)


@dataclass(frozen=True)
class Transmissibility:
    """Measured transmissibility T(f) = top / base (H1), with coherence; where a model was given, its
    transmissibility and the ratio measured/model. ``isolation_hz``: the frequency above which the
    measured |T| stays below 1 (isolation starts), NaN when it never does in the record's range."""

    freq: np.ndarray
    t: np.ndarray
    coherence: np.ndarray
    base: str
    top: str
    model: np.ndarray | None = None
    extras: Mapping[str, Any] = field(default_factory=dict)

    @property
    def magnitude(self) -> np.ndarray:
        return np.abs(self.t)

    @property
    def isolation_hz(self) -> float:
        return float(self.extras.get("isolation_hz", np.nan))

    def to_frame(self):
        import pandas as pd
        d = {"freq_hz": self.freq, "magnitude": self.magnitude, "phase_deg": np.degrees(np.angle(self.t)),
             "coherence": self.coherence}
        if self.model is not None:
            d["model_magnitude"] = self.model
            d["ratio_to_model"] = self.magnitude / self.model
        return pd.DataFrame(d)
