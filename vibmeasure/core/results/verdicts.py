"""Verdicts: a machine Diagnosis and a Comparison of measured with predicted modes."""

from __future__ import annotations

from dataclasses import dataclass, field

from ._common import jsonable


@dataclass(frozen=True)
class Diagnosis:
    """A machine diagnosis (``vm.diagnose``).

    Attributes
    ----------
    top : str
        The answer: a fault (unbalance, misalignment, looseness, bearing_outer_race, bearing_inner_race,
        bearing_ball, gear_mesh, resonance or electrical); "none" where no fault is named and the
        machine is healthy with a probability of 0.5 or more; "undetermined" where no fault is named
        yet a fault is the more likely (``extras["candidates"]`` lists the strongest families).
    confidence : float
        The probability that ``top`` is right, calibrated on synthetic machines
        (monitor/calibration.py); ``extras["score"]`` is the raw evidence score it was mapped from.
        For "undetermined" it is 1 - ``p_healthy``: the probability that some fault is present.
    reason : str
        Why, in words: the evidence, the strongest candidate of a "none", what was not checked.
    faults : pandas.DataFrame
        One row per fault family: evidence, p-value (bearing families), channel, pre-processing, band.
    speed : dict
        Declared and estimated rpm, the 1X line's height, consistency with fs and the note.
    severity : dict
        ISO 10816-3 velocity RMS (mm/s), its band, group, foundation and zone.
    envelope_band_hz : tuple
        The demodulation band of the envelope spectrum that carries the top (or strongest) bearing family.
    flags : tuple of str
        Quality flags (``speed_corrected``, ``unit_unknown``, ``band_limited``, ...).
    extras : dict
        The bearing test per family, that envelope spectrum and the kurtogram (for plots), the data
        quality findings.
    channel : str
        The channel that carries the top's evidence.
    bearing_checked : bool
        False without a bearing, or where the declared speed is contradicted.
    p_healthy : float or None
        The probability that the machine carries none of the faults checked (None for a diagnosis
        made before this field existed).

    Raises
    ------
    ParameterError
        Never for a ``vm.diagnose`` result.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="unbalance", rpm=1797, duration=4.0, seed=1)
    >>> d = vm.diagnose(rec, rpm=1797, bearing="6205-2RS")
    >>> d.top
    'unbalance'
    """

    top: str
    confidence: float
    reason: str
    faults: object
    speed: dict
    severity: dict
    envelope_band_hz: tuple
    flags: tuple = ()
    extras: dict = field(default_factory=dict)
    channel: str = ""
    bearing_checked: bool = False
    p_healthy: float | None = None

    def to_dict(self) -> dict:
        """The diagnosis as plain JSON-ready values (the CLI's ``--json`` document).

        Returns
        -------
        dict
            top, confidence, p_healthy, score, reason, channel, bearing_checked, faults (records), speed,
            severity, envelope_band_hz, flags, also, candidates, measured_top_hz.

        Raises
        ------
        ParameterError
            Never for a valid object.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> d = vm.diagnose(vm.synth.machine(fault="unbalance", rpm=1797, duration=2.0, seed=1), rpm=1797)
        >>> d.to_dict()["top"]
        'unbalance'
        """
        return jsonable({"top": self.top, "confidence": self.confidence, "p_healthy": self.p_healthy,
                         "score": self.extras.get("score"), "candidates": self.extras.get("candidates", []),
                         "reason": self.reason,
                         "channel": self.channel, "bearing_checked": self.bearing_checked,
                         "faults": self.faults.to_dict(orient="records"), "speed": self.speed,
                         "severity": self.severity, "envelope_band_hz": list(self.envelope_band_hz),
                         "flags": list(self.flags), "also": list(self.extras.get("also", ())),
                         "measured_top_hz": self.extras.get("measured_top_hz")})

    def __repr__(self) -> str:
        return f"Diagnosis(top={self.top!r}, confidence={self.confidence:.2f}: {self.reason})"


@dataclass(frozen=True)
class Comparison:
    """Paired modes with deviations and verdicts (``vm.compare``).

    Parameters
    ----------
    rows : tuple of dict
        One per paired mode: predicted and measured fn and zeta, deviations, dk/k, verdict.
    verdict : str
        The worst: "ok", "watch" or "alarm".
    reason : str
        Why, in words.
    unpaired_measured, unpaired_predicted : tuple of float
        Frequencies that found no partner.
    settings : dict
        The tolerances used.

    Raises
    ------
    ParameterError
        Never for a ``vm.compare`` result.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> est = vm.ModalEstimate(fn=[10.0], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001])
    >>> cmp = vm.compare(est, vm.ModalEstimate(fn=[10.5], zeta=[0.02]))
    >>> cmp.verdict
    'alarm'
    """

    rows: tuple
    verdict: str
    reason: str
    unpaired_measured: tuple = ()
    unpaired_predicted: tuple = ()
    settings: dict = field(default_factory=dict)

    def to_frame(self):
        """One row per paired mode.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> est = vm.ModalEstimate(fn=[10.0], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001])
        >>> cmp = vm.compare(est, vm.ModalEstimate(fn=[10.5], zeta=[0.02]))
        >>> len(cmp.to_frame())
        1
        """
        import pandas as pd
        return pd.DataFrame(list(self.rows))

    def to_dict(self) -> dict:
        """JSON-ready: verdict, reason, modes, unpaired_measured_hz, unpaired_predicted_hz, settings.

        Returns
        -------
        dict

        Raises
        ------
        ParameterError
            Never.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> est = vm.ModalEstimate(fn=[10.0], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001])
        >>> cmp = vm.compare(est, vm.ModalEstimate(fn=[10.5], zeta=[0.02]))
        >>> cmp.to_dict()["verdict"]
        'alarm'
        """
        return jsonable({"verdict": self.verdict, "reason": self.reason, "modes": list(self.rows),
                          "unpaired_measured_hz": list(self.unpaired_measured),
                          "unpaired_predicted_hz": list(self.unpaired_predicted), "settings": self.settings})

    def __repr__(self) -> str:
        return f"Comparison({self.verdict}: {self.reason})"
