"""The database store: SQLite by default for a .db file, PostgreSQL for a plant (a real server the tests
start themselves), the HDF5 store migrated, and both engines held to the HDF5 store's contract."""

import json
import random
import sqlite3
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import vibmeasure as vm
from vibmeasure.cli import main as cli_main
from vibmeasure.io.sql import SQLStore

from ._forked import Forked


def _fill(st, n=3, raw=True):
    """One asset, one point, n measurements (raw kept) with one result each; returns the ids."""
    st.add_asset("pump-1", bearing="6205-2RS", iso_group=2, gear=32, meta={"site": "north"})
    st.add_point("pump-1", "DE", channel="acc", unit="g")
    ids = []
    for i in range(n):
        rec = vm.Record.from_array(np.arange(500.0) * (i + 1), fs=1000.0, names=["acc"], unit="g")
        mid = st.add_measurement("pump-1", "DE", time=1.7e9 + 3600 * i, rpm=1500.0 + i, record=rec, keep_raw=raw,
                                 file=f"r{i}.h5", meta={"i": i})
        st.add_result(mid, "diagnose", {"top": "none", "i": i}, params={"band": None},
                      summary={"top": "none", "confidence": 0.5 + 0.1 * i, "v": float("nan") if i == 1 else 1.0})
        ids.append(mid)
    return ids


def test_results_of_several_tasks_from_one_query_are_each_tasks_own_frame(target, tmp_path):
    """What a trend reads in one query (every trended task at once) is, task by task, exactly the frame
    ``results`` gives for that task alone: its own summary columns, its latest result per measurement,
    and on every store only the errors no later success replaced (``results("error")`` is ``errors()``)."""
    url, raw_dir = target
    for store_target in (tmp_path / "ref.h5", url):
        with vm.Store(store_target, writable=True, **({"raw_dir": raw_dir} if store_target == url else {})) as st:
            ids = _fill(st, raw=False)
            st.add_result(ids[0], "spectrum", {"rms": 2.0}, summary={"rms": 2.0, "peak_hz": 50.0})
            st.add_result(ids[1], "error", {"task": "spectrum", "message": "x"}, summary={"failed_task": "spectrum"})
            st.add_result(ids[1], "spectrum", {"rms": 3.0}, summary={"rms": 3.0})
            st.add_result(ids[2], "diagnose", {"top": "looseness"}, summary={"top": "looseness", "confidence": 0.9})
            st.add_result(ids[2], "error", {"task": "ringdown", "message": "y"}, summary={"failed_task": "ringdown"})
        st = vm.Store(store_target, **({"raw_dir": raw_dir} if store_target == url else {}))
        tasks = ["diagnosis", "spectrum", "error", "ringdown"]
        for lean in (True, False):
            frames = st._results_by_task(tasks, asset="pump-1", with_result=not lean)
            assert sorted(frames) == ["diagnose", "error", "ringdown", "spectrum"]
            for task, df in frames.items():
                pd.testing.assert_frame_equal(df, st.results(task, asset="pump-1", with_result=not lean))
        assert frames["diagnose"]["top"].tolist() == ["none", "none", "looseness"]
        assert frames["spectrum"]["rms"].tolist() == [2.0, 3.0] and "top" not in frames["spectrum"]
        assert frames["ringdown"].empty
        # ids[1]'s error was replaced by its spectrum; ids[2]'s came after its last success and stands
        assert frames["error"]["measurement"].tolist() == [ids[2]] == st.errors()["measurement"].tolist()


@pytest.fixture(params=["sqlite", "postgresql"])
def target(request, tmp_path):
    """A new database store's target on each engine."""
    if request.param == "sqlite":
        return str(tmp_path / "plant.db"), None
    return request.getfixturevalue("postgres")(), tmp_path / "raw"


