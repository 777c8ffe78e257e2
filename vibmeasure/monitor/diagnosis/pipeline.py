"""Machine fault diagnosis from accelerometer records, read as its steps (one module each):

prepare (``job``: channels, units, damage, bearing, limits) -> running speed (``speed``, ``tracking``:
the 1X, its consistency with fs, order tracking) -> the gear pair's shafts (``mating``: a declared gear's
mate; ``gearbox``: a pair the spectrum shows where none is declared) -> the supply's lines (``mains``) -> ISO 10816-3
severity (``severity``) -> shaft-order faults (``shaft``: gated by severity) -> bearing families
(``bearings``: the statistical test of monitor/bearing on every channel, never gated by severity;
again at the file's own speed where it disputes the declared one) -> the bearing call tested again on
the record cut 1-2 % short (``stability``)
-> the gear (``gears``) -> decision (``decide``: the top, its calibrated confidence and its reason)
-> the doubts the answer carries (``doubts``: time base, speed, factor 2, the user's band).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...core._validate import as_record, memory_guard
from ...core.errors import warn_quality
from ...core.units import quantity_of
from ...core.results import Diagnosis
from .bearings import _narrow_channels, _plot_material, bearing_step, other_speed_rows
from . import doubts
from .decide import _decide, _unweighed, candidates
from .job import DIFFERENTIATIONS, Job, _prepare, _quality_note
from .mains import supply_lines
from .gearbox import found_note, gearbox_found
from .mating import mating_shaft
from .severity import iso_severity
from .gears import gear_rows
from .shaft import gate_rows, shaft_rows
from .speed import Run, running_speed
from .stability import survives_a_cut
from .tracking import _measured_speed

__all__ = ["diagnose"]


@memory_guard
def diagnose(rec, *, rpm: float | None = None, bearing=None, gear=None, machine_group: int | None = None,
             foundation: str | None = None, channel=None, channels=None, band=None,
             prewhitening=("cepstral",), line_frequency: float | None = None,
             fs: float | None = None, tach=None, pulses_per_rev: int = 1, rpm_profile=None) -> Diagnosis:
    """Diagnose a rotating machine from an acceleration record.

    The steps (docs/methods/diagnosis.md): every channel checked for the recording chain's damage
    (spikes and dropouts filled, transients gated, saturation flagged); the running speed from the 1X
    near ``rpm`` (within 12 %; a declared gear's mesh within 30 % with it), checked against fs and
    against shaft or bearing combs that stand where another speed puts them (flag
    ``speed_contradicted``: then no fault is looked for); the supply's lines set aside; the ISO 10816-3
    severity; shaft-order faults weighed by the level; bearing families as a statistical test on
    pre-whitened squared-envelope spectra of every channel; the decision with a calibrated confidence
    and its reason. A speed that varies (``tach``, ``rpm_profile``, or a 1X that drifts) is followed by
    order tracking (flag ``order_tracked``).

    Parameters
    ----------
    rec : Record or array_like
        Acceleration channels (an array needs ``fs``); a tachometer channel may ride along.
    rpm : float, optional
        Declared shaft speed (default the record's meta["rpm"], or the tachometer's mean).
    bearing : str or Bearing, optional
        A catalogue name (``vm.BEARINGS``: "6205-2RS", "6203-2RS", "MFPT", ...) or a vm.Bearing; without
        it bearing faults are not checked.
    gear : int or Gear, optional
        Teeth of a gear on the shaft.
    machine_group : {1, 2}, optional
        ISO 10816-3 group (default 2).
    foundation : {"rigid", "flexible"}, optional
        ISO 10816-3 support class (default rigid).
    channel : str or int, optional
        The channel for speed, severity and shaft orders (default the first that is not a force).
    channels : str, int or list, optional
        The channels searched for bearing faults (default every vibration channel): only these; the
        first of them is also the primary channel unless ``channel`` names another.
        ``extras["channels_used"]`` lists them.
    band : tuple of float, optional
        A demodulation band (Hz) of your choice, searched beside the record's own (the whole band, the
        kurtogram's and the infogram's): a finding in it alone needs overwhelming evidence, as in any
        single view.
    prewhitening : str or tuple of str
        "cepstral" (default) and/or "ar".
    line_frequency : float, optional
        The supply's frequency (50 or 60 Hz): adds the electrical check at twice it.
    fs : float, optional
        Sampling rate for an array.
    tach : str, int or array_like, optional
        Tachometer or encoder channel (or its samples): the speed is measured.
    pulses_per_rev : int
        Tachometer pulses per revolution.
    rpm_profile : array_like, optional
        One rpm per sample, instead of a tachometer.

    Returns
    -------
    Diagnosis
        ``top``, ``confidence``, ``reason``, ``faults`` (one row per family), ``speed``, ``severity``,
        ``channel``, ``flags`` and ``extras`` (the material for ``plot_diagnosis``).

    Raises
    ------
    ParameterError
        For a missing speed, fs too low for the bearing's lines, too few revolutions, bad options or
        a channel with nothing to analyse.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="bearing_inner_race", rpm=1797, duration=4.0, seed=1)
    >>> d = vm.diagnose(rec, rpm=1797, bearing="6205-2RS")
    >>> d.top, d.confidence > 0.9
    ('bearing_inner_race', True)
    """
    rec = as_record(rec, fs=fs)
    tracked = _tracked_speed(rec, tach, rpm_profile, pulses_per_rev)
    rpm = tracked["mean_rpm"] if rpm is None and tracked is not None else rpm
    measured = _prepare(rec, rpm, bearing, gear, machine_group, foundation, channel, channels, band, prewhitening,
                        line_frequency, skip=_tach_channel(rec, tach))
    run = gearbox_found(mating_shaft(running_speed(rec, measured, tracked, rpm, band)))
    supply = supply_lines(run)
    severity, gate = iso_severity(measured, run.job, supply)
    rows = shaft_rows(run, supply, gate, line_frequency)
    b_rows, ev, contradicted = bearing_step(run)
    b_rows = other_speed_rows(run, b_rows, ev)
    b_rows = survives_a_cut(run, b_rows, ev)
    narrow = _narrow_channels(ev, run.job, run.f1) if ev is not None and run.job.band is None else []
    rows += b_rows + gear_rows(run)
    gate_rows(rows, run.job.flags, contradicted)
    return _answer(run, rows, ev, severity, narrow, contradicted)


def _conversion_note(converted: dict) -> str:
    """What was made of channels in velocity or displacement units, and the standard's scope."""
    by_unit: dict = {}
    for k, u in converted.items():
        by_unit.setdefault(u, []).append(repr(k))
    note = "; ".join(f"{', '.join(names)} (in {u}) differentiated "
                     f"{'once' if DIFFERENTIATIONS[quantity_of(u)] == 1 else 'twice'}" for u, names in by_unit.items())
    note += " to acceleration for the envelope and the shaft orders"
    if any(quantity_of(u) == "displacement" for u in converted.values()):
        note += ("; the ISO 10816-3 zones judge velocity on the bearing housing: a proximity probe's shaft "
                 "displacement is judged by ISO 20816 / 7919 instead")
    return note


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
    """Whether the bearing side says little about "none": the speed varies (followed, if at all, along
    a speed estimated from the 1X, not measured), every channel's measured band ends below the
    demodulation region, or the declared speed is contradicted."""
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
    top, conf, reason, also, where, (kind, score, parts), p_healthy = _decide(table, job, weak)
    conf, reason = doubts.hold_all(run, ev, severity, top, conf, reason)
    p_healthy = min(p_healthy, conf) if top == "none" else p_healthy
    if unweighed:
        reason += (f"; shaft-order faults not called: the data's unit is unknown, so the ISO 10816-3 level that "
                   f"shows whether they matter cannot be computed (give unit=, e.g. 'g'); strongest pattern "
                   f"{unweighed[0]} at score {unweighed[1]:.2f}")
    if {"speed_inconsistent", "speed_contradicted", "order_tracked", "speed_varies",
            "speed_corrected", "half_order_ambiguous", "speed_unchecked"} & set(job.flags):
        reason += "; " + speed["note"]
    if narrow:
        reason += ("; " + ", ".join(f"{k} measures only up to {v:.0f} Hz" for k, v in narrow)
                   + " (above: a filter's stop band): the envelope bands reach down among the shaft harmonics")
    if "mating_teeth" in speed:
        reason += (f"; the mating gear's {speed['mating_teeth']} teeth measured from the mesh's sidebands (its "
                   "shaft's lines set apart; declare mating_shaft_ratio= to fix it)")
    if found_note(speed):
        reason += "; " + found_note(speed)
    if job.converted:
        reason += "; " + _conversion_note(job.converted)
    if "channels_restricted" in job.flags:
        reason += (f"; only {', '.join(map(repr, job.signals))} searched (channels=): a fault another sensor "
                   "sees is not looked for")
    if job.bearing is None or contradicted:
        job.flags.append("bearing_not_checked")
    extras = {"also": also, "primary": job.primary, "score": score, "confidence_kind": kind,
              "channels_used": list(job.signals), "p_healthy": float(p_healthy)}
    if top == "undetermined":
        extras["candidates"] = candidates(table)
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
                     channel=str(where), bearing_checked=job.bearing is not None and not contradicted,
                     p_healthy=float(p_healthy))
