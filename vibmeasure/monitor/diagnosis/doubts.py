"""Step: the doubts an answer must carry. Each check names an assumption the answer rests on (the time
base, a confirmed speed, a speed not off by a factor 2, a band that is the record's own); where the
record puts it in doubt, the answer gets a flag, the reason says why and what to check, and its
confidence is held under DOUBT_CONFIDENCE (``hold_all``)."""

from __future__ import annotations

import numpy as np

from ..bearing.families import HALVES
from ..bearing.rules import ALPHA, SLIP
from .lines import LINE_DB, _line
from .speed import SPEED_NOTED

DOUBT_CONFIDENCE = 0.45   # a doubtful answer stays under the 0.5 a confident answer needs
SHAFT_ELSEWHERE = (2, 3, 4)   # a shaft comb at these multiples of a declared 1X that does not show


def _held(flags: list, flag: str, why: str, conf: float, reason: str, hold: bool = True) -> tuple[float, str]:
    """The answer with ``flag`` set, ``why`` in its reason and (``hold``) its confidence held under
    DOUBT_CONFIDENCE."""
    if flag not in flags:
        flags.append(flag)
    reason += "; " + why
    if hold and conf > DOUBT_CONFIDENCE:
        reason += f"; confidence held at {DOUBT_CONFIDENCE} (was {conf:.2f})"
        conf = DOUBT_CONFIDENCE
    return conf, reason


def time_base(job, speed: dict, severity: dict, conf: float, reason: str) -> tuple[float, str]:
    """When the lines fit the declared speed only at another fs (or another speed by the same factor:
    rpm for Hz, pulses per revolution), every frequency the answer rests on may be off by that factor:
    the ISO zone is withdrawn too (the velocity scales with the time base). CWRU Normal_0 read at a
    quarter of its rate was answered 'none' at 0.97 with a zone from a velocity four times too high.
    (The flag, ``speed_inconsistent``, is set where the lines are found: ``speed._speed``.)"""
    r, flags = speed.get("fs_ratio", 1), job.flags
    if r == 1:
        return conf, reason
    if severity.get("zone") is not None:
        severity["zone"] = None
        severity["note"] = "; ".join(filter(None, [severity.get("note", ""), (
            f"no zone: the time base is in doubt (the lines fit only at {r}x fs, or {r}x the declared speed)")]))
    return _held(flags, "speed_inconsistent", f"the time base is in doubt, check fs and the speed (a factor {r}: "
                 f"rpm for Hz, pulses per revolution){_found_there(job, 'time base')}", conf, reason)


def unconfirmed_speed(run, conf: float, reason: str) -> tuple[float, str]:
    """No 1X line confirms the declared speed (no tachometer, no contradiction either), yet a shaft comb
    stands at 2, 3 or 4 x it (three of its first four harmonics 12 dB over their floor): the true speed
    may be that multiple (a sampling rate declared that many times too high), and every line was looked
    for where the declared speed alone puts it. A sampling rate declared 4x too high puts the 6203's
    shaft harmonics where its 2 x BSF harmonics should be (3.987 X): CWRU fan-end inner-race records
    read as ball at 1.00. Flag ``speed_unconfirmed``. A 1X merely buried in noise (synthetic machines at
    -10 dB) shows no such comb and is not held. A 1X found away from the declared speed
    (``speed_corrected``) confirms nothing either, with its harmonics or without: a comb counts there
    when it is not that 1X's own and its first line stands at least as high as that 1X (CWRU fan-end
    OR021@6_0 read at 4 x fs took a line 5.5 % below the declared speed, without harmonics, for its 1X
    and read as ball at 0.89 with all three channels; IR007_1, whose file states a speed 2.4 % slow,
    shows scattered lines near 2-4 x the declared speed under its strong true 1X). The bearing test is
    run again at the comb's speed (``bearings.other_speed_rows``) and what it finds there is said."""
    job = run.job
    combs = shaft_elsewhere(run)
    if not combs:
        return conf, reason
    corrected = "speed_corrected" in job.flags
    said = (f"the 1X taken, at {60 * run.f1:.0f} rpm, is off the declared {job.rpm:g} rpm" if corrected else
            f"no 1X line confirms the declared {job.rpm:g} rpm")
    return _held(job.flags, "speed_unconfirmed", f"{said}, and a shaft comb stands at {combs[0]} x the declared "
                 f"speed{_found_there(job, 'comb')}: check the speed and fs, or give tach=", conf, reason)