def test_the_database_store_keeps_the_hdf5_stores_contract(target, tmp_path):
    """Everything written reads back exactly as from the HDF5 store: the same frames (asset, point and
    measurement columns, summary values as columns, NaN kept), the same ids, the raw record sample for
    sample, the content hash found, read-only refusals."""
    url, raw_dir = target
    with vm.Store(tmp_path / "ref.h5", writable=True) as h5:
        _fill(h5)
    with vm.Store(url, writable=True, raw_dir=raw_dir) as st:
        assert isinstance(st, SQLStore)
        ids = _fill(st)
        assert st.pending == 8
    ref, st = vm.Store(tmp_path / "ref.h5"), vm.Store(url, raw_dir=raw_dir)
    assert ids == ["m0000001", "m0000002", "m0000003"]
    assert repr(st).endswith("1 assets, 1 points, 3 measurements, 3 results)")
    for a, b in ((ref.assets(), st.assets()), (ref.points(), st.points())):
        assert a.to_dict("records") == b.to_dict("records")
    m_ref, m = ref.measurements(), st.measurements()
    assert m_ref.drop(columns="time").to_dict("records") == m.drop(columns="time").to_dict("records")
    assert (m_ref["time"] == m["time"]).all() and str(m["time"].dt.tz) == "UTC"
    r_ref, r = ref.results("diagnose"), st.results("diagnosis")   # the alias is understood
    for col in ("measurement", "asset", "point", "top", "confidence", "params", "result"):
        assert r_ref[col].tolist() == r[col].tolist(), col
    assert np.isnan(r["v"].iloc[1]) and r["v"].iloc[0] == 1.0
    # a trend reads the summary only: the same frame without the result documents, on both stores
    for store, full in ((ref, r_ref), (st, r)):
        lean = store.results("diagnose", with_result=False)
        assert "result" not in lean and lean.columns.tolist() == full.drop(columns="result").columns.tolist()
        assert lean["confidence"].tolist() == full["confidence"].tolist()
        with pytest.raises(vm.ParameterError, match="with_result='no' must be True or False"):
            store.results("diagnose", with_result="no")
    assert np.array_equal(st.record("m0000002").data, ref.record("m0000002").data)
    sha = m["sha256"].iloc[2]
    assert st.has(sha) == "m0000003" and st.has("0" * 64) is None
    assert len(st.results("diagnose", since=1.7e9 + 3600, until=1.7e9 + 3600)) == 1
    assert st.results("nothing").empty and st.errors().empty
    with pytest.raises(vm.ParameterError, match="open for reading"):
        st.add_asset("x")
    with pytest.raises(vm.ParameterError, match="is not in the store"):
        vm.Store(url, writable=True, raw_dir=raw_dir).add_result("m0000099", "x", {})
    with vm.Store(url, writable=True, raw_dir=raw_dir) as w:
        with pytest.raises(vm.ParameterError, match="different description"):
            w.add_asset("pump-1", bearing="6203-2RS")
        assert w.add_asset("pump-1", bearing="6205-2RS", iso_group=2, gear=32, meta={"site": "north"}) == "pump-1"


def test_sqlite_runs_in_wal_mode_and_readers_see_only_committed_rows(tmp_path):
    """WAL: a reader opened while a writer holds uncommitted rows reads the last commit, and the writer
    is not blocked by it; after the commit the same reader object sees the new rows."""
    p = tmp_path / "plant.db"
    w = vm.Store(p, writable=True)
    _fill(w, n=2, raw=False)
    w.commit()
    with sqlite3.connect(p) as c:
        assert c.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    w.add_measurement("pump-1", "DE", time=1.8e9)
    reader = vm.Store(p)
    assert reader.n_measurements == 2            # the pending third is not visible
    w.add_measurement("pump-1", "DE", time=1.8e9 + 1)   # the reader does not block the writer
    w.commit()
    assert reader.n_measurements == 4
    w.close()


