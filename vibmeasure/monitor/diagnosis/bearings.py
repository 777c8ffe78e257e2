"""Step: the bearing families, from the statistical test of monitor/bearing over every channel (never
gated by severity), as table rows with their notes; and what the plots need of it."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..bearing import FAMILIES, bearing_evidence
from ..bearing.cage import _cage_stands
from ..bearing.spectra import _limits
from ..bearing.rules import ALPHA
from ..bearing.smeared import SMEAR_HUMP_P, SMEAR_HUMPS
from ...core.errors import ParameterError
from .doubts import file_disputes, shaft_elsewhere
from .job import MAX_RPM, MIN_REVOLUTIONS, _check_nyquist
from .lines import TOP_CONFIDENCE, _row
from .speed import SPEED_NOTED, SPEED_SEARCH, Run, _bearing_contradiction, _confirmed

if TYPE_CHECKING:   # for annotations only
    from .job import Job


# --- bearings ---------------------------------------------------------------------------------------

def record_evidence(job: Job, run: Run, speed_search: float | None = SPEED_SEARCH):
    """The bearing test over ``job``'s channels at the run's speed (``_evidence``); ``speed_search`` None
    leaves out the scan of other speeds. The shaft combs standing elsewhere (``doubts.shaft_elsewhere``)
    claim every harmonic of theirs: whichever speed is true, they are a shaft's lines (CWRU fan-end
    OR007@12_0 with its sampling rate declared twice too high took the true shaft's 2X, 3X, 5X, 7X for
    BPFI +-1X)."""
    speed, f1 = run.speed, run.f1
    elsewhere = tuple(k * run.job.rpm / 60.0 for k in shaft_elsewhere(run))
    return _evidence(job, f1, f1 / speed.get("fs_ratio", 1), speed["estimated_rpm"] is not None, speed_search,
                     _confirmed(speed), elsewhere)


def _bearing_rows(run: Run):
    """One row per bearing family from the statistical test over every channel; the evidence."""
    job = run.job
    if job.bearing is None:
        return [], None
    ev = record_evidence(job, run)
    rows = []
    for name, s in ev.families.items():
        lines = [f"{ln['hz']:.1f} Hz {ln['db']:.0f} dB" for ln in s["lines"] if ln["r"] >= 6.0]
        sm = s.get("smeared")
        if name == "bearing_cage":
            note = CAGE_NOTE if s["found"] else "no cage-rate comb"
        elif sm is not None and sm["found"]:
            humps = ", ".join(f"{ln['hz']:.1f} Hz {ln['db']:+.1f} dB" for ln in s["lines"])
            note = (f"{s['model']} at slip {s['slip'] * 100:+.2f} %: no line comb passes, but humps stand at 2 x BSF "
                    f"and its harmonics ({humps}: mean over each hump's bins, the races' lines left out): a ball's "
                    f"spin wanders and spreads its lines; p = {s['p_value']:.2g}, best decoy comb p = "
                    f"{np.exp(sm['decoy_log_p']):.2g}; in {sm['views']} views; {s['preprocessing']} "
                    f"{s['band_hz'][0]:.0f}-{s['band_hz'][1]:.0f} Hz in {s['channel']!r}")
        elif s["p_value"] < 1.0:
            note = (f"{s['model']} at slip {s['slip'] * 100:+.2f} %: {len(lines)} line(s) above the floor "
                    f"({', '.join(lines[:4])}); p = {s['p_value']:.2g} over {ev.n_spectra} spectra; "
                    f"{s['preprocessing']} {s['band_hz'][0]:.0f}-{s['band_hz'][1]:.0f} Hz in {s['channel']!r}; "
                    f"claimed first in {s['votes']} spectra")
        else:
            note = "no comb in any envelope spectrum"
        if sm is not None and not sm["found"] and sm["log_p"] < np.log(ALPHA) and sm["humps"] < SMEAR_HUMPS:
            note += (f"; the smeared comb's humps at 2 x BSF x 1-3 (p = {np.exp(sm['log_p']):.2g}) are not "
                     f"called: without its loudest line no hump stands at p < {SMEAR_HUMP_P:g} (a sharp line "
                     "inside a hump, another shaft's harmonic, is no smear)")
        if name != "bearing_cage" and s.get("cage_floor_db") is not None and not (sm is not None and sm["found"]):
            note += (f"; its lines are also harmonics of the cage comb, which stands up to "
                     f"{s['cage_floor_db']:.0f} dB there: they count only by what they stand above it")
        rows.append(_row(name, s["expected_hz"], s["found_hz"], s["amplitude"], s["evidence_db"], s["confidence"],
                         note, p_value=s["p_value"], log10_p=s["log10_p"], statistic=s["statistic"],
                         n_terms=s["n_terms"], decoy_p=s.get("decoy_p"), slip=s["slip"], channel=s["channel"],
                         preprocessing=s["preprocessing"], band_hz=s["band_hz"], votes=s["votes"], views=s.get("views"),
                         not_called=s.get("not_called"),
                         harmonics=[{k: ln[k] for k in ("harmonic", "sideband", "hz", "db")} for ln in s["lines"]]))
    return rows, ev


def _evidence(job: Job, f1: float, shaft: float, f1_known: bool, speed_search, speed_confirmed: bool,
              elsewhere: tuple = ()):
    """The bearing test over every channel at shaft speed f1 (``bearing_evidence``); the shafts at
    ``elsewhere`` (Hz) claim every harmonic of theirs."""
    # glitches at a fixed interval of samples stand at a fixed frequency only while the record keeps its
    # sampling (after angular resampling the repaired comb smears)
    glitch = () if "order_tracked" in job.flags else tuple(sorted(
        {job.fs / f["spike_interval_samples"] for f in job.quality.values() if "spike_interval_samples" in f}))
    return bearing_evidence(job.signals, job.fs, f1, job.bearing.frequencies(f1), job.bearing.n_balls,
                            band=job.band, shaft_hz=shaft, f1_known=f1_known, whitening=job.prewhitening,
                            artefact_hz=glitch, speed_search=speed_search, speed_confirmed=speed_confirmed,
                            smeared_ball=not ("speed_varies" in job.flags and "order_tracked" not in job.flags),
                            other_shafts_hz=_other_shafts(job, shaft), shaft_combs_hz=elsewhere,
                            hunting_hz=_hunting(job, shaft), time_base_doubted=shaft != f1 or bool(elsewhere))


def other_speed_rows(run: Run, rows: list, ev) -> list:
    """Where a doubt names another shaft speed the record may hold, the bearing test is run again there:
    the file's own speed where it disputes the declared one (``doubts.file_disputes``); the speed a
    time base r x the declared puts the shaft at (``speed_inconsistent``: f1 / r, and f1 / 2 where r is
    4, whose lines hold a factor 2's); a multiple of the declared speed where a shaft comb stands and no
    1X confirms the declared one (``doubts.shaft_elsewhere``). Every bearing line was put where the speed
    used says. When another speed's answer differs from it (the most confident family each would call,
    the other speed's of comparable significance: RIVAL_LOG_SHARE; at the speed used none called, at
    the other a family found), the record reads one fault at one speed and another at the other: no
    bearing fault is named, every family found at another speed counts against "none" by its smallest
    p, and the doubt's reason names them (``job.at_other_speeds``, also ``diag.speed["other_speeds"]``).
    Where every other speed gives the same answer, calls none, or reads far less significantly, the
    answer stands (held by its doubt). MFPT's outer-race record declared 1.2 x the 1500 rpm its file
    states read as ball (p = 1e-27, held at 0.45): at the file's speed it reads as outer race. CWRU
    fan-end OR007@6_1 read at half its sampling rate took the true shaft's harmonics for BPFI +-1X
    (inner race, held): at the true speed they are its outer race's.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, fs=12000.0, duration=4.0, seed=1)
    >>> told = vm.Record.from_array(rec.data, fs=rec.fs, names=list(rec.names), unit="g", meta={"rpm": 1797})
    >>> d = vm.diagnose(told, rpm=1.2 * 1797, bearing="6205-2RS")   # the file states 1797 rpm
    >>> d.top, d.extras["candidates"][0]["fault"]
    ('undetermined', 'bearing_outer_race')
    """
    job = run.job
    if ev is None or job.bearing is None:
        return rows
    called = {r["fault"]: r["confidence"] for r in rows if r["fault"] in FAMILIES and r["confidence"] >= TOP_CONFIDENCE}
    here_top = max(called, key=called.get) if called else None
    here_p = next((float(r["p_value"]) for r in rows if r["fault"] == here_top), 1.0)
    seen: dict = {}   # family -> (smallest p at another speed, where)
    disputed = False
    for hz, kind, where in _other_speeds(run):
        other = _evidence(job, hz, hz, False, None, False)
        fams = {n: s for n, s in other.families.items() if n in FAMILIES and s["found"]}
        found = {n: float(s["p_value"]) for n, s in sorted(fams.items(), key=lambda kv: -kv[1]["confidence"])}
        job.at_other_speeds.append({"rpm": 60 * hz, "why": kind, "where": where, "found": found})
        for name, p in found.items():
            if p < seen.get(name, (1.0, ""))[0]:
                seen[name] = (p, where)
        # the answer each speed gives: its most confident family (at the other speed, one it would call,
        # or a family found there at least as significant as the answer here); against an answer here,
        # only one of comparable significance (RIVAL_LOG_SHARE) disputes it
        there_top = next((n for n in found if fams[n]["confidence"] >= TOP_CONFIDENCE), None)
        if there_top is None and here_top is not None and found and min(found.values()) <= here_p:
            there_top = min(found, key=found.get)
        if here_top is not None and there_top is not None and not _rivals(found[there_top], here_p):
            there_top = None
        disputed |= bool(found) and there_top != here_top and not (there_top is None and here_top is not None)
    if job.at_other_speeds:
        run.speed["other_speeds"] = job.at_other_speeds   # what each speed tried reads, in diag.speed
    if not disputed:
        return rows
    there = ", ".join(f"{n} at {w} (p = {p:.2g})" for n, (p, w) in seen.items())
    for r in rows:
        name, old = r["fault"], r.get("not_called")
        if name in seen:
            # its p is the smallest at any speed: what the record holds, wherever the speed is
            p, where = seen[name]
            r["not_called"] = "; ".join(filter(None, [
                f"found at {where} (p = {p:.2g}); the speeds tried read different faults",
                f"called at the {60 * run.f1:.0f} rpm used" if name in called else
                f"at the {60 * run.f1:.0f} rpm used: {old}" if old else None]))
            r["p_value"] = min(float(r["p_value"]), p)
            r["log10_p"] = float(np.log10(max(r["p_value"], 1e-300)))
        elif name in called:
            r["not_called"] = (f"called at the {60 * run.f1:.0f} rpm used only: the record's lines dispute that "
                               f"speed, and the bearing test finds {there}")
        else:
            continue
        r["confidence"] = 0.0
    return rows


# A family another speed reads disputes the answer at the speed used where its log p is at least this
# share of the answer's: a comb at k x the declared speed is also the kX, 2kX, ... of a shaft at the
# declared speed whose 1X is weak, and a wrong speed's dense sideband models fit strong lines by
# chance (MFPT's inner race quantised to 8 bits, p 4e-60, against an outer race at 4 x its speed, p
# 4e-23: 0.38); a right speed's comb rivals the wrong one's (CWRU IR007_1 at 4 x fs: ball 2e-30 at the
# declared speed, inner race 1e-28 at the comb's: 0.94; OR007@6_1 at half its rate: 0.74)
RIVAL_LOG_SHARE = 0.5


def _rivals(p_there: float, p_here: float) -> bool:
    """Whether a family found at another speed with p_there is as significant as an answer with p_here
    (RIVAL_LOG_SHARE of its log p, both floored at 1e-300)."""
    return np.log(max(p_there, 1e-300)) <= RIVAL_LOG_SHARE * np.log(max(p_here, 1e-300))


def _other_speeds(run: Run) -> list:
    """(shaft Hz, kind, where said) of every other speed a doubt names (``other_speed_rows``) at which the
    record could have been diagnosed, had it been declared (enough turns, the bearing's lines under
    Nyquist)."""
    job, speed = run.job, run.speed
    out = []
    if file_disputes(run):
        out.append((job.file_rpm / 60.0, "file", "the file's speed"))
    r = speed.get("fs_ratio", 1)
    # from the 1X taken and from the declared speed: a 1X found in a spectrum read at the wrong rate may
    # be another line near the declared speed (CWRU OR007@6_1 at half its rate: a line 3 % off)
    bases = [run.f1] + ([job.rpm / 60.0] if abs(run.f1 / (job.rpm / 60.0) - 1) > SPEED_NOTED else [])
    for q in sorted({r, 2} if r == 4 else {r} - {1}):
        for base in bases:
            hz = base / q
            out.append((hz, "time base", f"{60 * hz:.0f} rpm (a time base {q} x the declared)"))
    for k in shaft_elsewhere(run):
        hz = k * job.rpm / 60.0
        out.append((hz, "comb", f"{60 * hz:.0f} rpm (the shaft comb's)"))
    return [o for o in out if _diagnosable(job, o[0])]


def _diagnosable(job: Job, hz: float) -> bool:
    """Whether the record could be diagnosed at shaft speed hz: under MAX_RPM, MIN_REVOLUTIONS turns in
    it, the bearing's third harmonics under Nyquist (``job._check_nyquist``)."""
    if 60 * hz > MAX_RPM or hz * job.a.size / job.fs < MIN_REVOLUTIONS:
        return False
    try:
        _check_nyquist(job.fs, hz, job.bearing, None)
    except ParameterError:
        return False
    return True


