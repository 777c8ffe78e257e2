"""Step: the doubts an answer must carry. Each check names an assumption the answer rests on (the time
base, a confirmed speed, a speed not off by a factor 2, a band that is the record's own); where the
record puts it in doubt, the answer gets a flag, the reason says why and what to check, and its
confidence is held under DOUBT_CONFIDENCE (``hold_all``)."""

from __future__ import annotations

import numpy as np

from ..bearing.families import HALVES
from ..bearing.rules import ALPHA
from .lines import LINE_DB, _line

DOUBT_CONFIDENCE = 0.45   # a doubtful answer stays under the 0.5 a confident answer needs
SHAFT_ELSEWHERE = (2, 3, 4)   # a shaft comb at these multiples of a declared 1X that does not show


def _held(flags: list, flag: str, why: str, conf: float, reason: str) -> tuple[float, str]:
    """The answer with ``flag`` set, ``why`` in its reason and its confidence held under DOUBT_CONFIDENCE."""
    if flag not in flags:
        flags.append(flag)
    reason += "; " + why
    if conf > DOUBT_CONFIDENCE:
        reason += f"; confidence held at {DOUBT_CONFIDENCE} (was {conf:.2f})"
        conf = DOUBT_CONFIDENCE
    return conf, reason


def time_base(speed: dict, severity: dict, flags: list, conf: float, reason: str) -> tuple[float, str]:
    """When the lines fit the declared speed only at another fs (or another speed by the same factor:
    rpm for Hz, pulses per revolution), every frequency the answer rests on may be off by that factor:
    the ISO zone is withdrawn too (the velocity scales with the time base). CWRU Normal_0 read at a
    quarter of its rate was answered 'none' at 0.97 with a zone from a velocity four times too high.
    (The flag, ``speed_inconsistent``, is set where the lines are found: ``speed._speed``.)"""
    r = speed.get("fs_ratio", 1)
    if r == 1:
        return conf, reason
    if severity.get("zone") is not None:
        severity["zone"] = None
        severity["note"] = "; ".join(filter(None, [severity.get("note", ""), (
            f"no zone: the time base is in doubt (the lines fit only at {r}x fs, or {r}x the declared speed)")]))
    return _held(flags, "speed_inconsistent", f"the time base is in doubt, check fs and the speed (a factor {r}: "
                 "rpm for Hz, pulses per revolution)", conf, reason)


def unconfirmed_speed(run, conf: float, reason: str) -> tuple[float, str]:
    """No 1X line confirms the declared speed (no tachometer, no contradiction either), yet a shaft comb
    stands at 2, 3 or 4 x it (three of its first four harmonics 12 dB over their floor): the true speed
    may be that multiple (a sampling rate declared that many times too high), and every line was looked
    for where the declared speed alone puts it. A sampling rate declared 4x too high puts the 6203's
    shaft harmonics where its 2 x BSF harmonics should be (3.987 X): CWRU fan-end inner-race records
    read as ball at 1.00. Flag ``speed_unconfirmed``. A 1X merely buried in noise (synthetic machines at
    -10 dB) shows no such comb and is not held."""
    speed, job = run.speed, run.job
    if speed.get("estimated_rpm") is not None or not speed.get("consistent", True):
        return conf, reason
    df = run.f[1]
    combs = [k for k in SHAFT_ELSEWHERE
             if sum(_line(run.f, run.A, m * k * run.f1, max(2 * df, 0.01 * m * k * run.f1),
                          m * k * run.f1 + 5 * df)[2] >= LINE_DB for m in (1, 2, 3, 4)) >= 3]
    if not combs:
        return conf, reason
    return _held(job.flags, "speed_unconfirmed", f"no 1X line confirms the declared {job.rpm:g} rpm, and a shaft "
                 f"comb stands at {combs[0]} x it: check the speed and fs, or give tach=", conf, reason)


def band_given(ev, job, top: str, conf: float, reason: str) -> tuple[float, str]:
    """A bearing fault that only the user's band shows (none of the record's own bands, whole, the
    kurtogram's or the infogram's, claims it first) rests on that band alone: flag ``band_unconfirmed``.
    A band that misses the bearing's resonance, or reaches down among the shaft harmonics, demodulates
    clutter whose combs look like a fault."""
    if ev is None or top not in ev.families or not ev.families[top].get("band_given_only"):
        return conf, reason
    return _held(job.flags, "band_unconfirmed", f"only the band given ({job.band[0]:g}-{job.band[1]:g} Hz) shows "
                 "it, none of the record's own bands: check that band holds the bearing's resonance", conf, reason)


def half_speed(ev, job, conf: float, reason: str) -> tuple[float, str]:
    """A bearing family whose significant comb is refused because lines stand halfway between its
    harmonics (``bearing.families._accepted``, HALVES) is the even part of a comb at half its
    fundamental: the true speed may be half the declared one. Whatever else the lines make of the
    declared speed then rests on a doubtful speed (MFPT's outer race declared at twice its speed
    read as inner race at 1.00 from BPFO x 3, 6, 9 at +1.2 % slip): flag ``speed_doubtful``. The cage
    is left out: its comb is reported, never called, and FTF's half-harmonics are dense."""
    if ev is None:
        return conf, reason
    halved = [n for n, fam in ev.families.items() if n != "bearing_cage" and fam.get("halves", 0) >= HALVES
              and fam["log_p"] < np.log(ALPHA)]
    if not halved:
        return conf, reason
    return _held(job.flags, "speed_doubtful", f"{', '.join(halved)}: lines stand halfway between its harmonics, a "
                 f"comb at half its fundamental: the speed may be half the declared {job.rpm:g} rpm (rpm for Hz, "
                 "pulses per revolution)", conf, reason)


def hold_all(run, ev, severity: dict, top: str, conf: float, reason: str) -> tuple[float, str]:
    """Every doubt in turn: the time base, a speed nothing confirms, a factor 2, the user's band."""
    conf, reason = time_base(run.speed, severity, run.job.flags, conf, reason)
    conf, reason = unconfirmed_speed(run, conf, reason)
    conf, reason = half_speed(ev, run.job, conf, reason)
    return band_given(ev, run.job, top, conf, reason)
