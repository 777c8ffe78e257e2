"""Machine diagnosis under the mistakes users make every day, on every development record.

Each fault record of ../shared/data/cwru_fe (45, fan-end bearing faults, three channels) and mfpt (8,
one channel) is diagnosed as recorded (the baseline) and again under each mistake:

- a demodulation band of the user's choice (four bands across the record's band);
- a declared speed of 0.5 x, 2 x, 0.8 x or 1.2 x the true one;
- a declared sampling rate of 0.5 x, 2 x or 4 x the true one;
- a slow drift of 0.1-0.5 g/s, or an offset of 5 g;
- the unit: the record integrated to velocity (mm/s) or displacement (um) and declared so (a right
  declaration the tool must convert), or the acceleration declared as mm/s (a wrong label);
- one channel alone, or two of the three (``channels=``; CWRU only).

Per mistake it counts: right (the seeded fault named), not named ("none" or "undetermined"), wrong
(another fault named) split into confident (confidence >= 0.5) and not, refused (a ParameterError that
names the problem), and the answers that are wrong or degraded (a right baseline answer lost) without a
flag the baseline did not carry (or a refusal). Targets (issue 46): 0 confident wrong answers, a flag on
every wrong or degraded answer.

    python benchmarks/diagnosis_mistakes.py [mistake ...]      (about 10 min on 2 cores)
"""

import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import vibmeasure as vm
from diagnosis_real import records, scored

NOT_NAMED = ("none", "undetermined")


def _rebuilt(rec, data=None, fs=None, unit="g", names=None):
    return vm.Record.from_array(rec.data if data is None else data, fs=rec.fs if fs is None else fs,
                                names=list(rec.names) if names is None else names, unit=unit)


def _band(lo, hi):
    """A fixed demodulation band from lo to hi x the Nyquist frequency."""
    return lambda rec, rpm, ch: (rec, rpm, dict(band=(lo * rec.fs / 2, hi * rec.fs / 2)))


def _rpm(k):
    return lambda rec, rpm, ch: (rec, k * rpm, {})


def _fs(k):
    return lambda rec, rpm, ch: (_rebuilt(rec, fs=k * rec.fs), rpm, {})


def _drift(g_per_s):
    def f(rec, rpm, ch):
        t = np.arange(rec.n_samples) / rec.fs
        return _rebuilt(rec, rec.data + g_per_s * t), rpm, {}
    return f


def _integrated(times, unit):
    """The record integrated once (m/s) or twice (m) and declared in ``unit``: what a velocity or a
    displacement sensor would have given; the tool must convert it back."""
    def f(rec, rpm, ch):
        x = rec
        for _ in range(times):
            x = vm.integrate(x)
        return x.to_unit(unit), rpm, {}
    return f


def _alone(suffix):
    def f(rec, rpm, ch):
        name = next(n for n in rec.names if n.endswith(suffix))
        return rec, rpm, dict(channels=[name])
    return f


def _pair(a, b):
    def f(rec, rpm, ch):
        names = [next(n for n in rec.names if n.endswith(s)) for s in (a, b)]
        return rec, rpm, dict(channels=names)
    return f


MISTAKES = {
    **{f"band {lo:g}-{hi:g} x Nyquist": _band(lo, hi) for lo, hi in ((0.05, 0.15), (0.2, 0.35), (0.4, 0.6),
                                                                     (0.7, 0.9))},
    "rpm x0.5": _rpm(0.5), "rpm x2": _rpm(2.0), "rpm x0.8": _rpm(0.8), "rpm x1.2": _rpm(1.2),
    "fs x0.5": _fs(0.5), "fs x2": _fs(2.0), "fs x4": _fs(4.0),
    **{f"drift {g:g} g/s": _drift(g) for g in (0.1, 0.3, 0.5)},
    "offset 5 g": lambda rec, rpm, ch: (_rebuilt(rec, rec.data + 5.0), rpm, {}),
    "velocity in mm/s": _integrated(1, "mm/s"),
    "displacement in um": _integrated(2, "um"),
    "acceleration labelled mm/s": lambda rec, rpm, ch: (_rebuilt(rec, unit="mm/s"), rpm, {}),
    **{f"{w} channel alone": _alone(s) for w, s in (("fan-end", "_FE_time"), ("drive-end", "_DE_time"),
                                                     ("base", "_BA_time"))},
    "fan-end + drive-end": _pair("_FE_time", "_DE_time"),
    "drive-end + base": _pair("_DE_time", "_BA_time"),
}
CWRU_ONLY = ("channel alone", "+")