def shaft_elsewhere(run) -> list:
    """The multiples k of the declared speed (SHAFT_ELSEWHERE) at which a shaft comb stands while no 1X
    confirms the declared speed (``unconfirmed_speed``): three of the comb's first four harmonics
    LINE_DB over their floor; beside a 1X found off the declared speed, a comb that is not that 1X's own
    and whose first line stands at least as high as it."""
    speed, job = run.speed, run.job
    # a 1X taken off the declared speed confirms nothing, with its harmonics or without (the bearing's
    # lines are then searched from 0.5 to 2 x, ``speed._confirmed``, never at 3 or 4 x)
    corrected = "speed_corrected" in job.flags
    if (speed.get("estimated_rpm") is not None and not corrected) or not speed.get("consistent", True):
        return []
    df, f0 = run.f[1], job.rpm / 60.0
    combs = []
    for k in SHAFT_ELSEWHERE:
        if corrected and _harmonic_of(k * f0, run.f1):
            continue
        lines = [_line(run.f, run.A, m * k * f0, max(2 * df, 0.01 * m * k * f0), m * k * f0 + 5 * df)
                 for m in (1, 2, 3, 4)]
        db = [ln[2] for ln in lines]
        # beside a 1X found, the comb must be no harmonic of it where its line stands (a 1X 1.2 % off
        # puts its 4X 1.2 % off 4 x the declared speed, inside the search) and outstand it
        if corrected and lines[0][0] is not None and _harmonic_of(lines[0][0], run.f1):
            continue
        if sum(d >= LINE_DB for d in db) >= 3 and (not corrected or db[0] >= speed["one_x_db"]):
            combs.append(k)
    return combs


def _found_there(job, kind: str) -> str:
    """What the bearing test found at the other speeds of one kind (``bearings.other_speed_rows``), said."""
    said = [f"at {o['where']} the bearing test finds " + ", ".join(f"{name} (p = {p:.2g})"
                                                                    for name, p in o["found"].items())
            for o in job.at_other_speeds if o["why"] == kind and o["found"]]
    return "".join("; " + s for s in said)


def _harmonic_of(f: float, f1: float) -> bool:
    """Whether f stands within 1 % of a whole multiple of f1 (that shaft's own comb)."""
    k = max(1, round(f / f1))
    return abs(f / (k * f1) - 1) <= 0.01


def band_given(ev, job, top: str, conf: float, reason: str) -> tuple[float, str]:
    """A bearing fault that only the user's band shows (none of the record's own bands, whole, the
    kurtogram's or the infogram's, claims it first) rests on that band alone: flag ``band_unconfirmed``.
    A band that misses the bearing's resonance, or reaches down among the shaft harmonics, demodulates
    clutter whose combs look like a fault. An answer that names no fault says so of its strongest
    bearing candidate too (the flag, no hold: it names nothing). A family the band alone shows is not
    called against one the record's own bands call (``bearing.evidence._family_summaries``); the answer
    is then theirs and says what the band read (the flag, no hold)."""
    if ev is None or job.band is None:
        return conf, reason
    if top == "undetermined":   # a candidate that only the band given shows, when it stands in the way
        fams = [n for n in ev.families if n != "bearing_cage" and ev.families[n]["log_p"] < np.log(ALPHA)]
        only = [n for n in fams if ev.families[n].get("band_given_only")]
        name = min(only, key=lambda n: ev.families[n]["log_p"], default=None)
        if name is None:
            return conf, reason
        others = [n for n in fams if n not in only]
        against = (f", against {', '.join(others)}, which the record's own bands show (analyse without band= to "
                   "see it named)") if others else ""
        return _held(job.flags, "band_unconfirmed", f"bearing candidate {name} only the band given "
                     f"({job.band[0]:g}-{job.band[1]:g} Hz) shows{against}: check that band holds the bearing's "
                     "resonance", conf, reason, hold=False)
    refused = [n for n in ev.families if ev.families[n].get("against_own")]
    if refused and top in ev.families and not ev.families[top].get("band_given_only"):
        return _held(job.flags, "band_unconfirmed", f"the band given ({job.band[0]:g}-{job.band[1]:g} Hz) reads "
                     f"{', '.join(refused)}, which none of the record's own bands show: the answer is theirs; check "
                     "that band holds the bearing's resonance", conf, reason, hold=False)
    if top not in ev.families or not ev.families[top].get("band_given_only"):
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


