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
from .lines import LINE_DB
from .speed import Run

MATING_TEETH = range(5, 251)
# Places within MATING_TOL lines of where a tooth count puts them (a line refined by a parabola through
# its log peak, standing LINE_DB over the median of the lines 6 to 60 bins either side): a count one
# tooth off moves the +-1 sideband by speed / z2, about a line at 6 s; wider tolerances let z2 +- 1 tie.
# A count must hold MATING_HITS of the 14 places and MATING_MARGIN more than any other: a healthy 61/19
# gearbox at 30 dB fills with its hunting-tooth comb every place of a count whose speed is a multiple
# of it (13 of 14 against 14). Measured on the eight pairs of benchmarks/gearbox.py, six records each
# (2-20 % tooth errors, 10 and 30 dB): 46 of 48 counts right, none wrong, the two 61/19 at 30 dB not
# measured.
MATING_TOL = 0.3
MATING_HITS = 10
MATING_MARGIN = 3


def place_db(f, A, hz: np.ndarray) -> np.ndarray:
    """For each frequency in hz, the height (dB over its floor, the median of the bins 6 to 60 lines
    either side) of the local peak at most a line away, where it stands LINE_DB and lies within
    MATING_TOL of it (its frequency refined by a parabola through its log peak); 0 elsewhere."""
    df, n = f[1], A.size
    i = np.rint(hz / df).astype(int)
    ok = (i >= 61) & (i < n - 61)
    i = np.where(ok, i, 61)
    j = i - 1 + np.argmax(np.stack([A[i - 1], A[i], A[i + 1]]), axis=0)
    a, b, c = (np.log(np.maximum(A[j + d], 1e-300)) for d in (-1, 0, 1))
    den = a - 2 * b + c
    fp = (j + np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, -1.0), 0.0)) * df
    ring = np.concatenate([np.arange(-60, -5), np.arange(6, 61)])
    floor = np.median(A[j[:, None] + ring[None, :]], axis=1)
    db = 20 * np.log10(np.maximum(A[j], 1e-300) / np.maximum(floor, 1e-300))
    return np.where(ok & (db >= LINE_DB) & (np.abs(fp - hz) <= MATING_TOL * df), db, 0.0)


def places(mesh_hz: float, s: np.ndarray) -> np.ndarray:
    """The 14 places (counts, 14) a shaft at each speed s puts lines at beside a mesh at ``mesh_hz``:
    its 1X and 2X, and sidebands at +-1..3 x s around the mesh's first and second harmonics."""
    offsets = [(0.0, 1.0), (0.0, 2.0)] + [(h * mesh_hz, q) for h in (1, 2) for q in (-3, -2, -1, 1, 2, 3)]
    return np.stack([base + q * s for base, q in offsets], axis=1)


def mating_teeth(f, A, mesh_hz: float, teeth: int) -> int | None:
    """The mating gear's tooth count the spectrum (f, A) shows around a mesh at ``mesh_hz`` of a gear of
    ``teeth`` teeth, or None where no count stands clearly ahead (MATING_HITS, MATING_MARGIN)."""
    df, f_shaft = f[1], mesh_hz / teeth
    z2 = np.array(MATING_TEETH)
    s = mesh_hz / z2
    # a speed at a harmonic or a half or third of this shaft's is this shaft's comb
    own = np.zeros(z2.size, bool)
    for m in (1, 2, 3):
        own |= np.abs(m * s / f_shaft - np.rint(m * s / f_shaft)) * f_shaft < 1.5 * df
    z2, s = z2[~own], s[~own]
    if z2.size < 2:
        return None
    at = places(mesh_hz, s)
    hits = (place_db(f, A, at.ravel()).reshape(at.shape) > 0).sum(axis=1)
    order = np.argsort(-hits, kind="stable")
    best, second = hits[order[0]], hits[order[1]]
    return int(z2[order[0]]) if best >= MATING_HITS and best - second >= MATING_MARGIN else None


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