def test_a_database_that_is_not_a_store_is_named(tmp_path):
    bad = tmp_path / "x.db"
    bad.write_bytes(b"not a database at all" * 100)
    with pytest.raises(vm.ParameterError, match="not a readable database"):
        vm.Store(bad)
    other = tmp_path / "other.db"
    with sqlite3.connect(other) as c:
        c.execute("CREATE TABLE people (name TEXT)")
    with pytest.raises(vm.ParameterError, match="database of something else"):
        vm.Store(other, writable=True)
    with pytest.raises(vm.ParameterError, match="does not exist"):
        vm.Store(tmp_path / "missing.db")
    with pytest.raises(vm.ParameterError, match="timeout='soon' must be a number of seconds"):
        vm.Store(tmp_path / "t.db", writable=True, timeout="soon")
    with pytest.raises(vm.ParameterError, match="raw_dir= is for a database store"):
        vm.Store(tmp_path / "s.h5", writable=True, raw_dir=tmp_path)


def _writer(path, raw_dir=None, count=100000, *, out):
    """``count`` measurements with their result and raw data, one commit each (or until killed); prints
    each id as it is committed."""
    st = vm.Store(path, writable=True, timeout=30, raw_dir=raw_dir)
    st.add_asset("a")
    st.add_point("a", "p")
    st.commit()
    for i in range(count):
        mid = st.add_measurement("a", "p", time=1.7e9 + i, record=vm.Record.from_array(np.full(2000, float(i)),
                                 fs=100.0), keep_raw=True)
        st.add_result(mid, "x", {"n": i}, summary={"n": i})
        st.commit()
        print(mid, file=out, flush=True)


# the same writer in a process of its own (python -c WRITER store raw_dir count), for writers at once
WRITER = textwrap.dedent(f"""
    import sys
    sys.path.insert(0, {str(Path(__file__).resolve().parents[1])!r})
    from tests.test_sqlstore import _writer
    _writer(sys.argv[1], sys.argv[2] or None, int(sys.argv[3]), out=sys.stdout)
""")


def test_kill_9_at_any_moment_loses_no_committed_row(tmp_path):
    """30 writers of one SQLite store killed at random moments: the store always opens, holds every
    measurement a writer reported committed, and each holds its result and its raw record. Every fifth
    writer is killed at a random moment from its start (often before its first commit); the others at a
    random moment after their first commit."""
    import sqlalchemy  # noqa: F401  (each fork starts with the engine imported, as a running writer has it)
    rng = random.Random(47)
    p = tmp_path / "s.db"
    reported = set()
    for trial in range(30):
        proc = Forked(_writer, p)
        if trial % 5:
            first = proc.readline().split()   # the first commit, then a random moment
            assert first, "the writer ended before its first commit"
            reported |= set(first)
            time.sleep(rng.uniform(0.0, 0.6))
        else:
            time.sleep(rng.uniform(0.0, 0.5))
        reported |= set(proc.kill().split())
    st = vm.Store(p)
    m = st.measurements()
    assert reported and reported <= set(m["id"])
    res = st.results("x")
    assert len(res) == len(m)
    for mid in m["id"].sample(10, random_state=1):
        n = int(res.loc[res["measurement"] == mid, "n"].iloc[0])
        assert np.all(st.record(mid).data == n)


