"""Answers that a record's length decides: every real development record (CWRU fan-end, MFPT, CWRU
drive-end; benchmarks/diagnosis_real.py's set) diagnosed at full length and with its last 1 % and 2 %
cut off, with its own bearing declared and, for the CWRU records, with the other end's (healthy there:
a bearing call is a false call). A fault's comb is the machine's, so the answers should not change.

Prints per length: right / none / wrong and the confident (>= 0.5) wrong answers, for the development
set, the drive-end records and the other end; then every record whose answer changes with the length.

    python benchmarks/diagnosis_cut.py
"""

import collections
import statistics
import time
import warnings

import vibmeasure as vm
from diagnosis_real import SHORT, records

OTHER = {"6203-2RS": "6205-2RS", "6205-2RS": "6203-2RS"}
SHARES = (1.0, 0.99, 0.98)


def _score(top: str, truth: str) -> str:
    if top.startswith("bearing_"):
        return "right" if top == truth else "wrong"
    return "right" if truth == "none" else "none"


def main():
    warnings.simplefilter("ignore", vm.QualityWarning)
    rows = []
    for dset, name, rec, rpm, bearing, truth, channel in records():
        cases = [("own", bearing, truth)] + ([("other", OTHER[bearing], "none")] if dset != "mfpt" else [])
        for kind, b, tr in cases:
            answers = []
            for share in SHARES:
                n = int(rec.n_samples * share)
                r = vm.Record.from_array(rec.data[:, :n], fs=rec.fs, names=list(rec.names), unit="g")
                t0 = time.perf_counter()
                d = vm.diagnose(r, rpm=rpm, bearing=b, channel=channel)
                answers.append((d.top, d.confidence, time.perf_counter() - t0))
            rows.append({"set": dset, "name": name, "kind": kind, "truth": tr, "answers": answers})
            print(f"  {dset:8s} {name:18s} {kind:5s} {SHORT.get(tr, tr):6s} "
                  + "  ".join(f"{a[0]:20s} {a[1]:.2f}" for a in answers), flush=True)
    groups = (("development set, own bearing", "own", ("cwru_fe", "mfpt")),
              ("CWRU drive-end, own bearing", "own", ("cwru",)),
              ("CWRU, the other end's bearing", "other", ("cwru_fe", "cwru")))
    print("\nright / none / wrong (confident wrong) at full length, 99 %, 98 %:")
    for title, kind, sets in groups:
        sel = [r for r in rows if r["kind"] == kind and r["set"] in sets]
        cells = []
        for i in range(len(SHARES)):
            c = collections.Counter(_score(r["answers"][i][0], r["truth"]) for r in sel)
            confident = sum(_score(r["answers"][i][0], r["truth"]) == "wrong" and r["answers"][i][1] >= 0.5
                            for r in sel)
            cells.append(f"{c['right']} / {c['none']} / {c['wrong']} ({confident})")
        print(f"  {title:32s} " + "   ".join(cells))
    print("\nanswers that change with the length:")
    for r in rows:
        if len({a[0] for a in r["answers"]}) > 1:
            print(f"  {r['set']:8s} {r['name']:18s} {r['kind']:5s} "
                  + " / ".join(f"{a[0]} {a[1]:.2f}" for a in r["answers"]))
    full = [r["answers"][0][2] for r in rows if r["set"] == "cwru_fe" and r["kind"] == "own"]
    print(f"\nmedian diagnose time, CWRU fan-end at full length: {statistics.median(full):.2f} s")


if __name__ == "__main__":
    main()
