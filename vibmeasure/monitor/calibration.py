"""Calibration of the diagnosis' confidence: raw evidence score -> probability that the answer is right.

``diagnose`` first scores its answer: a bearing call by its p-value's posterior, a shaft-order call by
its evidence ramp, "none" by the product of (1 - score) over every family. Those scores rank answers
well but are not probabilities: on the synthetic benchmark, "none" answers scored 0.5-0.8 were all
wrong (a weak resonance at -10 dB) and fault calls scored 0.7-0.8 right half the time.

The map from score to probability is learnt by isotonic regression (pool-adjacent-violators), one
map per answer: each fault name; answers the calibration set never gives (electrical) use their
group's pooled map ("shaft", "bearing"). A "none" with a bearing given has its score's parts
(shaft-order, gear, bearing) mapped apart (NONE_SHAFT, NONE_GEAR, NONE_BEARING) and multiplied; with
no gear declared the gear part is not looked for and left out. The maps are learnt
once with the bearing given and once without it (prefix UNCHECKED: there a "none" also stands for
every bearing fault it could not see). ``benchmarks/calibrate_diagnosis.py`` learns them on synthetic
machines the benchmark does not use and writes ``data/diagnosis_calibration.csv``. Each map is
monotone, so the answers keep their order; each pooled block's rate carries a Beta(1, 1) prior, so a
block of a few answers never says 0 or 1. The probabilities hold for the calibration set's mix: ten
kinds of machine in equal numbers (the nine of the benchmark, one healthy among them, and a healthy
two-gear gearbox with random tooth errors) at SNR -10, 0 and 10 dB; the bearing part of a
"none" (NONE_BEARING) is learnt on those and on the same kinds at -15 dB, the edge of bearing-fault
detection. At -10 dB and above the synthetic bearing faults always show, so a map learnt there alone
had never seen a "none" left beside a bearing family's near miss and gave it 0.99 (CWRU fan-end B021_0
and B014_1, ball faults whose ball comb stops at p = 0.0011 and 0.0016); at -15 dB such a "none" hid a
bearing fault every time, and the map now says 0.01 and 0.57 there. On a fleet where most machines are
healthy a "none" is right more often than it says; a fault the envelope cannot show at all (most ball
faults of the CWRU fan-end set, whose families stay at p = 1) still leaves a confident "none": no map
of the evidence can see it.
"""

from __future__ import annotations

import csv
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError, VibMeasureError

__all__ = ["calibrated", "fit_isotonic", "UNCHECKED", "NONE_SHAFT", "NONE_GEAR", "NONE_BEARING"]

UNCHECKED = "bearing not checked:"   # prefix of the maps learnt without a bearing (bearing faults unseen)
# "none" with a bearing: its score's parts (shaft-order, gear, bearing) are mapped on their own, each to
# the chance that no fault of its kind hides behind the answer, and multiplied. One map of their product
# could not tell a healthy machine with a marginal bearing comb (p ~ 0.002) from a buried resonance: both
# scored 0.75, and such answers were right 7 % of the time. Nor can one map of shaft orders and gear:
# a gear held at 0.45 (its residual between the surrogates' 95th and 99.5th percentiles) is common on a
# healthy gearbox's random tooth errors, where a shaft-order score of 0.45 was a fault every time.
NONE_SHAFT, NONE_GEAR, NONE_BEARING = "none|shaft", "none|gear", "none|bearing"
TABLE = Path(__file__).resolve().parents[1] / "data" / "diagnosis_calibration.csv"