def test_concurrent_writers_each_keep_every_row(target, tmp_path):
    """Four processes write one store at once (50 measurements each, a commit after each): 200 distinct
    ids, every result beside its measurement. SQLite serialises them (each waits for the others'
    transactions); PostgreSQL runs them side by side."""
    url, raw_dir = target
    args = [sys.executable, "-c", WRITER, url, str(raw_dir or ""), "50"]
    procs = [subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(4)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert all(p.returncode == 0 for p in procs), [e[-500:] for _, e in outs]
    ids = [mid for o, _ in outs for mid in o.split()]
    st = vm.Store(url, raw_dir=raw_dir)
    assert len(ids) == len(set(ids)) == 200 and set(st.measurements()["id"]) == set(ids)
    assert len(st.results("x")) == 200 and len(st.assets()) == 1


def test_migrate_copies_an_hdf5_store_exactly(target, tmp_path):
    """`vibmeasure store migrate old.h5 plant.db` (or a PostgreSQL URL): ids, rows and raw records as they
    were; a target that already holds measurements is refused; the HDF5 store stays readable."""
    url, raw_dir = target
    old = tmp_path / "old.h5"
    with vm.Store(old, writable=True) as st:
        _fill(st, n=4)
        st.add_asset("frame-1", kind="structure")
    argv = ["store", "migrate", str(old), url, "--json"] + (["--raw-dir", str(raw_dir)] if raw_dir else [])
    out, err = _Buf(), _Buf()
    assert cli_main(argv, out=out, err=err) == 0, err.text
    doc = json.loads(out.text)
    assert (doc["assets"], doc["points"], doc["measurements"], doc["results"], doc["raw"]) == (2, 1, 4, 4, 4)
    a, b = vm.Store(old), vm.Store(url, raw_dir=raw_dir)
    assert a.measurements()["id"].tolist() == b.measurements()["id"].tolist()
    assert a.results("diagnose")["result"].tolist() == b.results("diagnose")["result"].tolist()
    assert np.array_equal(a.record("m0000004").data, b.record("m0000004").data)
    with vm.Store(url, writable=True, raw_dir=raw_dir) as w:   # new ids continue after the copied ones
        assert w.add_measurement("pump-1", "DE", time=2e9) == "m0000005"
    assert cli_main(argv, out=_Buf(), err=(e := _Buf())) == 2 and "already holds measurements" in e.text
    out = _Buf()
    assert cli_main(["store", "info", url], out=out, err=_Buf()) == 0
    assert "5 measurements" in out.text


def test_batch_and_trend_on_a_database_store(tmp_path):
    """vm.batch writes a .db store as it writes an HDF5 one, re-runs skip what is stored, and vm.trend
    reads it."""
    folder = tmp_path / "in"
    folder.mkdir()
    for i in range(4):
        vm.write(folder / f"r{i}.h5", vm.synth.machine(rpm=1500.0, fs=12800.0, duration=1.0, seed=i))
    rep = vm.batch([folder], task="spectrum", store=tmp_path / "s.db")
    assert (rep["status"] == "done").all() and len(rep) == 4
    again = vm.batch([folder], task="spectrum", store=tmp_path / "s.db")
    assert (again["status"] == "skipped").all()
    assert len(vm.Store(tmp_path / "s.db").results("spectrum")) == 4


def test_a_batch_reads_only_its_inputs_rows_to_skip_them(tmp_path, monkeypatch):
    """The skip rule asks the database for the measurements of the inputs' contents (the sha256 index)
    and for those measurements' tasks, never for every measurement: a store of a million measurements
    took 10.7 s to read whole (PostgreSQL) before a batch of a few files could start. A new input beside
    stored ones is analysed, the stored ones with every task done are skipped, one missing a task gets
    that task only."""
    folder = tmp_path / "in"
    folder.mkdir()
    for i in range(3):
        vm.write(folder / f"r{i}.h5", vm.synth.machine(rpm=1500.0, fs=12800.0, duration=1.0, seed=i))
    with vm.Store(tmp_path / "s.db", writable=True) as st:   # other assets' history the batch must not read
        st.add_asset("other")
        st.add_point("other", "p")
        for k in range(300):
            st.add_result(st.add_measurement("other", "p", time=1.6e9 + k, sha256=f"{k:064x}"), "spectrum", {})
    vm.batch([folder / "r0.h5", folder / "r1.h5"], task="spectrum", store=tmp_path / "s.db")
    vm.batch([folder / "r1.h5"], task="diagnose", store=tmp_path / "s.db")

    def whole(*args, **kwargs):
        raise AssertionError("the batch read every measurement")
    monkeypatch.setattr(SQLStore, "measurements", whole)
    rep = vm.batch([folder], task="spectrum+diagnose", store=tmp_path / "s.db").set_index("file")
    status = {k.rsplit("/", 1)[-1]: v for k, v in rep["status"].items()}
    assert status == {"r0.h5": "done", "r1.h5": "skipped", "r2.h5": "done"}, rep
    monkeypatch.undo()
    con = sqlite3.connect(tmp_path / "s.db")
    rows = dict(con.execute("SELECT task, count(*) FROM results WHERE asset != 'other' GROUP BY task").fetchall())
    con.close()
    assert rows == {"spectrum": 3, "diagnose": 3}   # r0's spectrum was not analysed again, only its diagnosis


class _Buf:
    def __init__(self):
        self.parts = []

    def write(self, s):
        self.parts.append(s)

    def flush(self):
        pass

    def isatty(self):
        return False

    @property
    def text(self):
        return "".join(self.parts)


def test_a_postgresql_server_that_cannot_be_reached_is_named():
    with pytest.raises(vm.ParameterError, match="cannot be used"):
        vm.Store("postgresql://nobody@127.0.0.1:1/none", timeout=2)


@pytest.mark.parametrize("column,value", [("summary", "{not json"), ("params", "[1, 2]"), ("summary", "1, 2")])
def test_a_database_store_with_crafted_rows_is_named(tmp_path, column, value):
    """Issue 48's attacks on the database store: a stored value that is not JSON, or not the mapping a
    summary or params is, ends in a ParameterError, not a raw JSONDecodeError or TypeError."""
    import sqlite3
    p = tmp_path / "plant.db"
    with vm.Store(p, writable=True) as st:
        st.add_asset("pump-1")
        st.add_point("pump-1", "DE")
        mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797)
        st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
    con = sqlite3.connect(p)
    con.execute(f"UPDATE results SET {column} = ?", (value,))
    con.commit()
    con.close()
    with pytest.raises(vm.ParameterError, match="damaged"):
        vm.Store(p).results("diagnose")


