"""Rolling-element bearing and gear fault frequencies (kinematics), and a small bearing catalogue."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core._validate import positive
from ..core.errors import ParameterError

__all__ = ["Bearing", "Gear", "BEARINGS"]


@dataclass(frozen=True)
class Bearing:
    """Geometry: number of rolling elements, ball and pitch diameters (any one length unit) and the
    contact angle in degrees. ``frequencies(shaft_hz)`` gives BPFO, BPFI, BSF, 2xBSF and FTF in Hz
    (outer race fixed, inner race turning with the shaft)."""

    n_balls: int
    ball_diameter: float
    pitch_diameter: float
    contact_angle: float = 0.0
    name: str = ""

    def __post_init__(self):
        if isinstance(self.n_balls, bool) or not isinstance(self.n_balls, (int, np.integer)) or self.n_balls < 3:
            raise ParameterError(f"n_balls={self.n_balls!r} must be an integer >= 3")
        d, D = positive(self.ball_diameter, "ball_diameter"), positive(self.pitch_diameter, "pitch_diameter")
        if d >= D:
            raise ParameterError(f"ball_diameter={d} must be smaller than pitch_diameter={D}: impossible geometry")
        if not 0 <= self.contact_angle < 90:
            raise ParameterError(f"contact_angle={self.contact_angle} must be in [0, 90) degrees")

    def orders(self) -> dict:
        """Fault frequencies as multiples of the shaft speed."""
        r = self.ball_diameter / self.pitch_diameter * np.cos(np.radians(self.contact_angle))
        n = self.n_balls
        bsf = self.pitch_diameter / (2 * self.ball_diameter) * (1 - r ** 2)
        return {"BPFO": n / 2 * (1 - r), "BPFI": n / 2 * (1 + r), "BSF": bsf, "2xBSF": 2 * bsf, "FTF": (1 - r) / 2}

    def frequencies(self, shaft_hz: float) -> dict:
        f = positive(shaft_hz, "shaft_hz")
        return {k: v * f for k, v in self.orders().items()}


@dataclass(frozen=True)
class Gear:
    """A gear on the measured shaft: ``teeth``; mesh frequency teeth x shaft speed, with sidebands at
    the shaft speed (and at ``mating_shaft_ratio`` x shaft speed for the mating gear, if given)."""

    teeth: int
    mating_shaft_ratio: float | None = None

    def __post_init__(self):
        if isinstance(self.teeth, bool) or not isinstance(self.teeth, (int, np.integer)) or self.teeth < 5:
            raise ParameterError(f"teeth={self.teeth!r} must be an integer >= 5")


# SKF deep-groove bearings as used in the CWRU test rig (dimensions in inches)
BEARINGS = {
    "6205-2RS": Bearing(9, 0.3126, 1.537, 0.0, "SKF 6205-2RS JEM"),
    "6203-2RS": Bearing(8, 0.2656, 1.122, 0.0, "SKF 6203-2RS JEM"),
}