def mesh_speed(run, conf: float, reason: str) -> tuple[float, str]:
    """A declared gear whose mesh stands not at teeth x the declared speed but at 2, 0.5, 4 or 0.25 x
    that (``speed.MESH_FACTORS``), with a 1X at its speed (``speed._speed``: ``speed["mesh_factor"]``),
    or at half that as well as at it (the declared speed's line is then the mesh's second harmonic):
    the speed, or the sampling rate, may be off by that factor, and every order the answer rests on with
    it. A healthy 32/71 gearbox at 1800 rpm declared at 900 read its true 1X as 2X, "2X/1X = 10.4", and
    was called misalignment at 1.00: flag ``speed_doubtful``, held at 0.45."""
    q = run.speed.get("mesh_factor")
    if q is None:
        return conf, reason
    job = run.job
    also = " as well" if run.speed["mesh_hz"] != run.speed["mesh_factor_hz"] else ""
    return _held(job.flags, "speed_doubtful", f"the gear's mesh ({job.gear.teeth} teeth) stands at "
                 f"{run.speed['mesh_factor_hz']:.1f} Hz{also}, {q:g} x where the declared {job.rpm:g} rpm puts it, "
                 f"with a 1X at its speed: the speed may be {q:g} x the declared, or fs {q:g} x (rpm for Hz, pulses per "
                 "revolution, the sampling rate)",
                 conf, reason)


def gearbox_speed(run, conf: float, reason: str) -> tuple[float, str]:
    """A gear pair found in the spectrum, none declared (``gearbox.gearbox_found``: ``speed["gearbox"]``),
    neither of whose shafts turns at the speed used, where no 1X with its harmonics confirms that speed:
    the mesh measures both shafts teeth times finer than a 1X, so the speed (or fs) may be off, by a
    factor where one shaft stands at 2, 0.5, 4 or 0.25 x the declared speed, and every order the answer
    rests on with it. A healthy 32/71 gearbox declared at 0.8 x its speed called a ball at 0.68, read
    at 4 x its fs an outer race at 1.00: flag ``speed_doubtful``, held. Where a 1X with its harmonics
    confirms the speed, the pair is another stage's: said, not held."""
    info = run.speed.get("gearbox")
    if not info or info.get("on_shaft"):
        return conf, reason
    job = run.job
    (za, zb), (ra, rb) = info["teeth"], info["shafts_rpm"]
    what = (f"a gear mesh stands at {info['mesh_hz']:.1f} Hz with the sidebands of two shafts, {ra:.0f} rpm ({za} "
            f"teeth) and {rb:.0f} rpm ({zb} teeth), neither at the {60 * run.f1:.0f} rpm used")
    if info["confirmed"]:
        return _held(job.flags, "gear_elsewhere", what + ", whose 1X and harmonics stand: another stage's pair",
                     conf, reason, hold=False)
    q = info.get("factor")
    why = (f": the speed may be {q:g} x the declared (rpm for Hz, pulses per revolution) or fs {q:g} x" if q else
           ": the speed may be off")
    return _held(job.flags, "speed_doubtful", what + why + "; check the speed and fs, or give tach= (or declare "
                 "gear= for the shaft the sensor is on)", conf, reason)