def test_a_symlinked_database_store_writes_the_real_file(tmp_path):
    """Issue 48's symlink attack on the database store: the path is resolved, so the link stays a link
    and both names see the same rows."""
    real, link = tmp_path / "plant.db", tmp_path / "alias.db"
    with vm.Store(real, writable=True) as st:
        st.add_asset("pump-1")
    link.symlink_to(real)
    with vm.Store(link, writable=True) as st:
        st.add_asset("pump-2")
    assert link.is_symlink()
    assert sorted(vm.Store(real).assets()["asset"]) == ["pump-1", "pump-2"]


def test_the_alarm_history_keeps_each_change_of_verdict(target, tmp_path):
    """Issue 47: the database holds alarms and their history. Each change of a trend verdict per asset,
    point and metric is one row (the first evaluation starts the history); the same verdicts again
    write nothing; a metric that returns to ok is a new row; a store from before the table reads an
    empty history."""
    import pandas as pd
    url, raw = target
    with vm.Store(url, writable=True, raw_dir=raw) as st:
        def verdicts(v, last):
            return pd.DataFrame({"asset": ["pump-1"], "point": ["DE"], "task": ["diagnose"],
                                 "metric": ["velocity_rms_mm_s"], "verdict": [v], "last": [last],
                                 "watch_limit": [2.8], "alarm_limit": [4.5], "reason": [f"velocity {last}"],
                                 "last_time": [pd.Timestamp("2026-11-28T08:00", tz="UTC")]})
        assert st.record_verdicts(verdicts("ok", 1.0)) == 1
        assert st.record_verdicts(verdicts("ok", 1.1)) == 0             # no change, no row
        assert st.record_verdicts(verdicts("alarm", 7.2)) == 1
        assert st.record_verdicts(verdicts("ok", 1.2)) == 1             # cleared: its own row
        with pytest.raises(vm.ParameterError, match="must be a vm.trend frame"):
            st.record_verdicts([{"asset": "pump-1"}])
        with pytest.raises(vm.ParameterError, match="verdict values must be"):
            st.record_verdicts(verdicts("red", 9.0))
    h = vm.Store(url, raw_dir=raw).alarms(asset="pump-1")
    assert h["verdict"].tolist() == ["ok", "alarm", "ok"]
    assert h["limit"].tolist()[1] == 4.5 and h["value"].tolist() == [1.0, 7.2, 1.2]
    assert str(h["time"].iloc[0]) == "2026-11-28 08:00:00+00:00"


