"""Machine fault diagnosis from accelerometer records, read as its steps (one module each):

prepare (``job``: channels, units, damage, bearing, limits) -> running speed (``speed``, ``tracking``:
the 1X, its consistency with fs, order tracking) -> the supply's lines (``mains``) -> ISO 10816-3
severity (``severity``) -> shaft-order faults (``shaft``: gated by severity) -> bearing families
(``bearings``: the statistical test of monitor/bearing on every channel, never gated by severity)
-> decision (``decide``: the top, its calibrated confidence and its reason).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...core._validate import as_record, memory_guard
from ...core.errors import warn_quality
from ...core.results import Diagnosis
from .bearings import _narrow_channels, _plot_material, bearing_step
from .decide import _decide, _unweighed
from .job import Job, _prepare, _quality_note
from .mains import supply_lines
from .severity import iso_severity
from .shaft import gate_rows, gear_rows, shaft_rows
from .speed import Run, running_speed
from .tracking import _measured_speed

__all__ = ["diagnose"]


@memory_guard
def diagnose(rec, *, rpm: float | None = None, bearing=None, gear=None, machine_group: int | None = None,
             foundation: str | None = None, channel=None, channels=None, band=None,
             prewhitening=("cepstral",), line_frequency: float | None = None,
             fs: float | None = None, tach=None, pulses_per_rev: int = 1, rpm_profile=None) -> Diagnosis:
    """Diagnose a rotating machine from an acceleration record.

    ``rpm`` is the declared shaft speed (default: the record's meta["rpm"]); ``bearing`` a vm.Bearing
    or a catalogue name (``vm.BEARINGS``: "6205-2RS", "6203", "6308-2Z C3", "MFPT", ...; a roller
    bearing, which the catalogue does not hold, as vm.Bearing from the maker's data); ``gear`` a tooth count
    or vm.Gear; ``machine_group`` (1 or 2) and ``foundation`` ("rigid", "flexible") select the ISO
    10816-3 zones (default group 2, rigid). ``channel`` is the channel for speed, severity and shaft
    orders (default the first that is not a force); bearing faults are searched in every channel
    (``channels=`` restricts them) and the result names the one carrying the evidence. ``band`` fixes
    the demodulation band (default: whole band, fast kurtogram and infogram bands); ``prewhitening``
    names the pre-processings searched: "cepstral" (default) and/or "ar" (shaft-synchronous part and
    discrete lines removed, then AR whitening). ``line_frequency``
    (50 or 60 Hz) adds the electrical check at twice the line frequency; lines at the line frequency
    (default: 50 and 60 Hz) or twice it are mains, not taken for the 1X or for another shaft.

    A speed that varies over the record: give ``tach`` (the tachometer or encoder channel, by name or
    index, or its samples; ``pulses_per_rev`` pulses per revolution) or ``rpm_profile`` (one rpm per
    sample). ``rpm`` then defaults to the mean speed. When the mean speeds of up to 8 parts of the
    record differ by more than ``VARYING_SPEED`` (0.2 %), every channel is resampled at equal steps
    of shaft angle and the shaft-order and bearing analyses run in orders (cepstral pre-whitening
    after order tracking: Borghesani et al. 2013); frequencies are then orders x the mean speed, flag
    ``order_tracked``. Without speed information, a 1X that drifts along a curve (flag
    ``speed_varies``) gives the speed profile instead (``speed["source"]`` "1X line"). The ISO
    severity is taken from the record as measured.

    Every channel is checked for the recording chain's damage first (``signal.quality``): isolated
    spikes and dropouts are filled by AR interpolation (flags ``spikes_removed``, ``dropouts``; spikes
    at a fixed interval of P samples also have the comb at fs / P claimed in the envelope spectra),
    saturation is flagged (``saturated``); ``extras["data_quality"]`` holds the findings
    per channel, and a QualityWarning names them.

    The 1X is looked for within 12 % of ``rpm``. When the record contradicts the declared speed (a
    shaft comb stands elsewhere, 10 dB above the 1X candidate and with more harmonics, in any channel),
    the flag is ``speed_contradicted``, ``speed["contradicting_rpm"]`` says where the comb stands, and
    no shaft-order or bearing fault is looked for ("none", ``bearing_checked`` False). Where no 1X line
    confirms the declared speed, the bearing's own lines can contradict it too: a fault comb that
    stands where another speed (0.5-2 x) puts it, far stronger than any at the declared speed
    (``bearing.decoys._speed_scan``; ``speed["contradicted_by"]`` is then "bearing lines" and
    ``speed["bearing_comb"]`` holds the comb).
    """
    rec = as_record(rec, fs=fs)
    tracked = _tracked_speed(rec, tach, rpm_profile, pulses_per_rev)
    rpm = tracked["mean_rpm"] if rpm is None and tracked is not None else rpm
    measured = _prepare(rec, rpm, bearing, gear, machine_group, foundation, channel, channels, band, prewhitening,
                        line_frequency, skip=_tach_channel(rec, tach))
    run = running_speed(rec, measured, tracked, rpm, band)
    supply = supply_lines(run)
    severity, gate = iso_severity(measured, run.job, supply)
    rows = shaft_rows(run, supply, gate, line_frequency)
    b_rows, ev, contradicted = bearing_step(run)
    narrow = _narrow_channels(ev, run.job, run.f1) if ev is not None and run.job.band is None else []
    rows += b_rows + gear_rows(run)
    gate_rows(rows, run.job.flags, contradicted)
    return _answer(run, rows, ev, severity, narrow, contradicted)


def _tracked_speed(rec, tach, rpm_profile, pulses_per_rev) -> dict | None:
    """The speed a tachometer or an rpm profile measures, or None when neither is given."""
    if tach is None and rpm_profile is None:
        return None
    return _measured_speed(rec, tach, rpm_profile, pulses_per_rev)


def _tach_channel(rec, tach) -> tuple:
    """The tachometer's channel index (left out of the vibration channels), when tach names one."""
    if isinstance(tach, (str, int, np.integer)) and not isinstance(tach, bool):
        return (rec.index(tach),)
    return ()


def _bearing_weak(job: Job, ev, narrow: list, contradicted: bool) -> bool:
    """Whether the bearing side says little about "none": the speed varies unfollowed, every channel's
    measured band ends below the demodulation region, or the declared speed is contradicted."""
    weak = "speed_varies" in job.flags
    if narrow:
        weak = len(narrow) == len(ev.measured_top_hz)
    return weak or contradicted


def _answer(run: Run, rows: list, ev, severity: dict, narrow: list, contradicted: bool) -> Diagnosis:
    """The decision with its reason, flags and the material for plots."""
    job, speed = run.job, run.speed
    if narrow:
        job.flags.append("band_limited")
    weak = _bearing_weak(job, ev, narrow, contradicted)
    unweighed = _unweighed(rows) if "unit_unknown" in job.flags else None
    table = pd.DataFrame(rows).sort_values("confidence", ascending=False, ignore_index=True)
    top, conf, reason, also, where, (kind, score, parts) = _decide(table, job, weak)
    if unweighed:
        reason += (f"; shaft-order faults not called: the data's unit is unknown, so the ISO 10816-3 level that "
                   f"shows whether they matter cannot be computed (give unit=, e.g. 'g'); strongest pattern "
                   f"{unweighed[0]} at score {unweighed[1]:.2f}")
    if {"speed_inconsistent", "speed_contradicted", "order_tracked", "speed_varies",
            "speed_corrected"} & set(job.flags):
        reason += "; " + speed["note"]
    if narrow:
        reason += ("; " + ", ".join(f"{k} measures only up to {v:.0f} Hz" for k, v in narrow)
                   + " (above: a filter's stop band): the envelope bands reach down among the shaft harmonics")
    if job.bearing is None or contradicted:
        job.flags.append("bearing_not_checked")
    extras = {"also": also, "primary": job.primary, "score": score, "confidence_kind": kind}
    if job.quality:
        note = _quality_note(job.quality)
        reason += "; data: " + note
        extras["data_quality"] = {k: dict(v) for k, v in job.quality.items()}
        warn_quality("diagnose: " + note, stacklevel=5)
    if parts is not None:
        extras["score_parts"] = parts
    env_band = ()
    if ev is not None:
        extras.update(_plot_material(ev, top))
        extras["measured_top_hz"] = dict(ev.measured_top_hz)
        env_band = extras["ses"]["band_hz"]
    return Diagnosis(top, conf, reason, table, speed, severity, tuple(env_band), tuple(job.flags), extras,
                     channel=str(where), bearing_checked=job.bearing is not None and not contradicted)