def half_line(run, conf: float, reason: str) -> tuple[float, str]:
    """A line at half the declared speed standing ``speed.HALF_OVER_1X_DB`` over the 1X (or where no 1X
    stands), without the 1.5X that would make it a time base's mistake (``speed._speed``: ``speed["half_line"]``):
    the shaft's true 1X may be that line, at a speed declared twice too high, and every order the answer
    rests on is then read at twice its own. A loose machine's sub-harmonic stands under or about at its
    1X. A healthy 23/67 gearbox at 2400 rpm declared at 4800 rpm showed its true 1X 28 dB over the
    declared 1X (its true 2X), its 3X on the 120 Hz supply harmonic, and was called looseness at 1.00:
    flag ``speed_doubtful``, held."""
    half = run.speed.get("half_line")
    if half is None:
        return conf, reason
    return _held(run.job.flags, "speed_doubtful", f"a line at {half[0]:.2f} Hz, half the declared {run.job.rpm:g} rpm, "
                 f"stands {half[1]:.0f} dB over its floor, {half[1] - run.speed['one_x_db']:.0f} dB over the declared 1X's: it "
                 "may be the shaft's 1X, at a speed half the declared (rpm for Hz, pulses per revolution), or "
                 "a sub-harmonic: check the speed, or give tach=", conf, reason)


def two_x_alone(run, top: str, conf: float, reason: str) -> tuple[float, str]:
    """Misalignment called from its 2X where no 1X line stands at the declared speed (nor did a
    tachometer measure it): the 2X is also the 1X of a shaft at twice the declared speed, the commonest
    speed mistake (rpm for Hz, pulses per revolution), and "2X/1X" then compares a line with the noise.
    A misaligned shaft keeps a 1X (its unbalance is never nil); which of the two it is, only the speed
    can settle. A healthy 32/71 gearbox at 1800 rpm declared at 900 read 2X/1X = 10.4 and was called
    misalignment at 1.00: flag ``speed_unconfirmed``, held."""
    speed = run.speed
    if top != "misalignment" or speed.get("estimated_rpm") is not None or speed.get("source") is not None:
        return conf, reason
    return _held(run.job.flags, "speed_unconfirmed", f"no 1X line stands at the declared {run.job.rpm:g} rpm: the "
                 f"2X the call rests on is the 1X of a shaft at {2 * run.job.rpm:g} rpm if the speed was declared "
                 "half the true one (rpm for Hz, pulses per revolution): check the speed, or give tach=", conf, reason)


def gear_unseen(run, conf: float, reason: str) -> tuple[float, str]:
    """A gear declared whose mesh line does not stand at teeth x the speed used (``gears.gear_rows``
    sets the flag ``gear_not_seen``): the speed, the tooth count or the sensor's place is off, and the
    gear was not checked: said, with the flag, not held. A gearbox with a local tooth fault declared at
    0.8 x its speed (its mesh then beyond the search) read "none" at 0.73 without a word; a fleet's every
    machine declared with a gear, the sensor on the motor, or a 1X buried in noise beside it, leave the
    rest of the answer standing."""
    job = run.job
    if "gear_not_seen" not in job.flags:
        return conf, reason
    return _held(job.flags, "gear_not_seen", f"no mesh line stands at {job.gear.teeth} x the speed used "
                 f"({job.gear.teeth * run.f1:.1f} Hz): the gear was not checked; check the speed, the tooth count "
                 "and that the sensor sees the gear", conf, reason, hold=False)


