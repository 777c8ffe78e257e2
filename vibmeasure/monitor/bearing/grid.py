"""A gearbox's hunting-tooth comb in an envelope spectrum. Two gears' tooth errors repeat together every
hunting-tooth period, and their lines stand every f1 x gcd(z1, z2) / z2 over the whole spectrum, at
random heights; a bearing's comb on those lines is the gearbox's (``on_grid``), where the gear pair is
declared (teeth and ratio, or the ratio measured: ``diagnosis.mating``)."""

from __future__ import annotations

import numpy as np

# Where both gears of a pair are declared (teeth and ratio), that hunting-tooth comb is known: a line
# every f1 x gcd(z1, z2) / z2. Any line of it has lines of it at +-1X (z2 / gcd steps away), so a BPFI
# +-1X triplet can stand on it at any frequency, and its lines' random heights reach p = 1e-12 among
# thousands of such triplets (healthy gearboxes with rough gears, 20 % tooth errors: inner race at 0.99
# for 23/67 at 2400 rpm, 0.68 for 32/71 at 1800, 0.58 for 40/83 at 3600). A comb every one
# of whose standing lines (two or more), its frequency refined, lies within HUNT_TOL of a line of that
# grid is the gearbox's, not the bearing's. A bearing's comb falls on the grid by chance only as often as
# 2 HUNT_TOL over the grid's spacing in lines (at most 25 % for one carrier and its sidebands, where the
# grid is HUNT_MIN_SPACING lines; a few per cent for two carriers); a finer grid holds every line and
# is not tested. Measured on benchmarks/gearbox.py: no bearing fault under a two-gear mesh had every line
# of its comb within 0.25 line of the grid; the four healthy gearboxes' above (seeds 4-7 of 3-8) did.
HUNT_TOL = 0.25          # lines (bins)
HUNT_MIN_SPACING = 2.0   # lines (bins)
# A weak line's refined frequency wanders: lines of the grid 8-13 dB over their floor read up to 0.30
# line off it (rough 40/83 and 32/71 gearboxes at 30 dB, 20 % tooth errors: four-line combs called ball
# at 0.52 and inner race at 0.67 with every line 0.02-0.30 line from the grid). A comb of n lines falls
# on a grid of s lines by chance as often as (2 tol / s)^n; the tolerance widens up to HUNT_TOL_MAX
# where that chance stays under HUNT_CHANCE (three or more lines on a coarse grid), never under HUNT_TOL.
HUNT_TOL_MAX = 0.35
HUNT_CHANCE = 0.01


def grid_tolerance(n: int, spacing_lines: float) -> float:
    """The tolerance (lines) for n lines on a grid of ``spacing_lines`` lines: HUNT_TOL, widened up to
    HUNT_TOL_MAX while the chance (2 tol / spacing)^n stays under HUNT_CHANCE."""
    return float(min(HUNT_TOL_MAX, max(HUNT_TOL, 0.5 * spacing_lines * HUNT_CHANCE ** (1.0 / n))))


def on_grid(ses, hz: list, spacing: float | None) -> bool:
    """Whether every one of the lines ``hz`` (two or more; each refined by a parabola through the log power
    of its peak in the spectrum ``ses``) lies within ``grid_tolerance`` lines of a grid of ``spacing`` Hz; never
    where the grid is finer than HUNT_MIN_SPACING lines (it would hold every line)."""
    df = float(ses.freq[1])
    if spacing is None or spacing < HUNT_MIN_SPACING * df or len(hz) < 2:
        return False
    P = ses.amp[: ses.n_valid].astype(float) ** 2
    tol = grid_tolerance(len(hz), spacing / df)
    for f in hz:
        i = int(round(f / df))
        if not 2 <= i < P.size - 2:
            return False
        j = i - 1 + int(np.argmax(P[i - 1: i + 2]))
        a, b, c = np.log(np.maximum(P[j - 1: j + 2], 1e-300))
        den = a - 2 * b + c
        fp = (j + (0.5 * (a - c) / den if den < 0 else 0.0)) * df
        if abs(fp - round(fp / spacing) * spacing) > tol * df:
            return False
    return True
