"""Step: the decision. The top fault, its confidence calibrated on synthetic machines
(monitor/calibration.py) and its reason; a "none" names the strongest candidate."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..bearing import FAMILIES
from ..bearing.lines import _log_p_to_conf
from ..calibration import NONE_BEARING, NONE_GEAR, NONE_SHAFT, UNCHECKED, calibrated
from .bearings import CAGE_NOTE
from .lines import TOP_CONFIDENCE
from .shaft import SHAFT_FAULTS

if TYPE_CHECKING:   # for annotations only
    from .job import Job


# --- decision ---------------------------------------------------------------------------------------

LEVEL_GATED = ("unbalance", "misalignment", "looseness", "resonance", "electrical")


def _unweighed(rows) -> tuple | None:
    """Without the data's unit the ISO level is unknown, and the level-gated faults (LEVEL_GATED) are
    patterns only: every machine has shaft harmonics, and their level is what tells a fault. Measured on
    the 57 development records read without a unit, the patterns alone named looseness on 4 bearing-fault
    records (B007_1 at 1.00), against none with unit="g"; and the confidence maps were learnt on gated
    scores. Such rows keep their pattern score (``pattern``, which a "none" still weighs) but are not
    called. Returns (strongest pattern, its score) or None."""
    best = None
    for r in rows:
        if r["fault"] in LEVEL_GATED:
            r["pattern"] = r["confidence"]
            if r["confidence"] > 0:
                r["note"] = "not called, the data's unit is unknown: " + r["note"]
                if best is None or r["confidence"] > best[1]:
                    best = (r["fault"], r["confidence"])
            r["confidence"] = 0.0
    return best


def _decide(table, job: Job, weak: bool):
    """The top fault: the most confident shaft-order or bearing fault at TOP_CONFIDENCE or more and not
    tied with another of its own kind; else "none" when the machine is healthy with a probability of
    TOP_CONFIDENCE or more, and "undetermined" (probably a fault that cannot be named) below it, both
    with the reason and the strongest candidates. The last item returned is the probability that the
    machine is healthy (``p_healthy``)."""
    s_shaft, s_gear, s_bear = _p_none(table)
    if job.bearing is not None and not weak:
        # each part mapped to the chance that no fault of its kind was missed
        p_healthy = calibrated(NONE_SHAFT, s_shaft, NONE_SHAFT) * calibrated(NONE_BEARING, s_bear, NONE_BEARING)
        if s_gear is not None:
            p_healthy *= calibrated(NONE_GEAR, s_gear, NONE_GEAR)
    else:   # no bearing, or no channel with a band to demodulate: the bearing side says little
        p_healthy = calibrated(UNCHECKED + "none", s_shaft * (s_gear or 1.0) * s_bear, UNCHECKED + "none")
    ranked = table.assign(_bearing=table.fault.isin(list(FAMILIES)))
    # a bearing family that passed its test outranks shaft-order scores: it is the specific finding
    ranked = ranked.sort_values(["_bearing", "confidence"], ascending=False)
    calls = ranked[(ranked.confidence >= TOP_CONFIDENCE) & (ranked.fault != "bearing_cage")]
    ranked = ranked.sort_values("confidence", ascending=False)
    checked = ("; shaft-order and bearing faults not checked" if "speed_contradicted" in job.flags else
               "" if job.bearing is not None else "; bearing faults not checked (no bearing given)")
    if len(calls):
        best = calls.iloc[0]
        # a rival of the same kind close behind (even under TOP_CONFIDENCE: two bearing families that
        # split the spectra's votes near half and half) makes the answer a tie
        rivals = ranked[(ranked.fault != best.fault) & (ranked.fault != "bearing_cage")]
        kin = [r for _, r in rivals.iterrows() if (r.fault in FAMILIES) == (best.fault in FAMILIES)]
        if not kin or best.confidence - kin[0].confidence >= 0.15:
            top, score = str(best.fault), float(best.confidence)
            kind = "bearing" if top in FAMILIES else "shaft"
            pre = "" if job.bearing is not None else UNCHECKED
            conf = calibrated(pre + top, score, pre + kind)
            also = [str(r.fault) for _, r in calls.iloc[1:].iterrows() if r.fault != top]
            reason = f"{top}: {best.note} (confidence {conf:.2f}, score {score:.2f})"
            if also:
                reason += f"; also scored above {TOP_CONFIDENCE}: {', '.join(also)}"
            channel = best.get("channel") if top in FAMILIES else job.primary
            # the fault called and a healthy machine exclude each other
            return (top, conf, reason + checked, also, channel or job.primary, (kind, score, None),
                    min(p_healthy, 1.0 - conf))
        why = f"{best.fault} and {kin[0].fault} are equally likely"
    elif "speed_contradicted" in job.flags:
        why = "the declared speed is contradicted"
    else:
        why = "no fault family stands out"
    cand = ranked[ranked.fault != "bearing_cage"].iloc[0]
    bear = table[table.fault.isin(list(FAMILIES))]
    strongest = ""
    if len(bear):
        b = bear.sort_values("log10_p").iloc[0]
        strongest = f"; strongest bearing candidate {b.fault} p = {b.p_value:.2g}"
        if isinstance(b.get("not_called"), str):
            strongest += f" (not called: {b.not_called})"
    strongest += _cage_standing(table)
    p_none = s_shaft * (s_gear or 1.0) * s_bear
    parts = {"shaft": s_shaft, "bearing": s_bear} | ({} if s_gear is None else {"gear": s_gear})
    top_score = (f"strongest candidate {cand.fault} at score {cand.confidence:.2f}" if cand.confidence >= 0.005
                 else "every family scored 0.00")
    # "none" only where the machine is more likely healthy than not: below, "none, confidence 0.1" would
    # read "no fault, barely sure" where it means "probably a fault this test cannot name"
    top = "none" if p_healthy >= TOP_CONFIDENCE else "undetermined"
    conf = p_healthy if top == "none" else 1.0 - p_healthy
    said = (f"none: healthy with probability {p_healthy:.2f}" if top == "none" else
            f"undetermined: no fault named, yet the machine is healthy with probability only {p_healthy:.2f}")
    reason = (f"{said}; {why}{checked}" if "speed_contradicted" in job.flags else
              f"{said}; {why}; {top_score}{strongest}{checked}")
    return (top, conf, reason, [], job.primary, ("none", p_none, parts), p_healthy)


def candidates(table, n: int = 3) -> list[dict]:
    """The ``n`` strongest fault families of an answer that names none: shaft-order families by their
    score, bearing families by their p-value (the cage left out: it is reported, never called)."""
    rows = table[table.fault != "bearing_cage"]
    out = []
    for _, r in rows.iterrows():
        p = r.get("p_value") if r.fault in FAMILIES else None
        weight = float(r.confidence) if p is None or p != p else max(float(r.confidence), 1.0 - float(p))
        out.append({"fault": str(r.fault), "score": float(r.confidence),
                    "p_value": None if p is None or p != p else float(p), "_w": weight})
    out.sort(key=lambda c: -c["_w"])
    return [{k: v for k, v in c.items() if k != "_w"} for c in out[:n] if c["_w"] > 0.005]


def _cage_standing(table) -> str:
    """What a "none" says of a cage comb that stands out. The envelope modulated at the cage's rate is
    reported, never called (a healthy bearing can carry it: benchmarks/diagnosis.py, "healthy, strong
    cage-rate modulation"); but a rolling-element defect rides with the cage through the load zone and
    makes it too, so a "none" beside it names it. On the 57 development recordings the comb stands out
    in 13, all fault records; 4 of them read "none", all ball faults whose 2 x BSF lines do not stand
    out (fan-end B007_2, B014_0, B014_1 and drive-end B007_0, at p = 5e-6 to 1e-62)."""
    cage = table[(table.fault == "bearing_cage") & (table.note == CAGE_NOTE)]
    if not len(cage):
        return ""
    c = cage.iloc[0]
    return (f"; the cage comb stands out (FTF harmonics, p = {c.p_value:.2g} in {c.channel!r}): the envelope is "
            f"modulated at the cage's rate, as a defect on a rolling element (which rides with the cage) or "
            f"an uneven cage or load makes it; not called on its own: look for 2 x BSF with +-FTF sidebands "
            f"in a longer or later record")


def _p_none(table) -> tuple[float, float | None, float]:
    """The raw score of "none" in three parts, (shaft-order, gear, bearing): the product of 1 - score
    over the shaft-order families, 1 - the gear's score (None with no gear declared: no gear row), and
    the product over the bearing families of 1 - their posterior from the p-value. The score of "none"
    is their product; each part is calibrated on its own (monitor/calibration.py)."""
    sel = table[table.fault.isin(SHAFT_FAULTS) & (table.fault != "gear_mesh")]
    # a pattern not called for want of the unit still speaks against "none" (_unweighed)
    shaft = (sel.pattern.fillna(sel.confidence) if "pattern" in sel else sel.confidence).to_numpy(float)
    s_shaft = float(np.prod(1 - shaft)) if shaft.size else 1.0
    gear = table.confidence[table.fault == "gear_mesh"].to_numpy(float)
    s_gear = float(1 - gear.max()) if gear.size else None
    bear = table[table.fault.isin(list(FAMILIES))]
    s_bear = 1.0
    if len(bear):
        c = _log_p_to_conf(bear.log10_p.to_numpy(float) * np.log(10))
        s_bear = float(np.prod(1 - c))
    return s_shaft, s_gear, s_bear