def fit_isotonic(score, right, *, prior: float = 1.0):
    """Monotone (non-decreasing) map from score to the rate of right answers.

    ``score`` and ``right`` (bool) of N answers. Pool-adjacent-violators on the answers sorted by
    score; each pooled block's rate is (k + prior) / (n + 2 prior), then pooled again where that prior
    broke the order. Returns (knots, rates) for ``np.interp``: each block's rate holds from its lowest
    to its highest score (a step where the data change), with straight lines across the gaps between
    blocks. Below the lowest score seen the data say nothing, and the map falls linearly to (0, 0): a
    score never gains probability where no answer was calibrated. Above the highest it is constant.
    """
    s = np.asarray(score, float)
    y = np.asarray(right, float)
    if s.ndim != 1 or s.shape != y.shape or s.size == 0:
        raise ParameterError(f"score and right must be 1-D of the same non-zero length, got {s.shape} and {y.shape}")
    if not np.isfinite(s).all():
        raise ParameterError("score must be finite")
    if not np.isin(y, (0.0, 1.0)).all():
        raise ParameterError("right must hold booleans (or 0/1): whether each answer was right")
    if prior < 0:
        raise ParameterError(f"prior={prior!r} must be >= 0")
    order = np.argsort(s, kind="stable")
    s, y = s[order], y[order]
    # equal scores are one observation of the same rate: pool them first
    u, start = np.unique(s, return_index=True)
    n = np.diff(np.append(start, s.size)).astype(float)
    k = np.add.reduceat(y, start)
    blocks = _pav([[a, a, b, c] for a, b, c in zip(u, k, n)])
    # the prior can break the order between a small block and a large one: pool those again
    blocks = _pav([[lo, hi, (sy + prior) / (w + 2 * prior) * w, w] for lo, hi, sy, w in blocks])
    knots, rates = [], []
    for lo, hi, sy, w in blocks:
        knots += [lo] if hi == lo else [lo, hi]
        rates += [sy / w] * (1 if hi == lo else 2)
    if knots[0] > 0:
        knots, rates = [0.0] + knots, [0.0] + rates
    return np.array(knots, float), np.array(rates, float)


def _pav(blocks):
    """Pool adjacent violators over blocks [lowest score, highest score, sum of right, weight] in
    score order, until sum of right / weight does not decrease."""
    out = []
    for blk in blocks:
        out.append([float(v) for v in blk])
        while len(out) > 1 and out[-2][2] / out[-2][3] >= out[-1][2] / out[-1][3]:
            lo, hi, sy, w = out.pop()
            out[-1][1] = hi
            out[-1][2] += sy
            out[-1][3] += w
    return out


@lru_cache(maxsize=1)
def _table(path: Path = TABLE) -> dict:
    """The shipped maps {kind: (knots, rates)}; a missing or damaged table is named, not a traceback."""
    maps: dict = {}
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            for row in csv.DictReader(line for line in fh if not line.startswith("#")):
                maps.setdefault(row["kind"], []).append((float(row["score"]), float(row["probability"])))
    except (OSError, KeyError, TypeError, ValueError) as exc:
        raise VibMeasureError(f"the confidence calibration table {path} is missing or damaged ({exc}); reinstall "
                              "vibmeasure or rewrite it with benchmarks/calibrate_diagnosis.py") from None
    out = {k: (np.array([a for a, _ in v]), np.array([b for _, b in v])) for k, v in maps.items()}
    for k, (knots, rates) in out.items():
        if not (np.all(np.diff(knots) > 0) and np.all((rates >= 0) & (rates <= 1))):
            raise VibMeasureError(f"the confidence calibration table {path} is damaged: the map {k!r} is not "
                                  "increasing scores to probabilities in [0, 1]")
    return out


def calibrated(answer: str, score: float, group: str) -> float:
    """Probability that ``answer`` ("none" or a fault name) given with this raw score is right, from
    the shipped calibration table; an answer it has no map for uses its ``group``'s ("shaft",
    "bearing")."""
    if not 0.0 <= float(score) <= 1.0:   # also rejects NaN
        raise ParameterError(f"score={score!r} must be a finite evidence score in [0, 1]")
    table = _table()
    if answer not in table and group not in table:
        raise ParameterError(f"no calibration for answer={answer!r} nor its group={group!r} in {TABLE.name}")
    knots, rates = table[answer] if answer in table else table[group]
    return float(np.interp(float(score), knots, rates))
