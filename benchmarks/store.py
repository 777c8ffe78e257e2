"""The store's cost as it grows (issue 47): commit time from 1,000 to N results, and the query a trend
makes (one asset's year of results).

A plant of ASSETS machines measured hourly: each commit adds 50 measurements with one diagnosis result
each. Printed per engine at 1k, 10k, 100k, ... results: the mean time of 10 commits there, the time of
``results("diagnose", asset=..., since=..., until=...)`` over one asset's year (median of 3), of the same
with ``with_result=False`` (the summary values only: the query ``vm.trend`` makes) and of ``vm.trend`` on
that asset. The HDF5 store copies and seals its whole file on every commit, so it is run only up to
20,000 results; a database appends rows in a transaction. PostgreSQL is run when a URL of an empty
database is given (the tests start a throw-away cluster the same way). Targets: commit cost flat
(last / first <= 3), the year's query under 0.2 s. One asset's rows lie one per table block (the plant
writes every asset each hour): the results carry their asset and time, and on PostgreSQL a covering
index answers the summary-only query without visiting the table (``docs/store.md``).

    python benchmarks/store.py [N_RESULTS] [--postgres postgresql://user@127.0.0.1:PORT/db] [--only h5|sqlite|postgres]
"""

import sys
import tempfile
import time
from pathlib import Path

import vibmeasure as vm

PER_COMMIT = 50
ASSETS = 100
HOUR = 3600.0
T0 = 1.7e9


def run(target, n: int, raw_dir=None) -> list:
    """[(results so far, ms per commit over 10 commits, year query s, summary-only year query s, trend s,
    rows)] at each checkpoint."""
    marks = [m for m in (1000, 10_000, 100_000, 1_000_000, 10_000_000) if m <= n]
    out = []
    with vm.Store(target, writable=True, **({"raw_dir": raw_dir} if raw_dir else {})) as st:
        for a in range(ASSETS):
            st.add_asset(f"pump-{a:03d}", bearing="6205-2RS")
            st.add_point(f"pump-{a:03d}", "DE", unit="g")
        st.commit()
        k, times = 0, []
        while k < n:
            t0 = time.perf_counter()
            for _ in range(PER_COMMIT):
                asset, hour = f"pump-{k % ASSETS:03d}", k // ASSETS
                mid = st.add_measurement(asset, "DE", time=T0 + HOUR * hour, rpm=1480.0, sha256=f"{k:064x}")
                st.add_result(mid, "diagnose", {"top": "none", "confidence": 0.9},
                              summary={"top": "none", "confidence": 0.9, "velocity_rms_mm_s": 1.2 + 1e-4 * (k % 7),
                                       "zone": "A", "bearing_evidence": 1.0})
                k += 1
            st.commit()
            times.append(time.perf_counter() - t0)
            if marks and k >= marks[0]:
                ms = 1e3 * sum(times[-10:]) / len(times[-10:])
                year = min(8760.0, k / ASSETS)
                qs = []
                for _ in range(3):   # the median of 3: the first after a commit may wait on the disk
                    t1 = time.perf_counter()
                    df = st.results("diagnose", asset="pump-000", since=T0, until=T0 + HOUR * year)
                    qs.append(time.perf_counter() - t1)
                q = sorted(qs)[1]
                qs = []
                for _ in range(3):
                    t1 = time.perf_counter()
                    st.results("diagnose", asset="pump-000", since=T0, until=T0 + HOUR * year, with_result=False)
                    qs.append(time.perf_counter() - t1)
                q_summary = sorted(qs)[1]
                t1 = time.perf_counter()
                vm.trend(st, asset="pump-000")
                tr = time.perf_counter() - t1
                out.append((marks.pop(0), ms, q, q_summary, tr, len(df)))
    return out


def main(argv):
    n = int(argv[0]) if argv and argv[0].isdigit() else 100_000
    pg = argv[argv.index("--postgres") + 1] if "--postgres" in argv else None
    d = Path(tempfile.mkdtemp())
    engines = [("HDF5 (.h5)", d / "s.h5", min(n, 20_000), None), ("SQLite (.db, WAL)", d / "s.db", n, None)]
    if pg:
        engines.append(("PostgreSQL", pg, n, d / "raw"))
    if "--only" in argv:   # one engine: h5, sqlite or postgres
        want = argv[argv.index("--only") + 1].lower()
        engines = [e for e in engines if want in e[0].lower().replace("hdf5", "h5")]
    print(f"{ASSETS} assets measured hourly, commits of {PER_COMMIT} measurements with one result each\n")
    print(f"{'engine':20s} {'results':>9s} {'ms/commit':>10s} {'year query':>11s} {'summary only':>13s} "
          f"{'trend':>8s} {'rows':>6s}")
    for name, target, m, raw in engines:
        rows = run(target, m, raw)
        for k, ms, q, qs, tr, nrows in rows:
            print(f"{name:20s} {k:9d} {ms:10.1f} {q:9.3f} s {qs:11.3f} s {tr:6.3f} s {nrows:6d}")
        print(f"{name:20s} commit cost last / first: {rows[-1][1] / rows[0][1]:.2f}\n", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