def _other_shafts(job: Job, shaft: float) -> tuple:
    """The mating shaft's speed where a gear with its ratio is given (at ``shaft`` Hz) or found (as measured:
    ``gearbox``): its harmonics are claimed."""
    gear, shaft = _gear_at(job, shaft)
    return () if gear is None or gear.mating_shaft_ratio is None else (shaft * gear.mating_shaft_ratio,)


def _gear_at(job: Job, shaft: float) -> tuple:
    """(gear, its shaft's Hz): the declared gear at ``shaft``, or the pair found at its measured speed
    (the mesh fixes both shafts whatever speed a bearing test supposes), or (None, shaft)."""
    if job.gear is None and job.found_gear is not None:
        return job.found_gear
    return job.gear, shaft


def _hunting(job: Job, shaft: float) -> float | None:
    """The spacing of the gear pair's hunting-tooth comb, shaft x gcd(z1, z2) / z2, where the gear is
    given (or found: ``gearbox``) with a ratio that makes a whole number of teeth on the mating gear."""
    gear, shaft = _gear_at(job, shaft)
    if gear is None or gear.mating_shaft_ratio is None:
        return None
    z2 = gear.teeth / gear.mating_shaft_ratio
    if round(z2) < 1 or abs(z2 - round(z2)) > 1e-3 * z2:
        return None
    return shaft * math.gcd(gear.teeth, round(z2)) / round(z2)


