"""Step: the bearing families, from the statistical test of monitor/bearing over every channel (never
gated by severity), as table rows with their notes; and what the plots need of it."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..bearing import FAMILIES, bearing_evidence
from ..bearing.cage import _cage_stands
from ..bearing.spectra import _limits
from .lines import _row
from .speed import SPEED_SEARCH, Run, _bearing_contradiction, _confirmed

if TYPE_CHECKING:   # for annotations only
    from .job import Job


# --- bearings ---------------------------------------------------------------------------------------

def _bearing_rows(job: Job, f1: float, speed: dict):
    """One row per bearing family from the statistical test over every channel; the evidence."""
    if job.bearing is None:
        return [], None
    freqs = job.bearing.frequencies(f1)
    shaft = f1 / speed.get("fs_ratio", 1)
    # glitches at a fixed interval of samples stand at a fixed frequency only while the record keeps its
    # sampling (after angular resampling the repaired comb smears)
    glitch = () if "order_tracked" in job.flags else tuple(sorted(
        {job.fs / f["spike_interval_samples"] for f in job.quality.values() if "spike_interval_samples" in f}))
    ev = bearing_evidence(job.signals, job.fs, f1, freqs, job.bearing.n_balls, band=job.band,
                          shaft_hz=shaft, f1_known=speed["estimated_rpm"] is not None, whitening=job.prewhitening,
                          artefact_hz=glitch, speed_search=SPEED_SEARCH, speed_confirmed=_confirmed(speed),
                          smeared_ball=not ("speed_varies" in job.flags and "order_tracked" not in job.flags),
                          other_shafts_hz=_other_shafts(job, shaft))
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
