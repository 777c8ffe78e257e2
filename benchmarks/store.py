"""The store's cost per commit as it grows: 20,000 small diagnosis results in commits of 50 (issue 47).

The HDF5 store copies and seals its whole file on every commit, so its commit time grows with the file;
a database appends rows in a transaction. Printed per engine: the mean time of a commit (50 measurements
with one result each) over the first and the last 10 commits, and the whole run's wall time. PostgreSQL
is run when a URL is given (an empty database; the tests start a throw-away cluster the same way).

    python benchmarks/store.py [N_RESULTS] [--postgres postgresql://user@127.0.0.1:PORT/db]
"""

import sys
import tempfile
import time
from pathlib import Path

import vibmeasure as vm

PER_COMMIT = 50


def run(target, n: int, raw_dir=None) -> tuple[float, float, float]:
    """(ms per commit over the first 10, ms over the last 10, total s) for n results."""
    times = []
    t_all = time.perf_counter()
    with vm.Store(target, writable=True, **({"raw_dir": raw_dir} if raw_dir else {})) as st:
        st.add_asset("pump-1", bearing="6205-2RS")
        st.add_point("pump-1", "DE", unit="g")
        st.commit()
        for c in range(n // PER_COMMIT):
            t0 = time.perf_counter()
            for i in range(PER_COMMIT):
                k = c * PER_COMMIT + i
                mid = st.add_measurement("pump-1", "DE", time=1.7e9 + 60 * k, rpm=1480.0, sha256=f"{k:064x}")
                st.add_result(mid, "diagnose", {"top": "none", "confidence": 0.9, "faults": [k] * 20},
                              summary={"top": "none", "confidence": 0.9, "velocity_rms_mm_s": 1.2})
            st.commit()
            times.append(time.perf_counter() - t0)
    total = time.perf_counter() - t_all
    return 1e3 * sum(times[:10]) / 10, 1e3 * sum(times[-10:]) / 10, total


def main(argv):
    n = int(argv[0]) if argv and argv[0].isdigit() else 20000
    pg = argv[argv.index("--postgres") + 1] if "--postgres" in argv else None
    d = Path(tempfile.mkdtemp())
    rows = [("HDF5 (.h5)", run(d / "s.h5", n)), ("SQLite (.db, WAL)", run(d / "s.db", n))]
    if pg:
        rows.append(("PostgreSQL", run(pg, n, raw_dir=d / "raw")))
    print(f"{n} results in commits of {PER_COMMIT} (one measurement + one result each)\n")
    print(f"{'engine':20s} {'first 10 commits':>17s} {'last 10 commits':>16s} {'total':>9s}")
    for name, (first, last, total) in rows:
        print(f"{name:20s} {first:14.1f} ms {last:13.1f} ms {total:7.1f} s")
    h5_last = rows[0][1][1]
    for name, (_, last, _) in rows[1:]:
        print(f"last-commit ratio HDF5 / {name}: {h5_last / last:.1f}x")


if __name__ == "__main__":
    main(sys.argv[1:])