def _diagnose(rec, rpm, bearing, channel, extra):
    kw = dict(extra)
    if "channels" not in kw:
        kw["channel"] = channel if channel in rec.names else None
    try:
        return vm.diagnose(rec, rpm=rpm, bearing=bearing, **kw)
    except vm.ParameterError as e:
        return e


def one(job):
    """(mistake, record, truth, baseline answer, answer) for one record under one mistake."""
    idx, mistake = job
    warnings.simplefilter("ignore")
    dset, fname, rec, rpm, bearing, truth, channel = RECS[idx]
    base = _diagnose(rec, rpm, bearing, channel, {})
    r, s, extra = MISTAKES[mistake](rec, rpm, channel)
    d = _diagnose(r, s, bearing, channel, extra)
    return mistake, fname, truth, _summary(base), _summary(d)


def _summary(d):
    if isinstance(d, Exception):
        return {"refused": str(d)[:160]}
    return {"top": d.top, "confidence": float(d.confidence), "flags": list(d.flags)}


def judge(truth, base, ans) -> str:
    """right / not named / wrong, confident / wrong / refused; and whether an answer worse than the
    baseline (wrong, or a right call lost) carries a flag of its own."""
    if "refused" in ans:
        return "refused"
    top = scored(ans["top"])
    if top == truth:
        return "right"
    if top == "none":
        return "not named"
    return "wrong, confident" if ans["confidence"] >= 0.5 else "wrong"


def flagged(base, ans) -> bool:
    return "refused" in ans or bool(set(ans["flags"]) - set(base.get("flags", ())))


RECS = [r for r in records() if r[0] in ("cwru_fe", "mfpt")]


KINDS = ("right", "not named", "wrong", "wrong, confident", "refused")


def table(names, rows, note: str = "") -> None:
    """Print, per mistake, how many answers are of each kind and how many are worse than the baseline
    (wrong, or a right baseline answer lost) without a flag of their own, then ``note`` and the
    confident wrong and unflagged worse answers, one line each; ``rows``: (mistake, label, kind, the
    baseline's kind, baseline, answer)."""
    print(f"{'mistake':30s} {'n':>4} " + " ".join(f"{k:>16s}" for k in KINDS) + f" {'worse, unflagged':>17s}")
    totals = dict.fromkeys(KINDS, 0)
    bad = []
    for m in names:
        sel = [r for r in rows if r[0] == m]
        counts = dict.fromkeys(KINDS, 0)
        unflagged = 0
        for _, label, k, base_kind, base, ans in sel:
            counts[k] += 1
            worse = k.startswith("wrong") or (base_kind == "right" and k != "right")
            said = (f"{m}: {label} -> {ans.get('top')} {ans.get('confidence', 0):.2f} "
                    f"(as recorded {base.get('top')} {base.get('confidence', 0):.2f})")
            if worse and not flagged(base, ans):
                unflagged += 1
                bad.append(said + " unflagged")
            elif k == "wrong, confident":
                bad.append(said + f" flagged {sorted(set(ans['flags']) - set(base.get('flags', ())))}")
        totals = {k: totals[k] + counts[k] for k in KINDS}
        print(f"{m:30s} {len(sel):>4} " + " ".join(f"{counts[k]:>16d}" for k in KINDS) + f" {unflagged:>17d}",
              flush=True)
    print(f"{'all':30s} {len(rows):>4} " + " ".join(f"{totals[k]:>16d}" for k in KINDS) + note)
    print("\nconfident wrong answers, and worse answers without a flag of their own:")
    for b in bad:
        print("  " + b)


def main(names):
    jobs = [(i, m) for m in names for i, r in enumerate(RECS)
            if not (r[0] == "mfpt" and any(c in m for c in CWRU_ONLY))]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        out = list(pool.map(one, jobs, chunksize=4))
    print(f"{len(jobs)} diagnoses in {time.perf_counter() - t0:.0f} s; development records: 45 CWRU fan-end "
          "(3 channels) + 8 MFPT (1 channel)\n")
    table(names, [(m, f"{fname} {truth}", judge(truth, base, ans), judge(truth, base, base), base, ans)
                  for m, fname, truth, base, ans in out])


if __name__ == "__main__":
    args = sys.argv[1:]
    unknown = [a for a in args if a not in MISTAKES]
    if unknown:
        sys.exit(f"unknown mistake(s) {unknown}; choose from {list(MISTAKES)}")
    main(args or list(MISTAKES))
