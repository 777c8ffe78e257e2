"""Batch throughput: synthetic 3-channel, 25.6 kHz machine records through spectrum+diagnose.

Runs, in one process: vm.batch serially, vm.batch on a local Dask cluster with 2 worker processes
(127.0.0.1), and a naive loop an engineer might write (scipy.signal.welch per channel + a pandas
row per record, no diagnosis). Prints records/s, the ratio 2 workers / serial (target >= 1.7x on 2
cores) and the client's peak resident memory after each run (it must not grow with the number of
records: results are committed and dropped as they arrive). The store is an SQLite database (the
default engine), or the HDF5 file with ``--store h5``.

    python benchmarks/batch.py [N] [--seconds S] [--store db|h5]
        N records of S s (default 200 of 10 s: about 12 minutes on 2 cores; 1000 of 1 s about 5)
    python benchmarks/batch.py --memory N   (the serial batch only, the client's RSS every N/12 records)
"""

import resource
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import vibmeasure as vm


def rss_mb():
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def make(folder: Path, n: int, seconds: float = 1.0) -> Path:
    rng = np.random.default_rng(0)
    lines = ["file,asset,point,rpm,bearing,time"]
    faults = ("none", "none", "none", "bearing_outer_race", "unbalance")
    for i in range(n):
        chans = [vm.synth.machine(fault=faults[i % 5], rpm=1500.0, fs=25600.0, duration=seconds,
                                  seed=int(rng.integers(1 << 31))).data[0] for _ in range(3)]
        rec = vm.Record(np.array(chans), 25600.0, [vm.Channel(c, "acceleration", "g") for c in ("DE", "FE", "BA")])
        vm.write(folder / f"r{i:05d}.h5", rec)
        lines.append(f"r{i:05d}.h5,m{i % 20},DE,1500,6205-2RS,2026-03-01T00:00:00")
    man = folder / "manifest.csv"
    man.write_text("\n".join(lines) + "\n")
    return man