def test_batch_records_the_alarms_of_the_assets_it_ran(tmp_path):
    """vm.batch writes the touched assets' verdict changes into the history: a pump whose last two
    records carry an outer-race fault is in alarm from that run on; a re-run adds nothing."""
    lines = ["file,asset,point,rpm,bearing,time"]
    for i in range(12):
        rec = vm.synth.machine(fault="none" if i < 10 else "bearing_outer_race", rpm=1500.0, fs=25600.0,
                               duration=1.0, seed=i)
        vm.write(tmp_path / f"r{i}.h5", rec)
        lines.append(f"r{i}.h5,pump,DE,1500,6205-2RS,2026-03-{i + 1:02d}T00:00:00")
    (tmp_path / "m.csv").write_text("\n".join(lines) + "\n")
    vm.batch(manifest=tmp_path / "m.csv", task="diagnose", store=tmp_path / "plant.db")
    h = vm.Store(tmp_path / "plant.db").alarms()
    got = dict(zip(h["metric"], h["verdict"]))
    assert got["diagnosis"] == "alarm" and "bearing outer race" in h[h["metric"] == "diagnosis"]["reason"].iloc[0]
    vm.batch(manifest=tmp_path / "m.csv", task="diagnose", store=tmp_path / "plant.db")
    assert len(vm.Store(tmp_path / "plant.db").alarms()) == len(h)
    import io
    from vibmeasure.cli import main
    out = io.StringIO()
    assert main(["store", "alarms", str(tmp_path / "plant.db")], out=out, err=io.StringIO()) == 0
    assert "pump/DE  diagnosis: alarm" in out.getvalue() and "bearing outer race named at" in out.getvalue()


def _as_version_1(url):
    """The store made as version 1 wrote it: results without their asset, point and time."""
    import sqlalchemy as sa
    from vibmeasure.io.sql.schema import _url
    engine = sa.create_engine(_url(url))
    with engine.begin() as c:
        for index in ("ix_results_asset_task_time", "ix_results_wide"):
            c.execute(sa.text(f"DROP INDEX IF EXISTS {index}"))
        for col in ("asset", "point", '"time"'):
            c.execute(sa.text(f"ALTER TABLE results DROP COLUMN {col}"))
        c.execute(sa.text("UPDATE vibmeasure SET value = '1' WHERE key = 'schema_version'"))
    engine.dispose()


