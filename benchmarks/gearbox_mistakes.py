"""Machine diagnosis of synthetic gearboxes under the mistakes users make every day.

``diagnosis_mistakes.py`` runs its mistakes on real bearing records, none of which carries a mesh; a
gearbox changes what a mistake does (a mesh and every shaft order of the tooth errors stand, the 1X
is often the weakest line, the mating shaft's comb lies beside the measured one's). Records (a
6205-2RS declared on each, 6 s at 12 kHz, ``synth.machine``):

- healthy: the eight gear pairs of ``gearbox.py`` with 5 and 10 % tooth errors, at 10 and 30 dB;
- local tooth fault: each pair, 5 % tooth errors, 10 dB;
- bearing faults (outer race, inner race, ball) under a 0.5 g mesh with 5 % tooth errors, four pairs.

Each is diagnosed as recorded (the baseline) and under each mistake of ``diagnosis_mistakes.py`` that
applies to one channel (the bands, the speed x0.5, x2, x0.8, x1.2, fs x0.5, x2, x4, drifts, an
offset, the units), twice: with no gear declared and with the gear's teeth and the mating shaft's
ratio. Counted per mistake as there: right (a healthy record answered "none" or "undetermined"; a
fault named), not named, wrong (confident: >= 0.5), refused, and the worse answers without a flag of
their own. Target (issue 46): 0 confident wrong answers, a flag on every wrong or degraded answer.

    python benchmarks/gearbox_mistakes.py [mistake ...]      (about 10 min on 2 cores)
"""

import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import vibmeasure as vm
from diagnosis_mistakes import CWRU_ONLY, MISTAKES, NOT_NAMED, table
from gearbox import FS, DURATION, MORE_PAIRS, PAIRS

ONE_CHANNEL = [m for m in MISTAKES if not any(c in m for c in CWRU_ONLY)]


def cases():
    """(label, synth.machine keywords, rpm, teeth, mating teeth, truth) of every record."""
    for rpm, z1, z2 in PAIRS + MORE_PAIRS:
        for error in (0.05, 0.1):
            for snr in (10, 30):
                yield (f"healthy {rpm} rpm {z1}/{z2} errors {error:g} {snr} dB",
                       dict(fault="none", mesh=1.0, tooth_error=error, snr_db=snr, seed=0), rpm, z1, z2, "none")
        yield (f"tooth fault {rpm} rpm {z1}/{z2}", dict(fault="gear_mesh", tooth_error=0.05, snr_db=10, seed=1),
               rpm, z1, z2, "gear_mesh")
    for fault in ("bearing_outer_race", "bearing_inner_race", "bearing_ball"):
        for rpm, z1, z2 in PAIRS[::2] + MORE_PAIRS[:1]:
            yield (f"{fault} {rpm} rpm {z1}/{z2}", dict(fault=fault, mesh=0.5, tooth_error=0.05, seed=0),
                   rpm, z1, z2, fault)


CASES = list(cases())


def _diagnose(rec, rpm, gear, extra):
    try:
        return vm.diagnose(rec, rpm=rpm, bearing="6205-2RS", gear=gear, **extra)
    except vm.ParameterError as e:
        return e


def _summary(d):
    if isinstance(d, Exception):
        return {"refused": str(d)[:160]}
    return {"top": d.top, "confidence": float(d.confidence), "flags": list(d.flags)}


def one(idx):
    """[(mistake, label, declared, truth, baseline, answer)] for one record under every mistake."""
    warnings.simplefilter("ignore")
    label, kw, rpm, z1, z2, truth = CASES[idx]
    x = vm.synth.machine(rpm=rpm, gear_teeth=z1, mating_teeth=z2, fs=FS, duration=DURATION, **kw).data[0]
    rec = vm.Record.from_array(x, fs=FS, names=["acc"], unit="g")
    out = []
    for declared, gear in (("no gear", None), ("gear", vm.Gear(z1, mating_shaft_ratio=z1 / z2))):
        base = _summary(_diagnose(rec, rpm, gear, {}))
        for m in NAMES:
            r, s, extra = MISTAKES[m](rec, rpm, "acc")
            out.append((m, label, declared, truth, base, _summary(_diagnose(r, s, gear, extra))))
    return out


def judge(truth, ans) -> str:
    """right / not named / wrong / wrong, confident / refused; a healthy gearbox is answered right by
    "none" and by "undetermined" (no fault named)."""
    if "refused" in ans:
        return "refused"
    top = ans["top"]
    if top == truth or (truth == "none" and top in NOT_NAMED):
        return "right"
    if top in NOT_NAMED:
        return "not named"
    return "wrong, confident" if ans["confidence"] >= 0.5 else "wrong"


NAMES = ONE_CHANNEL


def main():
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        out = [row for rows in pool.map(one, range(len(CASES))) for row in rows]
    print(f"{len(out)} diagnoses in {time.perf_counter() - t0:.0f} s; {len(CASES)} synthetic gearboxes, each with "
          "no gear and with the gear (teeth, ratio) declared\n")
    base_right = sum(judge(o[3], o[4]) == "right" for o in out if o[0] == NAMES[0])
    table(NAMES, [(m, f"{label}, {declared}", judge(truth, ans), judge(truth, base), base, ans)
                  for m, label, declared, truth, base, ans in out],
          f"\n\nas recorded: {base_right} of {2 * len(CASES)} right")


if __name__ == "__main__":
    args = sys.argv[1:]
    unknown = [a for a in args if a not in ONE_CHANNEL]
    if unknown:
        sys.exit(f"unknown mistake(s) {unknown}; choose from {ONE_CHANNEL}")
    NAMES = args or ONE_CHANNEL
    main()