class Clock:
    """progress callback that keeps the time of every result: the rate once running leaves out the
    start-up (the cluster's processes, the workers' first imports)."""

    def __init__(self):
        self.times = []
        self.first = None
        self.rss = []   # (results taken, client RSS in kB) every 25 results

    def __call__(self, done, total):
        now = time.perf_counter()
        self.first = self.first or now
        self.times.append(now)
        if done % 25 == 0:
            self.rss.append((done, rss_mb() * 1024))

    def growth(self):
        """The client's RSS slope (kB per record) over the second half of the run: what it keeps per
        record once the allocator's pools and the first imports are in place."""
        pts = np.array(self.rss[len(self.rss) // 2:], float)
        if len(pts) < 3:
            return float("nan"), float("nan")
        return float(np.polyfit(pts[:, 0], pts[:, 1], 1)[0]), float(pts[-1, 1] - pts[0, 1])

    def rate(self):
        t = self.times[9:] if len(self.times) > 20 else self.times
        return (len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 and t[-1] > t[0] else float("nan")


def naive(files):
    import pandas as pd
    from scipy.signal import welch
    rows = []
    for f in files:
        rec = vm.read(f)
        row = {"file": f.name}
        for c, x in zip(rec.channels, rec.data):
            fr, p = welch(x, fs=rec.fs, nperseg=4096)
            row[f"{c.name}_rms"] = float(np.sqrt(np.sum(p) * (fr[1] - fr[0])))
            row[f"{c.name}_peak_hz"] = float(fr[np.argmax(p[1:]) + 1])
        rows.append(row)
    return pd.DataFrame(rows)


def _work(item):
    from vibmeasure.monitor.batch import analyse_file
    t0 = time.perf_counter()
    for _ in range(8):
        analyse_file(item, ("spectrum", "diagnose"), {})
    return time.perf_counter() - t0


def parallel_ceiling(item):
    """What two processes can gain on this machine: the same analysis 8 times in one process, then
    in two processes at once (no Dask). On a machine whose two cores are fully independent the ratio
    is 2; shared or throttled virtual cores give less, and no scheduler can beat it."""
    import multiprocessing as mp
    with mp.get_context("spawn").Pool(2) as pool:
        pool.map(_work, [item, item])  # warm-up: imports
        t0 = time.perf_counter()
        pool.map(_work, [item])
        one = time.perf_counter() - t0
        t0 = time.perf_counter()
        pool.map(_work, [item, item])
        two = time.perf_counter() - t0
    return 2 * one / two


def memory(n):
    """The client's RSS over a long serial batch: flat once the first records are in (bounded)."""
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        man = make(d, n)
        clock = Clock()
        vm.batch(task="spectrum+diagnose", store=d / "serial.h5", manifest=man, progress=clock)
        print(f"client RSS during a serial batch of {n} records:")
        for k in range(0, len(clock.rss), max(1, len(clock.rss) // 12)):
            print(f"  after {clock.rss[k][0]:6d} records {clock.rss[k][1] / 1024:7.1f} MB")
        slope, rise = clock.growth()
        print(f"  slope over the second half {slope:+.2f} kB per record ({rise / 1024:+.1f} MB); target: bounded")


def _options(argv):
    import argparse
    ap = argparse.ArgumentParser(description="vm.batch throughput, serial and on 2 Dask workers")
    ap.add_argument("n", nargs="?", type=int, default=200)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--store", choices=("db", "h5"), default="db")
    return ap.parse_args(argv)


def main():
    if sys.argv[1:2] == ["--memory"]:
        return memory(int(sys.argv[2]) if len(sys.argv) > 2 else 3000)
    opt = _options(sys.argv[1:])
    n = opt.n
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        t0 = time.perf_counter()
        man = make(d, n, opt.seconds)
        print(f"{n} records ({opt.seconds:g} s, 3 channels, 25.6 kHz) written in {time.perf_counter() - t0:.0f} s; "
              f"client RSS {rss_mb():.0f} MB; store: {'SQLite' if opt.store == 'db' else 'HDF5'}")
        t0 = time.perf_counter()
        naive(sorted(d.glob("r*.h5")))
        t_naive = time.perf_counter() - t0
        print(f"  naive loop (welch + pandas, no diagnosis) {n / t_naive:7.1f} records/s   RSS {rss_mb():.0f} MB")
        t0 = time.perf_counter()
        clock_s = Clock()
        rep = vm.batch(task="spectrum+diagnose", store=d / f"serial.{opt.store}", manifest=man, progress=clock_s)
        t_serial = time.perf_counter() - t0
        done = int((rep["status"] == "done").sum())
        print(f"  vm.batch serial                            {n / t_serial:7.2f} records/s   RSS {rss_mb():.0f} MB"
              f"   ({done} done)")
        t0 = time.perf_counter()
        clock_d = Clock()
        rep = vm.batch(task="spectrum+diagnose", store=d / f"dask.{opt.store}", manifest=man, workers=2,
                       progress=clock_d)
        t_dask = time.perf_counter() - t0
        done = int((rep["status"] == "done").sum())
        print(f"  vm.batch, local Dask cluster, 2 workers    {n / t_dask:7.2f} records/s   RSS {rss_mb():.0f} MB"
              f"   ({done} done; cluster start-up included: {clock_d.first - t0:.1f} s to the first result)")
        print(f"  2 workers / serial: {t_serial / t_dask:.2f}x overall (target >= 1.7x on 2 cores); "
              f"{clock_d.rate() / clock_s.rate():.2f}x once running ({clock_s.rate():.2f} and {clock_d.rate():.2f} "
              "records/s from the 10th to the last result)")
        for name, c in (("serial", clock_s), ("2 workers", clock_d)):
            slope, rise = c.growth()
            print(f"  client memory, {name}: {slope:+.2f} kB per record over the second half of the run "
                  f"({rise / 1024:+.1f} MB in all; target: bounded, ~0 kB per record)")
        ceiling = parallel_ceiling(vm.read_manifest(man)[0])
        print(f"  this machine's ceiling: two processes doing the same work at once run {ceiling:.2f}x one "
              "process (2.0 on independent cores)")


if __name__ == "__main__":
    main()
