"""Machine diagnosis: confusion matrix on synthetic faults at three SNRs, the CWRU records, speed.

Targets (issue 6): the correct top in at least 95 % of cases above the lowest SNR, no false alarm
on healthy records; a 10 s, 12 kHz record diagnosed in under 1 s.

    python benchmarks/diagnosis.py [N]        (N seeds per fault and SNR, default 20)
"""

import statistics
import sys
import time
import warnings
from pathlib import Path


import vibmeasure as vm

FAULTS = ["none", "unbalance", "misalignment", "looseness", "bearing_outer_race", "bearing_inner_race",
          "bearing_ball", "gear_mesh", "resonance"]
SNRS = [-10, 0, 10]
SHORT = {"none": "none", "unbalance": "unbal", "misalignment": "misal", "looseness": "loose",
         "bearing_outer_race": "BPFO", "bearing_inner_race": "BPFI", "bearing_ball": "ball", "bearing_cage": "cage",
         "gear_mesh": "gear", "resonance": "reson", "electrical": "elec"}


def main(n):
    warnings.simplefilter("ignore", vm.QualityWarning)
    cols = [SHORT[f] for f in FAULTS] + ["cage", "elec"]
    for snr in SNRS:
        counts = {f: dict.fromkeys(cols, 0) for f in FAULTS}
        for fault in FAULTS:
            for seed in range(n):
                rec = vm.synth.machine(fault=fault, snr_db=snr, seed=1000 * (snr + 100) + seed, duration=6.0)
                d = vm.diagnose(rec, bearing="6205-2RS", gear=32)
                counts[fault][SHORT.get(d.top, d.top)] += 1
        correct = sum(counts[f][SHORT[f]] for f in FAULTS)
        false_alarms = n - counts["none"]["none"]
        print(f"\nSNR {snr} dB: correct {correct}/{n * len(FAULTS)} ({correct / (n * len(FAULTS)) * 100:.1f} %), "
              f"false alarms on healthy {false_alarms}/{n}")
        print(f"{'truth / top':>20} " + " ".join(f"{c:>6}" for c in cols))
        for f in FAULTS:
            print(f"{f:>20} " + " ".join(f"{counts[f][c]:>6}" for c in cols))
    data = Path(__file__).resolve().parents[2] / "shared" / "data" / "cwru"
    if data.exists():
        print("\nCWRU drive-end records (fs 12 kHz, g, SKF 6205-2RS):")
        for f, var in (("IR007_0.mat", "X105_DE_time"), ("OR007_6_0.mat", "X130_DE_time"),
                       ("B007_0.mat", "X118_DE_time"), ("Normal_0.mat", "X097_DE_time")):
            rec = vm.read(data / f, fs=12000, unit="g", channels=[var])
            d = vm.diagnose(rec, bearing="6205-2RS")
            print(f"  {f:16s} top {d.top:20s} confidence {d.confidence:.2f}  speed consistent {d.speed['consistent']}"
                  f"  zone {d.severity['zone']}")
    rec = vm.synth.machine(fault="bearing_inner_race", snr_db=10, seed=1, duration=10.0, fs=12000.0)
    ts = []
    for _ in range(5):
        t0 = time.perf_counter()
        vm.diagnose(rec, bearing="6205-2RS", gear=32)
        ts.append(time.perf_counter() - t0)
    print(f"\nspeed: 10 s at 12 kHz diagnosed in {statistics.median(ts):.3f} s (median of 5; target 1 s)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20)
