"""Step: the bearing families, from the statistical test of monitor/bearing over every channel (never
gated by severity), as table rows with their notes; and what the plots need of it."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..bearing import FAMILIES, bearing_evidence
from ..bearing.cage import _cage_stands
from ..bearing.spectra import _limits
from .doubts import file_disputes
from .job import MAX_RPM, MIN_REVOLUTIONS
from .lines import TOP_CONFIDENCE, _row
from .speed import SPEED_SEARCH, Run, _bearing_contradiction, _confirmed

if TYPE_CHECKING:   # for annotations only
    from .job import Job


# --- bearings ---------------------------------------------------------------------------------------

def _bearing_rows(job: Job, f1: float, speed: dict):
    """One row per bearing family from the statistical test over every channel; the evidence."""
    if job.bearing is None:
        return [], None
    ev = _evidence(job, f1, f1 / speed.get("fs_ratio", 1), speed["estimated_rpm"] is not None, SPEED_SEARCH,
                   _confirmed(speed))
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


def _evidence(job: Job, f1: float, shaft: float, f1_known: bool, speed_search, speed_confirmed: bool):
    """The bearing test over every channel at shaft speed f1 (``bearing_evidence``)."""
    # glitches at a fixed interval of samples stand at a fixed frequency only while the record keeps its
    # sampling (after angular resampling the repaired comb smears)
    glitch = () if "order_tracked" in job.flags else tuple(sorted(
        {job.fs / f["spike_interval_samples"] for f in job.quality.values() if "spike_interval_samples" in f}))
    return bearing_evidence(job.signals, job.fs, f1, job.bearing.frequencies(f1), job.bearing.n_balls,
                            band=job.band, shaft_hz=shaft, f1_known=f1_known, whitening=job.prewhitening,
                            artefact_hz=glitch, speed_search=speed_search, speed_confirmed=speed_confirmed,
                            smeared_ball=not ("speed_varies" in job.flags and "order_tracked" not in job.flags),
                            other_shafts_hz=_other_shafts(job, shaft))


def file_speed_rows(run: Run, rows: list, ev) -> list:
    """Where the speed the file states disputes the declared one (``doubts.file_disputes``: no tachometer
    or 1X line settles which is right), the bearing test is run again at the file's speed. Every bearing
    line was put where the declared speed says. When the two speeds' answers differ (the most confident
    family each would call; at the declared speed none called, at the file's speed a family found), the
    record reads one fault at one speed and another at the other: no bearing fault is named, the
    families found at the file's speed count against "none" by their p-value, and the answer says so
    (``job.at_file_rpm``, ``doubts.file_speed``). MFPT's outer-race record declared 1.2 x the 1500 rpm
    its file states read as ball (p = 1e-27, held at 0.45): at the file's speed it reads as outer race.
    Where both give the same answer, or the file's speed would call none, the declared speed's answer
    stands (held by the doubt)."""
    job = run.job
    if ev is None or job.bearing is None or not file_disputes(run):
        return rows
    f_file = job.file_rpm / 60.0
    # a speed the record could not be diagnosed at, had it been declared, is not tried (flagged all the same)
    if job.file_rpm > MAX_RPM or f_file * job.a.size / job.fs < MIN_REVOLUTIONS:
        return rows
    other = _evidence(job, f_file, f_file, False, None, False)
    fams = {n: s for n, s in other.families.items() if n in FAMILIES and s["found"]}
    found = {n: float(s["p_value"]) for n, s in sorted(fams.items(), key=lambda kv: -kv[1]["confidence"])}
    job.at_file_rpm.update(found)
    called = {r["fault"]: r["confidence"] for r in rows if r["fault"] in FAMILIES and r["confidence"] >= TOP_CONFIDENCE}
    # the answer each speed gives: its most confident family (at the file's speed, one it would call)
    there_top = next((n for n in found if fams[n]["confidence"] >= TOP_CONFIDENCE), None)
    here_top = max(called, key=called.get) if called else None
    if not found or there_top == here_top or (there_top is None and here_top is not None):
        return rows
    there = ", ".join(f"{n} (p = {p:.2g})" for n, p in found.items())
    for r in rows:
        name, old = r["fault"], r.get("not_called")
        if name in found:
            # its p is the file's speed's: what the record holds, wherever the speed is
            r["not_called"] = "; ".join(filter(None, [
                f"found at the {job.file_rpm:g} rpm the file states (p = {found[name]:.2g}), which disputes the "
                f"declared {job.rpm:g} rpm", f"at the declared speed: {old}" if old else None]))
            r["p_value"] = min(float(r["p_value"]), found[name])
            r["log10_p"] = float(np.log10(max(r["p_value"], 1e-300)))
        elif name in called:
            r["not_called"] = (f"called at the declared {job.rpm:g} rpm only: the {job.file_rpm:g} rpm the file "
                               f"states disputes it, and there the bearing test finds {there}")
        else:
            continue
        r["confidence"] = 0.0
    return rows


def _other_shafts(job: Job, shaft: float) -> tuple:
    """The mating shaft's speed where a gear with its ratio is given (its harmonics are claimed)."""
    gear = job.gear
    return () if gear is None or gear.mating_shaft_ratio is None else (shaft * gear.mating_shaft_ratio,)


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
    rows, ev = _bearing_rows(run.job, run.f1, run.speed) if not contradicted else ([], None)
    if ev is not None and ev.speed_scan is not None:
        _bearing_contradiction(run.job, run.speed, run.f1, ev.speed_scan)
        contradicted = True
    return rows, ev, contradicted
