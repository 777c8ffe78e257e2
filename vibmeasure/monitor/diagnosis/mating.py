"""Step: the mating shaft, measured where a gear is declared without its ratio. The mesh is a whole
order of both shafts: the mating gear's z2 teeth turn at mesh / z2, and its shaft puts a 1X, a 2X and
sidebands at +-1..3 x its speed around the mesh's harmonics. The tooth count whose places (14: its 1X,
2X, and the sidebands around mesh harmonics 1 and 2) hold the most lines, each within MATING_TOL of
where that count puts it, clearly ahead of every other count, gives the ratio, and the steps after this
one treat it as declared: the mating shaft's harmonics are its own, not a bearing's, and the gears'
hunting-tooth grid is known."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...models.bearing import Gear
from .lines import LINE_DB, _line
from .speed import Run

MATING_TEETH = range(5, 251)
# Places within MATING_TOL lines of where a tooth count puts them (a line refined by a parabola through
# its log peak): a count one tooth off moves the +-1 sideband by speed / z2, about a line at 6 s; wider
# tolerances let z2 +- 1 tie. Measured on benchmarks/gearbox.py's eight pairs (2-20 % tooth errors, 10
# and 30 dB, 32 records): the true count held 10-14 of the 14 places, every other count at most 13; a
# count chosen only MATING_MARGIN places ahead of the next (a healthy 61/19 gearbox at 30 dB, 10 %
# errors: its hunting-tooth comb fills every place of a count whose speed is a multiple of it, 13 of 14
# against 14) is no measurement.
MATING_TOL = 0.3
MATING_HITS = 10
MATING_MARGIN = 3


def _peak(f, A, logA, hz):
    """(refined frequency, height in dB) of the local peak at most a line from hz, or None."""
    df = f[1]
    i = int(round(hz / df))
    if not 2 <= i < A.size - 2:
        return None
    j = i - 1 + int(np.argmax(A[i - 1:i + 2]))
    a, b, c = logA[j - 1:j + 2]
    den = a - 2 * b + c
    fp = (j + (0.5 * (a - c) / den if den < 0 else 0.0)) * df
    return fp, _line(f, A, fp, 0.6 * df, fp + 5 * df)[2]


def mating_teeth(f, A, mesh_hz: float, teeth: int) -> int | None:
    """The mating gear's tooth count the spectrum (f, A) shows around a mesh at ``mesh_hz`` of a gear of
    ``teeth`` teeth, or None where no count stands clearly ahead (MATING_HITS, MATING_MARGIN)."""
    df, f_shaft = f[1], mesh_hz / teeth
    logA = np.log(np.maximum(A, 1e-300))
    scores = []
    for z2 in MATING_TEETH:
        s = mesh_hz / z2
        # a speed at a harmonic or a half or third of this shaft's is this shaft's comb
        if any(abs(m * s / f_shaft - round(m * s / f_shaft)) * f_shaft < 1.5 * df for m in (1, 2, 3)):
            continue
        places = [s, 2 * s] + [h * mesh_hz + q * s for h in (1, 2) for q in (-3, -2, -1, 1, 2, 3)]
        hits = 0
        for hz in places:
            pk = _peak(f, A, logA, hz) if hz < f[-1] - 5 * df else None
            hits += pk is not None and pk[1] >= LINE_DB and abs(pk[0] - hz) <= MATING_TOL * df
        scores.append((hits, z2))
    if len(scores) < 2:
        return None
    scores.sort(reverse=True)
    (best, z2), (second, _) = scores[0], scores[1]
    return z2 if best >= MATING_HITS and best - second >= MATING_MARGIN else None


def mating_shaft(run: Run) -> Run:
    """The run with the declared gear's ratio measured (``speed["mating_teeth"]``) where the gear is given
    without one and its mesh measured the speed (``speed["mesh_hz"]``, no factor in doubt)."""
    gear, speed = run.job.gear, run.speed
    if gear is None or gear.mating_shaft_ratio is not None or "mesh_hz" not in speed or "mesh_factor" in speed:
        return run
    z2 = mating_teeth(run.f, run.A, speed["mesh_hz"], gear.teeth)
    if z2 is None:
        return run
    speed["mating_teeth"] = z2
    job = dataclasses.replace(run.job, gear=Gear(gear.teeth, mating_shaft_ratio=gear.teeth / z2))
    return dataclasses.replace(run, job=job)