def test_a_version_1_store_is_read_through_the_join_and_upgraded_by_a_writer(target, tmp_path):
    """A store written before results carried their asset, point and time: a reader answers as before
    (through the join with the measurements), the first writer copies the columns in (version 2), and
    both give exactly the frames the store gave when it was written."""
    url, raw_dir = target
    kw = {"raw_dir": raw_dir} if raw_dir else {}
    with vm.Store(url, writable=True, **kw) as st:
        ids = _fill(st, n=4, raw=False)
        st.add_result(ids[1], "spectrum", {"rms": 3.0}, summary={"rms": 3.0})
        st.add_result(ids[2], "diagnose", {"top": "looseness"}, summary={"top": "looseness", "confidence": 0.9})
    tasks = ["diagnose", "spectrum", "error"]
    with vm.Store(url, **kw) as st:
        want = st._results_by_task(tasks, asset="pump-1", with_result=True)
    _as_version_1(url)
    with vm.Store(url, **kw) as st:
        assert st._joined
        got = st._results_by_task(tasks, asset="pump-1", with_result=True)
        for task in tasks:
            pd.testing.assert_frame_equal(got[task], want[task])
    with vm.Store(url, writable=True, **kw) as st:
        assert not st._joined
        mid = st.add_measurement("pump-1", "DE", time=1.8e9)
        st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none", "confidence": 0.2})
    import sqlalchemy as sa
    with vm.Store(url, **kw) as st:
        assert not st._joined
        assert st._conn.execute(sa.text("SELECT value FROM vibmeasure WHERE key = 'schema_version'")).scalar() == "2"
        assert st._conn.execute(sa.text("SELECT count(*) FROM results WHERE asset IS NULL")).scalar() == 0
        got = st._results_by_task(tasks, asset="pump-1", with_result=True)
        for task in ("spectrum", "error"):
            pd.testing.assert_frame_equal(got[task], want[task])
        pd.testing.assert_frame_equal(got["diagnose"].iloc[:-1], want["diagnose"])
        assert got["diagnose"]["measurement"].iloc[-1] == mid