CAGE_NOTE = "cage-rate modulation (FTF comb): common on healthy bearings; not a fault by itself, trend it"


def _narrow_channels(ev, job: Job, f1: float) -> list:
    """Channels whose measured band (below a filter's edge) cannot hold a demodulation band of the
    narrowest width above the shaft-harmonic region: [(channel, top of its band in Hz)]."""
    freqs = job.bearing.frequencies(f1)
    f_lo_full = _limits(job.fs, f1, freqs)[3]
    return [(name, top) for name, top in ev.measured_top_hz.items()
            if _limits(job.fs, f1, freqs, top)[3] < f_lo_full - 1e-9]


def _plot_material(ev, top):
    """The squared-envelope spectrum that carries the top (or strongest) bearing family, with its
    kurtogram, for plot_diagnosis."""
    fams = ev.families
    name = top if top in FAMILIES else min(FAMILIES, key=lambda n: fams[n]["log_p"])
    s = fams[name]
    pick = ev.spectra[0]
    for sp in ev.spectra:
        if sp.channel == s["channel"] and sp.prep == s["preprocessing"] and sp.band == s["band_hz"]:
            pick = sp
            break
    kg = next((sp.kurtogram for sp in ev.spectra if sp.channel in pick.channel.split("+")
               and sp.kurtogram is not None), None)
    cage = pick.results.get("bearing_cage")
    ses = {"freq": pick.freq, "amp": pick.amp, "channel": pick.channel, "preprocessing": pick.prep,
           "band_hz": pick.band, "family": name, "slip": s["slip"], "lines": s["lines"],
           # where the cage comb stands: its fundamental, and the stretches its level was divided from
           "cage_hz": ev.families["bearing_cage"]["expected_hz"] * (1 + cage["slip"])
           if cage is not None and _cage_stands(cage) else None,
           "cage_floor": sorted(pick.cage_floor.values())}
    return {"bearing": {k: {kk: vv for kk, vv in v.items() if kk != "lines"} for k, v in fams.items()},
            "ses": ses, "kurtogram": kg}


def bearing_step(run: Run) -> tuple[list, object, bool]:
    """(rows, evidence, contradicted): the bearing rows unless the speed is contradicted; the bearing's
    own lines standing where another speed puts them contradict it too (``decoys._speed_scan``)."""
    contradicted = "speed_contradicted" in run.job.flags
    rows, ev = _bearing_rows(run) if not contradicted else ([], None)
    if ev is not None and ev.speed_scan is not None:
        _bearing_contradiction(run.job, run.speed, run.f1, ev.speed_scan)
        contradicted = True
    return rows, ev, contradicted
