"""Rolling-element bearing and gear fault frequencies (kinematics), and a small bearing catalogue."""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..core._validate import positive
from ..core.errors import ParameterError

__all__ = ["Bearing", "Gear", "BEARINGS", "bearing_from"]


@dataclass(frozen=True)
class Bearing:
    """A rolling-element bearing's geometry (outer race fixed, inner race turning with the shaft).

    Parameters
    ----------
    n_balls : int
        Number of rolling elements.
    ball_diameter : float
        Ball (roller) diameter, in any length unit.
    pitch_diameter : float
        Pitch diameter, in the same unit.
    contact_angle : float
        Contact angle in degrees.
    name : str
        A label (catalogue bearings carry their designation).

    Raises
    ------
    ParameterError
        For a geometry that cannot turn (ball larger than the pitch, fewer than 3 balls).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> b = vm.Bearing(9, 0.3126, 1.537, 0.0)
    >>> round(float(b.frequencies(1797 / 60)["BPFO"]), 1)
    107.4
    """

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
        """Fault frequencies as multiples of the shaft speed.

        Returns
        -------
        dict
            BPFO, BPFI, BSF, 2xBSF, FTF in orders.

        Raises
        ------
        ParameterError
            Never for a valid bearing.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> round(float(vm.BEARINGS["6205-2RS"].orders()["BPFO"]), 3)
        3.585
        """
        r = self.ball_diameter / self.pitch_diameter * np.cos(np.radians(self.contact_angle))
        n = self.n_balls
        bsf = self.pitch_diameter / (2 * self.ball_diameter) * (1 - r ** 2)
        return {"BPFO": n / 2 * (1 - r), "BPFI": n / 2 * (1 + r), "BSF": bsf, "2xBSF": 2 * bsf, "FTF": (1 - r) / 2}

    def frequencies(self, shaft_hz: float) -> dict:
        """Fault frequencies in Hz at a shaft speed.

        Parameters
        ----------
        shaft_hz : float
            Shaft speed in Hz.

        Returns
        -------
        dict
            BPFO, BPFI, BSF, 2xBSF, FTF in Hz.

        Raises
        ------
        ParameterError
            For a speed that is not positive.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> sorted(vm.BEARINGS["6205-2RS"].frequencies(30.0))
        ['2xBSF', 'BPFI', 'BPFO', 'BSF', 'FTF']
        """
        f = positive(shaft_hz, "shaft_hz")
        return {k: v * f for k, v in self.orders().items()}


@dataclass(frozen=True)
class Gear:
    """A gear on the measured shaft: mesh frequency teeth x shaft speed, sidebands at the shaft speed.

    Parameters
    ----------
    teeth : int
        Number of teeth.
    mating_shaft_ratio : float, optional
        The mating shaft's speed over this shaft's (its sidebands).

    Raises
    ------
    ParameterError
        For fewer than one tooth or a ratio that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.Gear(32).teeth
    32
    """

    teeth: int
    mating_shaft_ratio: float | None = None

    def __post_init__(self):
        if isinstance(self.teeth, bool) or not isinstance(self.teeth, (int, np.integer)) or self.teeth < 5:
            raise ParameterError(f"teeth={self.teeth!r} must be an integer >= 5")


def _load_catalogue() -> dict:
    """The shipped catalogue (vibmeasure/data/bearings.csv): rig bearings with published geometry
    and nominal 62xx/63xx deep-groove designs."""
    import csv
    from pathlib import Path
    out = {}
    with open(Path(__file__).resolve().parents[1] / "data" / "bearings.csv", newline="", encoding="utf-8") as fh:
        rows = csv.DictReader(line for line in fh if not line.startswith("#"))
        for r in rows:
            desc = r["description"] + (" [nominal design: check the maker's datasheet]" if r["source"] == "nominal"
                                       else "")
            out[r["name"]] = Bearing(int(r["n"]), float(r["d"]), float(r["D"]), float(r["angle"]), desc)
    return out


BEARINGS = _load_catalogue()
_SUFFIX = re.compile(r"[-\s]?(2RS1?|2RSH|2RZ|2Z|ZZ|RS|Z|N|NR|C3|C4|E|JEM|/C3)+$", re.I)


def bearing_from(spec) -> Bearing | None:
    """A vm.Bearing from a Bearing, None, or a catalogue name ("6205-2RS", "6308", "6308-2Z C3",
    "MFPT"); seals, shields and clearance suffixes fall back to the base designation."""
    if spec is None or isinstance(spec, Bearing):
        return spec
    if not isinstance(spec, str):
        raise ParameterError(f"bearing must be a vm.Bearing or a catalogue name, got {type(spec).__name__}")
    key = spec.strip().upper()
    names = {k.upper(): k for k in BEARINGS}
    if key in names:
        return BEARINGS[names[key]]
    base = key.replace(" ", "")
    while True:
        shorter = _SUFFIX.sub("", base)
        if shorter == base:
            break
        base = shorter
    if base in names:
        return BEARINGS[names[base]]
    raise ParameterError(f"bearing={spec!r} is not in the catalogue ({', '.join(sorted(BEARINGS))}); "
                         "give vm.Bearing(n_balls, ball_diameter, pitch_diameter, contact_angle)")