def test_writers_that_open_a_version_1_store_at_once_upgrade_it_once(target, tmp_path):
    """A plant's collectors updated together each open the version-1 store for writing at the same
    moment: one upgrades it, the others wait for it or find the work done; every writer then writes,
    and no result is left without its asset, point and time."""
    import sqlalchemy as sa
    url, raw_dir = target
    kw = {"raw_dir": raw_dir} if raw_dir else {}
    with vm.Store(url, writable=True, **kw) as st:
        st.add_asset("a")
        st.add_point("a", "p")
        for i in range(200):
            st.add_result(st.add_measurement("a", "p", time=1.6e9 + i), "x", {"n": -i}, summary={"n": -i})
    _as_version_1(url)
    args = [sys.executable, "-c", WRITER, url, str(raw_dir or ""), "10"]
    procs = [subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(4)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert all(p.returncode == 0 for p in procs), [e[-500:] for _, e in outs]
    with vm.Store(url, **kw) as st:
        assert st._conn.execute(sa.text("SELECT value FROM vibmeasure WHERE key = 'schema_version'")).scalar() == "2"
        assert st._conn.execute(sa.text("SELECT count(*) FROM results WHERE asset IS NULL")).scalar() == 0
        got = st.results("x", asset="a")
    assert len(got) == 240 and got["time"].is_monotonic_increasing


def test_postgresql_reads_a_trend_from_the_covering_index_and_keeps_wide_rows(postgres, tmp_path):
    """On PostgreSQL the query a trend makes is answered from the covering index alone (an index-only
    scan: one asset's rows are adjacent there, while in the table they lie one per block); a result
    too wide for a B-tree entry (2,704 bytes) is stored all the same and comes back in its place."""
    import sqlalchemy as sa
    url = postgres()
    with vm.Store(url, writable=True, raw_dir=tmp_path / "raw") as st:
        st.add_asset("pump-1")
        st.add_point("pump-1", "DE")
        rng = random.Random(3)
        for i in range(40):
            mid = st.add_measurement("pump-1", "DE", time=1.7e9 + 3600 * i)
            # row 17 over the entry's limit even if compressed 2:1; row 23 just under the covering index's
            # bound, in text that does not compress: its entry (with header and fixed columns) must fit
            note = "x" * 6000 if i == 17 else "".join(rng.choice("0123456789abcdef") for _ in range(2280)) \
                if i == 23 else ""
            st.add_result(mid, "diagnose", {"i": i}, summary={"top": "none", "confidence": 0.01 * i, "note": note})
    engine = sa.create_engine(url.replace("postgresql://", "postgresql+psycopg://"))
    with engine.connect().execution_options(isolation_level="AUTOCOMMIT") as c:
        c.execute(sa.text("VACUUM ANALYZE results"))
    engine.dispose()
    with vm.Store(url, raw_dir=tmp_path / "raw") as st:
        df = st.results("diagnose", asset="pump-1", with_result=False)
        assert df["confidence"].tolist() == pytest.approx([0.01 * i for i in range(40)], abs=1e-12)
        assert len(df["note"].iloc[17]) == 6000 and len(df["note"].iloc[23]) == 2280
        from vibmeasure.io.sql.schema import WIDE_BYTES, _tables, _wide
        r = _tables()["results"]
        size = _wide(r).left   # the byte count the predicate compares
        sizes = [v for (v,) in st._conn.execute(sa.select(size).order_by(r.c.id))]
        assert WIDE_BYTES - 100 < sizes[23] <= WIDE_BYTES < sizes[17]
        stmt = st._results_statement(["diagnose"], "pump-1", None, 1.7e9, 1.8e9, False)
        # a table this small is read faster whole: the plain scans are ruled out to see which index serves
        # the query as the store sends it (its values bound, not written into the text)
        st._conn.execute(sa.text("SET enable_seqscan = off"))
        st._conn.execute(sa.text("SET enable_bitmapscan = off"))
        compiled = stmt.compile(dialect=st._conn.dialect, compile_kwargs={"render_postcompile": True})
        plan = "\n".join(r[0] for r in st._conn.exec_driver_sql("EXPLAIN " + str(compiled), compiled.params))
    assert "Index Only Scan using ix_results_asset_task_time" in plan, plan
    assert "ix_results_wide" in plan, plan


def test_a_version_1_store_a_writer_may_not_alter_is_named_and_still_read(postgres, tmp_path):
    """A plant's collector often writes under a role that may insert but not alter tables: opening a
    version-1 store for writing then names the rule (ParameterError, no retry loop, no traceback from
    the driver), and the store is still read as it is."""
    import psycopg
    url = postgres()
    with vm.Store(url, writable=True, raw_dir=tmp_path / "raw") as st:
        _fill(st, n=2, raw=False)
    _as_version_1(url)
    with psycopg.connect(url, autocommit=True) as c:
        c.execute("CREATE ROLE collector LOGIN")
        c.execute("GRANT SELECT, INSERT, UPDATE ON ALL TABLES IN SCHEMA public TO collector")
    as_collector = url.replace("vibmeasure@", "collector@")
    t0 = time.monotonic()
    with pytest.raises(vm.ParameterError, match="schema_version 1 and could not be upgraded.*may alter"):
        vm.Store(as_collector, writable=True, raw_dir=tmp_path / "raw")
    assert time.monotonic() - t0 < 10.0
    with vm.Store(as_collector, raw_dir=tmp_path / "raw") as st:
        assert st.results("diagnose")["confidence"].tolist() == pytest.approx([0.5, 0.6])


@pytest.mark.parametrize("name", ["plant.h5", "plant.db"])
def test_an_empty_store_s_frames_keep_their_columns(tmp_path, name):
    """A store whose writer was killed before its first measurement committed holds assets but no
    measurement: ``measurements()["id"]`` is an empty column on both back-ends (the HDF5 store gave a
    frame without columns, a KeyError on "id"), and so are the points of an asset without one."""
    path = tmp_path / name
    with vm.Store(path, writable=True) as st:
        st.add_asset("pump-1")
    st = vm.Store(path)
    for frame in (st.measurements(), st.measurements(asset="pump-1", since="2026-01-01")):
        assert frame.empty and {"id", "asset", "point", "time", "rpm", "file"} <= set(frame.columns)
    assert st.measurements()["id"].tolist() == []
    assert {"asset", "point", "channel", "unit"} <= set(st.points().columns)
