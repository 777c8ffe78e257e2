"""Step: a gearbox found where none is declared. A gear mesh is a whole order of both its shafts: a
strong line with sidebands at +-1..3 x each shaft's speed around it and its second harmonic, and each
shaft's 1X and 2X (``mating.places``). The strongest lines are tried as a mesh; every tooth count
5..250 puts a shaft at mesh / count, and the two counts, of unrelated speeds, whose places hold the
most lines are the gear pair, where both hold MATING_HITS of the 14 and a third count holds clearly
fewer. Both shafts' speeds are then measured, teeth times finer than a 1X, whatever speed was declared:

- one of them is the speed used (a 1X found within SPEED_NOTED of it, or, with no 1X found, within
  SPEED_SEARCH of the declared speed, which the mesh then corrects): the gear pair is known, as if
  declared with its ratio, for the bearing test (``Job.found_gear``: the mating shaft's harmonics and
  the pair's hunting-tooth comb are the gearbox's, not a bearing's); the gear itself is not judged;
- neither is, and no 1X with its harmonics confirms the speed used: the speed is in doubt
  (``doubts.gearbox_speed``), as when a declared gear's mesh stands at another speed's.

Without it a healthy 61/19 gearbox read in a band of the user's choice called its hunting-tooth comb
a ball fault at 0.81, and a healthy 32/71 gearbox declared at 0.8 x its speed or read at 4 x its fs
called a ball at 0.68 and an outer race at 1.00 on its two shafts' combination lines."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...models.bearing import Gear
from .lines import _harmonic_support, _refine
from .mating import MATING_HITS, MATING_MARGIN, MATING_TEETH, place_db, places
from .speed import MESH_DB, MESH_FACTORS, ONE_X_CONFIRMS, SPEED_NOTED, SPEED_SEARCH, Run

# The FOUND_LINES strongest local peaks standing MESH_DB over their floor (the median 6 to 60 lines
# either side) are tried as a mesh, the strongest first; the first where two counts hold MATING_HITS
# decides. Shaft speeds within FOUND_SPEEDS x the speed used are searched: the speed mistakes users
# make are factors of 2 and 4 (rpm for Hz, pulses per revolution, the sampling rate).
FOUND_LINES = 3
FOUND_SPEEDS = (1 / 4.5, 4.5)
# A count m times finer (a speed a whole fraction of another's) is the shaft where it holds MATING_HITS
# places too and their median height is within FINER_DB of the coarser count's: its 1X and odd sidebands
# stand where the coarser count has none. A gearbox's hunting-tooth comb (every line of the pair's
# common period) fills the places of every count dividing z1 x z2 at 12-20 dB where the shafts' own
# stand 30-50 dB (32/71 at 3000 rpm, 30 dB: 142 teeth, half the mating shaft's speed, held 10 places).
FINER_DB = 10.0
# The pair holds where the third count holds MATING_MARGIN fewer places, or its places' median height is
# FINER_DB under the second's (a 61/19 pair at 30 dB: its hunting-tooth comb gives a third count 12-14).
# Measured: the eight pairs of benchmarks/gearbox.py, 2-20 % tooth errors, 10 and 30 dB, two seeds: 124 of
# 128 pairs found, none wrong (the four missed: 2 % errors at 10 dB, the mating shaft's sidebands
# buried); no pair found on the 53 real development records, every channel, at fs x 0.5, 1, 2, 4 and a
# speed declared 0.5, 0.8, 1 and 2 x (2,464 spectra).


def _related(s: np.ndarray, ref: float, df: float) -> np.ndarray:
    """Which speeds s are a harmonic or a half or third of one of ref's, or ref of theirs: one shaft's."""
    out = np.zeros(s.size, bool)
    for m in (1, 2, 3):
        out |= np.abs(m * s / ref - np.rint(m * s / ref)) * ref < 1.5 * df
        out |= np.abs(m * ref / s - np.rint(m * ref / s)) * s < 1.5 * df
    return out


def _finest(k: int, z: np.ndarray, hits: np.ndarray, med: np.ndarray) -> int:
    """The count m x z[k] (m = 2..8) that holds as well (MATING_HITS, FINER_DB), the largest; else k."""
    index = {int(v): i for i, v in enumerate(z)}
    best = k
    for m in range(2, 9):
        j = index.get(int(z[k]) * m)
        if j is not None and hits[j] >= MATING_HITS and med[j] >= med[k] - FINER_DB:
            best = j
    return best


def gear_pair(f, A, mesh_hz: float, z: np.ndarray):
    """((z_a, s_a), (z_b, s_b)) of the gear pair whose shafts' places (``mating.places``) around a mesh at
    ``mesh_hz`` hold the most lines among the counts z; False where a third count holds about as many,
    None where no two do."""
    df, s = f[1], mesh_hz / z
    at = places(mesh_hz, s)
    db = place_db(f, A, at.ravel()).reshape(at.shape)
    hits, med = (db > 0).sum(axis=1), np.median(db, axis=1)
    free = np.ones(z.size, bool)
    picks = []
    for k in np.lexsort((-db.sum(axis=1), -hits)):
        if free[k]:
            k = _finest(int(k), z, hits, med)
            picks.append(k)
            free &= ~_related(s, s[k], df)
            if len(picks) == 3:
                break
    if len(picks) < 2 or hits[picks[1]] < MATING_HITS:
        return None
    a, b = picks[:2]
    third = (hits[picks[2]], med[picks[2]]) if len(picks) == 3 else (0, 0.0)
    if hits[b] - third[0] < MATING_MARGIN and med[b] < third[1] + FINER_DB:
        return False
    return (int(z[a]), float(s[a])), (int(z[b]), float(s[b]))


def _mesh_lines(f, A, lo_hz: float) -> list:
    """The FOUND_LINES strongest local peaks from lo_hz on that stand MESH_DB over their floor."""
    df, n = f[1], A.size
    i = np.arange(max(62, int(lo_hz / df)), n - 62)
    i = i[(A[i] >= A[i - 1]) & (A[i] > A[i + 1])]
    i = i[np.argsort(-A[i])][:30]
    ring = np.concatenate([np.arange(-60, -5), np.arange(6, 61)])
    floor = np.median(A[i[:, None] + ring[None, :]], axis=1)
    db = 20 * np.log10(np.maximum(A[i], 1e-300) / np.maximum(floor, 1e-300))
    return [int(j) for j in i[db >= MESH_DB][:FOUND_LINES]]


def find_gearbox(f, A, f1: float):
    """(mesh Hz, (z_a, s_a), (z_b, s_b)) of a gear pair the spectrum (f, A) shows, its shafts within
    FOUND_SPEEDS x f1 (Hz), or None.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure.monitor.diagnosis.gearbox import find_gearbox
    >>> x = vm.synth.machine(rpm=1200, mesh=1.0, gear_teeth=19, mating_teeth=61, tooth_error=0.05,
    ...                      duration=6.0, seed=0).data[0]
    >>> w = np.hanning(x.size)
    >>> A, f = np.abs(np.fft.rfft(x * w)), np.fft.rfftfreq(x.size, 1 / 12000)
    >>> mesh, (za, sa), (zb, sb) = find_gearbox(f, A, 20.0)
    >>> round(mesh), sorted([za, zb])
    (380, [19, 61])
    """
    df = f[1]
    for i in _mesh_lines(f, A, 1.1 * f1):
        mesh = _refine(f, A, f[i])
        z = np.array(MATING_TEETH)
        s = mesh / z
        keep = (s >= max(FOUND_SPEEDS[0] * f1, 8 * df)) & (s <= FOUND_SPEEDS[1] * f1)
        z, s = z[keep], s[keep]
        if z.size < 3 or 2 * mesh + 3 * s.max() >= f[-1]:
            continue
        pair = gear_pair(f, A, mesh, z)
        if pair is not None:
            return (mesh, *pair) if pair else None
    return None


def gearbox_found(run: Run) -> Run:
    """The run with a gear pair the spectrum shows where none is declared (``speed["gearbox"]``): known
    for the bearing test where one of its shafts is the speed used (``Job.found_gear``), a doubt where
    neither is (``doubts.gearbox_speed``). Where the speed used is the declared one (no 1X found) or a
    1X found off it (``speed_corrected``: the line with the most harmonics, which may be the mate's 2X),
    a shaft of the pair within SPEED_SEARCH of the declared speed is the speed: the mesh measures it
    teeth times finer than any 1X."""
    job, speed = run.job, run.speed
    if job.gear is not None:
        return run
    found = find_gearbox(run.f, run.A, run.f1)
    if found is None:
        return run
    mesh, (za, sa), (zb, sb) = found
    shafts = ((za, sa, zb, sb), (zb, sb, za, sa))
    measured = speed.get("estimated_rpm") is not None
    here = [h for h in shafts if measured and abs(h[1] / run.f1 - 1) <= SPEED_NOTED]
    moved = not here and (not measured or "speed_corrected" in job.flags)
    if moved:
        here = [h for h in shafts if abs(h[1] / (job.rpm / 60) - 1) <= SPEED_SEARCH]
    info = {"mesh_hz": mesh, "teeth": (za, zb), "shafts_rpm": (60 * sa, 60 * sb)}
    speed["gearbox"] = info
    if not here:
        info["confirmed"] = measured and (speed.get("source") is not None
                                          or speed.get("one_x_harmonics", 0) >= ONE_X_CONFIRMS)
        ratio = [(q, s) for q in MESH_FACTORS for s in (sa, sb) if abs(s / (q * job.rpm / 60) - 1) <= SPEED_NOTED]
        info["factor"] = ratio[0][0] if ratio else None
        return run
    z, s, zo, so = min(here, key=lambda h: abs(h[1] / run.f1 - 1))
    info.update(teeth=(z, zo), shafts_rpm=(60 * s, 60 * so), on_shaft=True)
    if moved:
        _speed_from_mesh(run, mesh, z, s)
    job = dataclasses.replace(job, found_gear=(Gear(z, mating_shaft_ratio=z / zo), s))
    return dataclasses.replace(run, job=job, f1=s if moved else run.f1)


def _speed_from_mesh(run: Run, mesh: float, z: int, s: float) -> None:
    """The speed dict and flags where the pair's shaft s (Hz) is taken for the speed (its 1X's harmonics
    counted as where a declared gear's mesh measures it: ``speed._speed``)."""
    job, speed = run.job, run.speed
    off = s / (job.rpm / 60) - 1
    speed.update(estimated_rpm=60 * s, note=(
        f"the speed is measured from a gear mesh at {mesh:.1f} Hz ({z} teeth x {60 * s:.0f} rpm), "
        f"{100 * off:+.1f} % from the declared {job.rpm:g} rpm"))
    speed["one_x_harmonics"] = _harmonic_support(run.f, run.A, s)
    for flag in ("speed_unchecked", "speed_corrected"):
        if flag in job.flags:
            job.flags.remove(flag)
    if abs(off) > SPEED_NOTED:
        job.flags.append("speed_corrected")


def found_note(speed: dict) -> str:
    """The reason's sentence for a gear pair found where the shaft is (``gearbox_found``), or ''."""
    info = speed.get("gearbox")
    if not info or not info.get("on_shaft"):
        return ""
    (z, zo), (_, rpm_o) = info["teeth"], info["shafts_rpm"]
    return (f"a gear mesh stands at {info['mesh_hz']:.1f} Hz with the sidebands of this shaft ({z} teeth) and of "
            f"its mate ({zo} teeth, {rpm_o:.0f} rpm): that shaft's harmonics and the pair's hunting-tooth comb are "
            "set apart from the bearing's lines; declare gear= to have the gear itself checked")