def file_speed(run, conf: float, reason: str) -> tuple[float, str]:
    """A declared rpm that differs from the speed the file states (``Job.file_rpm``) by more than
    SPEED_NOTED, where neither a tachometer nor a 1X line settles which is right (a 1X at the file's
    speed; or one at the declared speed with no line at the file's: a shaft's 2X stands at twice its
    speed, so a line at a declared speed of twice the file's settles nothing): one of them is a mistake
    (rpm for Hz, pulses per revolution, another shaft, a nameplate speed), and every bearing line was
    put where the declared one says. Flag ``speed_disagrees_file``, held; the reason says what the bearing
    test finds at the file's speed (``bearings.other_speed_rows``). MFPT's outer-race record declared 1.2
    x the 1500 rpm its file states (its 1X too weak to be found) reads as ball at the declared speed and
    as outer race at the file's. A speed the record contradicts names no fault already: there the file's
    speed is only said."""
    job = run.job
    if not file_disputes(run):
        return conf, reason
    said = _found_there(job, "file")
    return _held(job.flags, "speed_disagrees_file", f"the file states {job.file_rpm:g} rpm, the declared "
                 f"{job.rpm:g} rpm ({job.rpm / job.file_rpm:.3g} x) was used and no 1X line settles which is right"
                 f"{said}: check the speed (rpm for Hz, pulses per revolution), or give tach=", conf, reason,
                 hold="speed_contradicted" not in job.flags)


def file_disputes(run) -> bool:
    """Whether the speed the file states disputes the declared one (``file_speed``): they differ by more
    than SPEED_NOTED, no tachometer measured the speed, and no 1X line settles it (one at the file's speed;
    or one at the declared speed with none at the file's)."""
    job, speed = run.job, run.speed
    if job.file_rpm is None or abs(job.rpm / job.file_rpm - 1) <= SPEED_NOTED or speed.get("source") is not None:
        return False
    measured = speed.get("estimated_rpm")
    if measured is not None and abs(measured / job.file_rpm - 1) <= SPEED_NOTED:
        return False
    f_file, df = job.file_rpm / 60.0, run.f[1]
    file_line = _line(run.f, run.A, f_file, max(2 * df, SPEED_NOTED * f_file), f_file + 5 * df)[2] >= LINE_DB
    return not (measured is not None and abs(measured / job.rpm - 1) <= SPEED_NOTED and not file_line)


def factor_rival(run, ev, conf: float, reason: str) -> tuple[float, str]:
    """The 1X was found away from the declared speed (``speed_corrected``: the declared speed is wrong
    already), and the bearing's lines make a comb near 0.5 or 2 x the speed used as significant as any
    at that speed (``BearingEvidence.factor_rival``: both may saturate). Which speed is the shaft's the
    lines cannot tell, and the 1X taken may be another line (a supply line, another shaft's): flag
    ``speed_doubtful``. CWRU OR014@3_3 read at half its sampling rate took the 60 Hz supply's image,
    4 % above the declared speed, for its 1X and read as inner race at 0.88, while the outer race's comb
    stood at 0.48 x that speed (the true one), p = 1e-101 as against 1e-55."""
    rival = None if ev is None else ev.factor_rival
    if rival is None or "speed_corrected" not in run.job.flags:
        return conf, reason
    return _held(run.job.flags, "speed_doubtful", f"a {rival['family']} comb ({rival['model']}, p = "
                 f"{rival['p_value']:.2g}) stands where {60 * run.f1 * rival['factor']:.0f} rpm "
                 f"({rival['factor']:.2f} x the speed used) puts it, as clearly as any at the speed used: check "
                 "the speed and fs (a factor 2: rpm for Hz, pulses per revolution), or give tach=", conf, reason)


def ball_slip_edge(ev, job, top: str, conf: float, reason: str) -> tuple[float, str]:
    """A ball called from its smeared comb (humps at 2 x BSF and its harmonics, no line comb) whose best
    common slip is the search's edge (+-SLIP): the humps would fit better outside the range the model
    allows, so they may be another comb's skirts, or the ball's spin is further off its kinematic value
    than the model assumes. A line comb at its edge is refused for that reason; the smeared comb, wide by
    nature, is called but held: flag ``ball_slip_edge``. CWRU fan-end B007_1 and B014_1 are found so
    (slip -2.00 %)."""
    fam = None if ev is None else ev.families.get("bearing_ball")
    sm = None if fam is None else fam.get("smeared")
    if top != "bearing_ball" or sm is None or not sm.get("found") or abs(sm["slip"]) < SLIP * (1 - 1e-9):
        return conf, reason
    return _held(job.flags, "ball_slip_edge", f"the smeared ball comb fits best at the edge of the slip searched "
                 f"({100 * sm['slip']:+.2f} %): a longer record, or one under another load, should show whether "
                 "the humps follow 2 x BSF", conf, reason)


def unstable_call(job, top: str, conf: float, reason: str) -> tuple[float, str]:
    """The bearing family named is not called on the record cut 1-2 % short, though its comb is still
    significant there (``stability.survives_a_cut``): part of what called it (its views, votes or
    decoys) rests on where the record ends. Flag ``bearing_call_unstable``. CWRU fan-end B014_3 (ball,
    0.77) keeps its comb at p = 2e-10 on the shorter record but no call; with the other end's bearing
    declared, OR007@6_3 read ball at 0.64 and 0.49 cut."""
    cut = job.cut_retest
    if not cut or cut["family"] != top:
        return conf, reason
    return _held(job.flags, "bearing_call_unstable", f"on the first {cut['cut_to']} of the {cut['samples']} samples "
                 f"the comb stands (p = {cut['p_value']:.2g}) but is not called: the call rests in part on where the "
                 "record ends; a longer record, or another, should settle it", conf, reason)


def unit_label(job, severity: dict, conf: float, reason: str) -> tuple[float, str]:
    """A channel declared velocity or displacement whose content is an acceleration's (``job.
    _unit_plausibility``: most of its power above 1 kHz): the conversion the answer rests on (one or
    two differentiations) is in doubt, and with it every level and the ISO zone. CWRU OR007@12_1, its
    acceleration declared mm/s, was called a ball fault at full confidence."""
    if "unit_doubtful" not in job.flags:
        return conf, reason
    if severity.get("zone") is not None:
        severity["zone"] = None
        severity["note"] = "; ".join(filter(None, [severity.get("note", ""), "no zone: the unit is in doubt"]))
    return _held(job.flags, "unit_doubtful", f"the channel declared {next(iter(job.converted.values()))} holds "
                 f"{job.unit_share:.2g}x more power above 1 kHz than in 10-1000 Hz, as an acceleration does: check "
                 "the unit", conf, reason)


def hold_all(run, ev, severity: dict, top: str, conf: float, reason: str) -> tuple[float, str]:
    """Every doubt in turn: the time base, the unit, a speed the file contradicts, a gear's mesh at 2,
    0.5, 4 or 0.25 x the declared speed's, a gear pair found whose shafts are not the speed used, a
    strong line at half it, a 2X called without a 1X, a gear whose mesh is not seen, a speed nothing
    confirms, a factor 2 (half-harmonics, a rival comb), a smeared ball at its slip's edge, a call the
    record cut short does not make, the user's band. An answer that names no fault yet finds one
    likely ("undetermined", confidence 1 - p_healthy) keeps its confidence: a doubt about the speed
    puts the fault's name in doubt, not its presence."""
    named = conf if top != "undetermined" else min(conf, DOUBT_CONFIDENCE)   # nothing to hold: none said
    named, reason = time_base(run.job, run.speed, severity, named, reason)
    named, reason = unit_label(run.job, severity, named, reason)
    named, reason = file_speed(run, named, reason)
    named, reason = mesh_speed(run, named, reason)
    named, reason = gearbox_speed(run, named, reason)
    named, reason = half_line(run, named, reason)
    named, reason = two_x_alone(run, top, named, reason)
    named, reason = gear_unseen(run, named, reason)
    named, reason = unconfirmed_speed(run, named, reason)
    named, reason = half_speed(ev, run.job, named, reason)
    named, reason = factor_rival(run, ev, named, reason)
    named, reason = ball_slip_edge(ev, run.job, top, named, reason)
    named, reason = unstable_call(run.job, top, named, reason)
    named, reason = band_given(ev, run.job, top, named, reason)
    return (conf if top == "undetermined" else named), reason
