"""Condition monitoring across a fleet: the measurement store, batch analysis (serial and on a real
Dask LocalCluster), trends and alarms."""

import io
import json
import os
import random
import re
import signal
import subprocess
import sys
import textwrap
import time

import h5py
import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.io import store as store_mod

from ._forked import Forked


def _small_store(path, n=3, keep_raw=True):
    rng = np.random.default_rng(0)
    recs = []
    with vm.Store(path, writable=True) as st:
        st.add_asset("pump-1", bearing="6205-2RS", iso_group=2, meta={"site": "A"})
        st.add_point("pump-1", "DE", channel="acc", direction="horizontal", unit="g")
        for i in range(n):
            rec = vm.Record.from_array(rng.normal(size=(2, 500)), fs=1000.0, names=["a", "b"])
            recs.append(rec)
            mid = st.add_measurement("pump-1", "DE", time=f"2026-01-0{i + 1}T10:00:00", rpm=1480 + i, record=rec,
                                     keep_raw=keep_raw)
            st.add_result(mid, "spectrum", {"peaks_hz": [24.6, 49.3]}, params={"nperseg": 256},
                          summary={"rms": 0.1 * (i + 1), "peak1_hz": 24.6})
    return recs


def test_store_round_trip_is_exact(tmp_path):
    p = tmp_path / "s.h5"
    recs = _small_store(p)
    st = vm.Store(p)
    assert repr(st).startswith(f"Store({str(p)!r}: 1 assets, 1 points, 3 measurements, 3 results")
    df = st.results("spectrum", asset="pump-1")
    assert list(df["rms"]) == [0.1, 0.2, 0.30000000000000004]  # the floats, bit for bit
    assert list(df["time"].dt.day) == [1, 2, 3] and str(df["time"].dt.tz) == "UTC"
    assert df["params"][0] == {"nperseg": 256} and df["version"][0] == vm.__version__
    assert df["result"][1] == {"peaks_hz": [24.6, 49.3]}
    m = st.measurements()
    assert list(m["rpm"]) == [1480.0, 1481.0, 1482.0]
    back = st.record(m["id"][1])
    assert np.array_equal(back.data, recs[1].data) and back.fs == 1000.0 and back.channels == recs[1].channels
    assert st.assets()["meta"][0] == {"site": "A"}
    assert len(st.results("spectrum", since="2026-01-02", until="2026-01-02T23:00")) == 1


def test_store_finds_hashes_on_disk_and_keeps_no_rows_in_memory(tmp_path):
    import tracemalloc
    p = tmp_path / "s.h5"
    sha = lambda i: f"{i:064x}"  # noqa: E731
    twin = "0" * 16 + "f" * 48  # the same first 64 bits as sha(0): the index must confirm on disk
    tracemalloc.start()
    try:
        with vm.Store(p, writable=True) as st:
            st.add_asset("a")
            st.add_point("a", "p")
            for i in range(300):
                mid = st.add_measurement("a", "p", time=1e9 + i, sha256=sha(i))
                st.add_result(mid, "spectrum", {"payload": list(range(200))}, summary={"rms": float(i)})
                if i % 50 == 49:
                    st.commit()
                if i == 99:
                    before = tracemalloc.get_traced_memory()[0]
            grown = tracemalloc.get_traced_memory()[0] - before
            assert st.has(sha(7)) == "m0000008" and st.has(twin) is None and st.has(sha(300)) is None
            mid = st.add_measurement("a", "p", time=2e9, sha256=sha(7))  # pending: the latest wins
            assert st.has(sha(7)) == mid == "m0000301"
            st.add_measurement("a", "p", time=2e9 + 1)  # pending without a hash: no hash finds it
            assert st.has(None) is None and st.has("") is None
    finally:
        tracemalloc.stop()
    # after 200 more committed measurements with results, what stays is the hash index (16 bytes each)
    # and assets/points; holding the rows (about 2 kB each with summaries) would grow by ~400 kB
    assert grown < 200 * 100, grown
    st = vm.Store(p)
    assert st.has(sha(7)) == "m0000301" and st.has(sha(299)) == "m0000300" and st.n_measurements == 302
    with vm.Store(p, writable=True) as w:  # a reader's view is the file it opened: later commits only append
        w.add_result(w.add_measurement("a", "p", time=3e9), "spectrum", {}, summary={"rms": -1.0})
    assert len(st.results("spectrum")) == 300 and len(vm.Store(p).results("spectrum")) == 301
    assert st.n_measurements == 302 and vm.Store(p).n_measurements == 303
    with pytest.raises(vm.ParameterError, match="is not in store"):
        st.record("m0000999")


def test_store_refuses_another_schema_version(tmp_path, monkeypatch):
    p = tmp_path / "s.h5"
    monkeypatch.setattr(store_mod, "STORE_VERSION", 2)
    _small_store(p, n=1)
    monkeypatch.setattr(store_mod, "STORE_VERSION", 1)
    with pytest.raises(vm.ParameterError, match="has store schema version 2; this vibmeasure reads version 1"):
        vm.Store(p)


@pytest.mark.parametrize("damage", ["flip", "truncate"])
def test_a_damaged_store_is_a_named_error(tmp_path, damage):
    p = tmp_path / "s.h5"
    _small_store(p)
    raw = bytearray(p.read_bytes())
    if damage == "flip":
        raw[len(raw) // 2] ^= 0x10
    else:
        raw = raw[: len(raw) // 2]
    p.write_bytes(bytes(raw))
    with pytest.raises(vm.ParameterError, match="is damaged"):
        vm.Store(p)


def test_a_store_that_is_not_one_is_named(tmp_path):
    p = tmp_path / "plain.h5"
    with h5py.File(p, "w") as f:
        f["x"] = np.arange(3)
    with pytest.raises(vm.ParameterError, match="not a vibmeasure store"):
        vm.Store(p)
    with pytest.raises(vm.ParameterError, match="does not exist"):
        vm.Store(tmp_path / "missing.h5")


def test_a_read_only_store_cannot_be_written(tmp_path):
    p = tmp_path / "s.h5"
    _small_store(p, n=1)
    with pytest.raises(vm.ParameterError, match="open for reading"):
        vm.Store(p).add_asset("x")


HOLD = textwrap.dedent("""
    import sys, time
    import vibmeasure as vm
    st = vm.Store(sys.argv[1], writable=True)
    print("locked", flush=True)
    time.sleep(float(sys.argv[2]))
    st.close()
""")


def test_one_writer_at_a_time(tmp_path):
    p = tmp_path / "s.h5"
    proc = subprocess.Popen([sys.executable, "-c", HOLD, str(p), "1.5"], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "locked"
        with pytest.raises(vm.StoreLockedError, match=rf"being written by pid {proc.pid} on "):
            vm.Store(p, writable=True)
        t0 = time.monotonic()
        with vm.Store(p, writable=True, timeout=20) as st:  # waits for the holder to finish
            assert time.monotonic() - t0 > 0.2
            st.add_asset("a")
    finally:
        proc.wait(timeout=30)
    assert len(vm.Store(p).assets()) == 1


def _writer(path, *, out):
    """Measurements with their result and raw data, one commit each, until killed; prints the count."""
    st = vm.Store(path, writable=True)
    st.add_asset("a")
    st.add_point("a", "p")
    st.commit()
    for _ in range(100000):
        n = len(st.measurements())
        mid = st.add_measurement("a", "p", time=1.7e9 + n, record=vm.Record.from_array(np.full(2000, float(n)),
                                 fs=100.0), keep_raw=True)
        st.add_result(mid, "x", {"n": n}, summary={"n": n})
        st.commit()
        print(n + 1, file=out)


def test_kill_9_at_any_moment_leaves_every_committed_measurement(tmp_path):
    # 50 writers killed at random moments: the store always opens, holds at least every measurement
    # the writer had reported committed, and each measurement it holds is whole (result and raw data).
    # Every fifth writer is killed at a random moment from its start; the others at a random moment
    # after their first commit, whatever their start-up takes on a loaded machine
    rng = random.Random(11)
    p = tmp_path / "s.h5"
    for trial in range(50):
        proc = Forked(_writer, p)
        first = ""
        if trial % 5:
            first = proc.readline()
            assert first.strip(), "the writer ended before its first commit"
            time.sleep(rng.uniform(0.0, 0.6))
        else:
            time.sleep(rng.uniform(0.0, 0.5))
        out = first + proc.kill()
        reported = int(out.split()[-1]) if out.split() else 0
        if not p.exists():
            assert reported == 0
            continue
        with vm.Store(p) as st:
            m = st.measurements()
            assert len(m) >= reported
            res = st.results("x")
            assert len(res) == len(m)
            for mid in m["id"][-3:]:
                n = int(res.loc[res["measurement"] == mid, "n"].iloc[0])
                assert np.all(st.record(mid).data == n)
    leftovers = [f for f in os.listdir(tmp_path) if f.endswith(".part")]
    with vm.Store(p, writable=True) as st:  # the next writer cleans what killed ones left
        st.add_point("a", "q")
    assert len([f for f in os.listdir(tmp_path) if f.endswith(".part")]) <= len(leftovers) and \
        not [f for f in os.listdir(tmp_path) if f.endswith(".part")]


# --- batch ---------------------------------------------------------------------------------------

def _machines(folder, n):
    """n small machine records (1 s at 12.8 kHz) with a manifest; every 5th with an outer-race fault."""
    folder.mkdir()
    lines = ["file,asset,point,rpm,bearing,time"]
    for i in range(n):
        fault = "bearing_outer_race" if i % 5 == 0 else "none"
        rec = vm.synth.machine(fault=fault, rpm=1500.0, fs=12800.0, duration=1.0, seed=i, severity=0.5)
        vm.write(folder / f"r{i:03d}.h5", rec)
        lines.append(f"r{i:03d}.h5,m{i % 7},DE,1500,6205-2RS,2026-02-01T{i // 60:02d}:{i % 60:02d}:00")
    (folder / "manifest.csv").write_text("\n".join(lines) + "\n")
    return folder / "manifest.csv"


def _by_file(store, task):
    df = vm.Store(store).results(task)
    st = vm.Store(store).measurements()
    files = dict(zip(st["id"], st["file"]))
    return {os.path.basename(files[m]): r for m, r in zip(df["measurement"], df["result"])}


def test_batch_skips_what_is_stored_and_lists_bad_files(tmp_path):
    man = _machines(tmp_path / "in", 6)
    (tmp_path / "in" / "broken.h5").write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    with open(man, "a") as fh:
        fh.write("broken.h5,m9,DE,1500,6205-2RS,2026-02-02T00:00:00\n")
    calls = []
    rep = vm.batch(task="spectrum+diagnose", store=tmp_path / "s.h5", manifest=man,
                   progress=lambda done, total: calls.append((done, total)))
    assert list(rep["status"]).count("done") == 6 and list(rep["status"]).count("error") == 1
    # the total is said before the first input is analysed (a Ctrl-C then reads "0 of 7 stored")
    assert calls == [(k, 7) for k in range(8)]
    assert "broken.h5" in rep.loc[rep["status"] == "error", "file"].iloc[0]
    errs = vm.Store(tmp_path / "s.h5").errors()
    assert len(errs) == 1 and errs["failed_task"][0] == "read"
    diag = vm.Store(tmp_path / "s.h5").results("diagnose")
    assert list(diag["top"][diag["asset"] == "m0"]) == ["bearing_outer_race"]  # r000: the faulty one
    again = vm.batch(task="spectrum+diagnose", store=tmp_path / "s.h5", manifest=man)
    assert list(again["status"]).count("skipped") == 6  # same content, every task done: not analysed twice
    # an input that failed is tried again (it is still broken: a second error, no second measurement)
    assert again.loc[again["file"].str.endswith("broken.h5"), "status"].iloc[0] == "error"
    forced = vm.batch(task="spectrum", store=tmp_path / "s.h5", manifest=man, force=True)
    assert list(forced["status"]).count("done") == 6
    # force re-analyses into the measurements already stored: 7 measurements, not 14 or 21
    assert vm.Store(tmp_path / "s.h5").n_measurements == 7
    spec = vm.Store(tmp_path / "s.h5").results("spectrum")   # the re-analysis replaces the first
    assert len(spec) == 6 and spec["measurement"].nunique() == 6


def test_a_failed_input_is_analysed_again_once_its_manifest_is_fixed(tmp_path, shared_data):
    """No rpm in the manifest and none in the file: diagnose fails and is stored as an error; with the
    rpm added to the manifest a re-run analyses it (into the same measurement) instead of skipping it."""
    folder = tmp_path / "in"
    folder.mkdir()
    rec = vm.synth.machine(fault="bearing_outer_race", rpm=1500.0, fs=12800.0, duration=1.0, seed=3)
    vm.write(folder / "a.h5", vm.Record(rec.data, rec.fs, rec.channels))   # the speed left out of the file
    (folder / "m.csv").write_text("file,asset,point,bearing\na.h5,m1,DE,6205-2RS\n")
    first = vm.batch(task="diagnose", store=tmp_path / "s.db", manifest=folder / "m.csv")
    assert first["status"].tolist() == ["error"] and "shaft speed" in first["message"].iloc[0]
    (folder / "m.csv").write_text("file,asset,point,bearing,rpm\na.h5,m1,DE,6205-2RS,1500\n")
    second = vm.batch(task="diagnose", store=tmp_path / "s.db", manifest=folder / "m.csv")
    assert second["status"].tolist() == ["done"]
    st = vm.Store(tmp_path / "s.db")
    assert st.n_measurements == 1 and st.results("diagnose")["top"].tolist() == ["bearing_outer_race"]
    assert st.errors().empty   # the error is replaced by the new outcome
    third = vm.batch(task="diagnose", store=tmp_path / "s.db", manifest=folder / "m.csv")
    assert third["status"].tolist() == ["skipped"]


def test_files_and_a_manifest_and_sensors_by_channel(tmp_path):
    """A file given both as an input and in the manifest is analysed once, with the manifest's metadata;
    a row listed twice once. Two rows of one file on different channels are two points, each diagnosed
    from its own sensor only (a fault on one channel is not the other point's). A folder whose files
    carry time stamps for names (no readable suffix) is read; a row's unit and fs apply."""
    folder = tmp_path / "in"
    folder.mkdir()
    bad = vm.synth.machine(fault="bearing_outer_race", rpm=1500.0, fs=12800.0, duration=2.0, seed=5)
    good = vm.synth.machine(fault="none", rpm=1500.0, fs=12800.0, duration=2.0, seed=6)
    two = vm.Record.from_array(np.vstack([bad.data[0], good.data[0]]), fs=bad.fs, names=["de", "nde"], unit="g")
    vm.write(folder / "two.h5", two)
    (folder / "m.csv").write_text("file,asset,point,channel,rpm,bearing\n"
                                  "two.h5,pump,DE,de,1500,6205-2RS\ntwo.h5,pump,NDE,nde,1500,6205-2RS\n"
                                  "two.h5,pump,NDE,nde,1500,6205-2RS\n")
    rep = vm.batch([folder / "two.h5"], task="diagnose", store=tmp_path / "s.db", manifest=folder / "m.csv")
    assert rep["status"].tolist().count("done") == 2 and "listed twice" in " ".join(rep["message"].fillna(""))
    d = vm.Store(tmp_path / "s.db").results("diagnose").set_index("point")
    assert d.loc["DE", "top"] == "bearing_outer_race" and d.loc["NDE", "top"] == "none"
    stamped = tmp_path / "ims"
    stamped.mkdir()
    np.savetxt(stamped / "2004.02.12.10.32.39", good.data[0][:4096, None], delimiter="\t")
    (stamped / "rows.csv").write_text("file,asset,fs,unit\n2004.02.12.10.32.39,rig,12800,g\n")
    found = vm.batch([stamped], task="spectrum", store=tmp_path / "s2.db", manifest=stamped / "rows.csv")
    assert found["status"].tolist() == ["done"], found["message"].tolist()
    # a folder's own manifest is no record, even when the batch is not told it is the manifest
    (stamped / "other.csv").write_text("file,asset\n2004.02.12.10.32.39,rig\n")
    rep = vm.batch([stamped], task="spectrum", store=tmp_path / "s3.db", fs=12800.0)
    assert sorted(rep["status"]) == ["done", "skipped", "skipped"], rep.to_string()
    assert rep.loc[rep["status"] == "skipped", "message"].str.contains("a manifest, not a record").all()
    r = vm.Store(tmp_path / "s2.db").results("spectrum")
    assert r["result"].iloc[0]["unit"].startswith("g")


def test_manifest_rules(tmp_path):
    (tmp_path / "m.csv").write_text("file,asset,speed\nx.h5,a,3\n")
    with pytest.raises(vm.ParameterError, match=r"unknown column\(s\) \['speed'\]"):
        vm.read_manifest(tmp_path / "m.csv")
    (tmp_path / "m.csv").write_text("file,asset\nnothing*.h5,a\n")
    # a row's own rule breaks that row only: it comes back as an error item
    [row] = vm.read_manifest(tmp_path / "m.csv")
    assert "no file matches 'nothing*.h5'" in row["error"]
    with pytest.raises(vm.ParameterError, match="task='fft' must be one of"):
        vm.batch(tmp_path, task="fft", store=tmp_path / "s.h5")


def test_a_manifest_names_the_tachometer_of_run_ups(tmp_path):
    # two machines run up 1500 -> 2100 rpm; the manifest names the tachometer channel instead of an rpm
    (tmp_path / "in").mkdir()
    for i, fault in enumerate(("bearing_inner_race", "none")):
        vm.write(tmp_path / "in" / f"r{i}.h5", vm.synth.machine(fault=fault, rpm=(1500.0, 2100.0), tach=1, seed=i,
                                                              snr_db=10, duration=3.0))
    (tmp_path / "in" / "m.csv").write_text("file,asset,channel,tach,pulses_per_rev,bearing\n"
                                           "r0.h5,a,acc,tach,1,6205-2RS\nr1.h5,b,acc,tach,1,6205-2RS\n")
    rep = vm.batch(task="diagnose", store=tmp_path / "s.h5", manifest=tmp_path / "in" / "m.csv")
    assert list(rep["status"]) == ["done", "done"]
    diag = vm.Store(tmp_path / "s.h5").results("diagnose")
    assert dict(zip(diag["asset"], diag["top"])) == {"a": "bearing_inner_race", "b": "none"}
    (tmp_path / "in" / "bad.csv").write_text("file,asset,tach,pulses_per_rev\nr0.h5,a,tach,two\n")
    [row] = vm.read_manifest(tmp_path / "in" / "bad.csv")
    assert "pulses_per_rev='two' is not a whole number" in row["error"]


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as lc, distributed.Client(lc) as client:
        yield client


def test_dask_batch_equals_the_serial_run_item_by_item(tmp_path, cluster):
    # 40 inputs: 20 to each of the two workers, 8 of them faulty
    man = _machines(tmp_path / "in", 40)
    vm.batch(task="spectrum+diagnose", store=tmp_path / "serial.h5", manifest=man)
    rep = vm.batch(task="spectrum+diagnose", store=tmp_path / "dask.h5", manifest=man, client=cluster)
    assert list(rep["status"]).count("done") == 40
    for task in ("spectrum", "diagnose"):
        a, b = _by_file(tmp_path / "serial.h5", task), _by_file(tmp_path / "dask.h5", task)
        assert sorted(a) == sorted(b) and len(a) == 40
        for f in a:
            assert json.dumps(a[f], sort_keys=True) == json.dumps(b[f], sort_keys=True), f


def test_batch_on_an_existing_cluster_by_its_scheduler_address(tmp_path, cluster):
    man = _machines(tmp_path / "in", 10)
    rep = vm.batch(task="spectrum", store=tmp_path / "s.h5", manifest=man, scheduler=cluster.scheduler.address)
    assert list(rep["status"]).count("done") == 10
    assert len(vm.Store(tmp_path / "s.h5").results("spectra")) == 10  # the plural is understood too


def test_a_worker_killed_mid_batch_loses_no_result(tmp_path, cluster):
    man = _machines(tmp_path / "in", 40)
    pids = list(cluster.run(os.getpid).values())
    killed = []

    def progress(done, total):
        if done == 5 and not killed:
            os.kill(pids[0], signal.SIGKILL)  # the nanny starts a new worker; Dask reruns its tasks
            killed.append(pids[0])
    rep = vm.batch(task="diagnose", store=tmp_path / "s.h5", manifest=man, client=cluster, progress=progress)
    assert killed and list(rep["status"]).count("done") == 40
    assert len(vm.Store(tmp_path / "s.h5").results("diagnose")) == 40


# --- trends --------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def fleet_store(tmp_path_factory):
    d = tmp_path_factory.mktemp("fleet")
    vm.synth.fleet(d / "in", n_measurements=52, fault_onset=26)
    vm.batch(task="diagnose+spectrum", store=d / "fleet.h5", manifest=d / "in" / "machines.csv")
    vm.batch(task="ringdown+compare", store=d / "fleet.h5", manifest=d / "in" / "structures.csv")
    return d / "fleet.h5"


def test_the_growing_bearing_fault_alarms_on_its_own_machine_only(fleet_store):
    tr = vm.trend(fleet_store)
    assert tr.attrs["assets"] == {"frame-1": "alarm", "pump-1": "ok", "pump-2": "ok", "pump-3": "alarm"}
    healthy = tr[tr["asset"].isin(["pump-1", "pump-2"])]
    assert (healthy["n"] >= 50).all() and healthy["first_alarm"].isna().all()  # never, over 52 each
    be = tr[(tr["asset"] == "pump-3") & (tr["metric"] == "bearing_evidence")].iloc[0]
    onset = vm.Store(fleet_store).measurements(asset="pump-3")["time"].iloc[26]
    assert be["verdict"] == "alarm" and onset <= be["first_alarm"] <= onset + np.timedelta64(42, "D")
    assert vm.Store(fleet_store).results("diagnose", asset="pump-3")["top"].iloc[-1] == "bearing_outer_race"


def test_the_falling_stiffness_alarms_and_compare_sees_it(fleet_store):
    tr = vm.trend(fleet_store, asset="frame-1")
    fn = tr[tr["metric"] == "fn1_hz"].iloc[0]
    assert fn["verdict"] == "alarm" and fn["last"] < fn["alarm_limit"] < fn["baseline_mean"]
    assert fn["baseline_mean"] == pytest.approx(24.0, abs=0.01)  # the synthetic frame's fn
    cmp = vm.Store(fleet_store).results("compare", asset="frame-1")
    assert cmp["verdict"].iloc[0] == "ok" and cmp["verdict"].iloc[-1] == "alarm"  # 6 % stiffness: 3 % in fn


def test_trend_command_and_plot(fleet_store, tmp_path):
    from vibmeasure.cli import main
    import io
    out = io.StringIO()
    assert main(["trend", str(fleet_store), "--json", "--plot", str(tmp_path / "t.png")], out=out,
                err=io.StringIO()) == 0
    doc = json.loads(out.getvalue())
    assert doc["assets"]["pump-3"] == "alarm" and (tmp_path / "t.png").stat().st_size > 10_000


def test_trend_lists_every_asset_and_judges_a_fault_present_from_the_start(tmp_path):
    """No asset is left out: one with fewer measurements than the baseline needs reads "too few" (with
    its ISO zone where it is C or D). An asset diagnosed with an inner-race fault at 1.00 on every
    record is an alarm whatever its baseline (the baseline holds the fault). A warm-up slope over a few
    hours is not extrapolated weeks ahead. A measurement analysed twice counts once."""
    p = tmp_path / "s.db"
    t0 = 1.7e9
    with vm.Store(p, writable=True) as st:
        for a in ("faulty", "new", "zone-d", "warm"):
            st.add_asset(a)
            st.add_point(a, "DE")

        def diag(a, t, top, conf, v, zone="A"):
            mid = st.add_measurement(a, "DE", time=t)
            st.add_result(mid, "diagnose", {}, summary={"top": top, "confidence": conf, "velocity_rms_mm_s": v,
                                                       "zone": zone, "bearing_evidence": 1.0})
            return mid
        for k in range(12):
            mid = diag("faulty", t0 + 86400 * k, "bearing_inner_race", 1.0, 1.0 + 0.01 * (k % 3))
        st.add_result(mid, "diagnose", {}, summary={"top": "bearing_inner_race", "confidence": 1.0,
                                                   "velocity_rms_mm_s": 1.0, "zone": "A", "bearing_evidence": 1.0})
        diag("new", t0, "none", 0.9, 1.0)
        diag("zone-d", t0, "none", 0.9, 12.0, "D")
        diag("zone-d", t0 + 60, "none", 0.9, 12.5, "D")
        # 8 steady then a slow rise over 4.6 hours, within its limits
        for k in range(14):
            v = 2.0 + 0.002 * (k % 2) + (0.01 * (k - 7) if k >= 8 else 0.0)
            diag("warm", t0 + 1200 * k, "none", 0.95, v)
    tr = vm.trend(p, baseline_count=8)
    assets = tr.attrs["assets"]
    assert set(assets) == {"faulty", "new", "zone-d", "warm"}
    assert assets["faulty"] == "alarm" and assets["new"] == "no baseline yet" and assets["zone-d"] == "alarm"
    assert assets["warm"] == "ok", tr[tr.asset == "warm"][["metric", "verdict", "reason"]].to_string()
    row = tr[(tr.asset == "faulty") & (tr.metric == "diagnosis")].iloc[0]
    assert "bearing inner race named at 1.00 in the last two" in row.reason
    vel = tr[(tr.asset == "faulty") & (tr.metric == "velocity_rms_mm_s")].iloc[0]
    assert vel["n"] == 12   # the measurement with two results counts once
    assert tr[(tr.asset == "warm") & (tr.metric == "velocity_rms_mm_s")]["alarm_date"].isna().all()


def test_cli_batch_fails_when_every_input_failed_and_ctrl_c_is_one_line(tmp_path):
    """`vibmeasure batch` exits 1 when an input failed (the JSON document still lists the errors);
    Ctrl-C ends it with exit 130 and one line ("interrupted: N of M stored"), no traceback, the store
    readable and holding what was stored."""
    from vibmeasure.cli import main as cli_main
    (tmp_path / "a.csv").write_text("not,a,record\n")
    out, err = io.StringIO(), io.StringIO()
    code = cli_main(["batch", str(tmp_path / "a.csv"), "--store", str(tmp_path / "s.db"), "--task", "spectrum",
                     "--json"], out=out, err=err)
    assert code == 1 and "1 of 1 input(s) failed" in err.getvalue()
    assert json.loads(out.getvalue())["counts"] == {"error": 1}
    folder = tmp_path / "many"
    folder.mkdir()
    # long enough that Ctrl-C half a second after the store appears finds the batch running: 12 records
    # of 30 s, about a second each on a loaded 2-core machine (0.3 s on an idle one)
    for i in range(12):
        vm.write(folder / f"r{i:02d}.h5", vm.synth.machine(rpm=1500.0, fs=12800.0, duration=30.0, seed=i))
    # as from a terminal: a shell without job control starts background commands with SIGINT ignored,
    # and the child would inherit that (CI launched with `&` failed here with exit 0)
    proc = subprocess.Popen([sys.executable, "-m", "vibmeasure", "batch", str(folder), "--store",
                             str(tmp_path / "big.db"), "--task", "diagnose"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 60
    while not (tmp_path / "big.db").exists() and time.monotonic() < deadline:   # the batch has begun
        time.sleep(0.1)
    time.sleep(0.5)
    assert proc.poll() is None, "the batch ended before it could be interrupted"
    proc.send_signal(signal.SIGINT)
    _, errs = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in errs, errs[-800:]
    n = int(re.search(r"interrupted: (\d+) of 12 stored", errs).group(1))
    assert vm.Store(tmp_path / "big.db").n_measurements == n   # what it said it stored is there


def test_cli_batch_first_ctrl_c_waits_for_the_input_in_hand_and_a_second_does_not():
    """The first SIGINT only marks the batch to stop between inputs (an interrupt raised inside compiled
    code could end the interpreter by SIGINT instead of exit 130); a second one interrupts at once; the
    handler that was there before is back afterwards."""
    from vibmeasure.cli.batch import _stop_between_inputs
    before = signal.getsignal(signal.SIGINT)
    with _stop_between_inputs() as asked:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)   # the handler runs at the next bytecode boundary
        assert asked == [signal.SIGINT]
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)
    assert signal.getsignal(signal.SIGINT) is before


def _one_row_store(path):
    with vm.Store(path, writable=True) as st:
        st.add_asset("pump-1")
        st.add_point("pump-1", "DE")
        mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797,
                                 record=vm.synth.machine(rpm=1797, duration=0.2, seed=1), keep_raw=True)
        st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
    return mid


@pytest.mark.parametrize("kind", ["external_link", "external_storage", "virtual"])
def test_a_resealed_store_with_links_out_of_its_file_is_refused(tmp_path, kind):
    """Issue 48: an object that reads or writes another file is refused on opening, even past a valid seal."""
    from vibmeasure.io.hdf5 import seal
    p = tmp_path / "plant.h5"
    _one_row_store(p)
    other = tmp_path / "other.bin"
    other.write_bytes(b"secret" * 100)
    with h5py.File(p, "a") as f:
        if kind == "external_link":
            f["raw_extra"] = h5py.ExternalLink(str(other), "/x")
        elif kind == "external_storage":
            f.create_dataset("raw_extra", shape=(100,), dtype="u1", external=[(str(other), 0, 100)])
        else:
            layout = h5py.VirtualLayout(shape=(10,), dtype="f8")
            layout[:] = h5py.VirtualSource(str(other), "x", shape=(10,))
            f.create_virtual_dataset("raw_extra", layout)
    seal(p)
    with pytest.raises(vm.ParameterError, match="refused"):
        vm.Store(p)


def test_a_symlinked_store_locks_and_writes_the_real_file(tmp_path):
    """Issue 48: both names of one store exclude each other, and a commit leaves the link a link."""
    real, link = tmp_path / "plant.h5", tmp_path / "alias.h5"
    _one_row_store(real)
    link.symlink_to(real)
    with vm.Store(link, writable=True) as st:
        with pytest.raises(vm.StoreLockedError):
            vm.Store(real, writable=True)
        st.add_measurement("pump-1", "DE", time="2026-11-22T09:00", rpm=1797)
    assert link.is_symlink()
    assert vm.Store(real).n_measurements == 2
    fifo = tmp_path / "fifo.h5"
    os.mkfifo(fifo)
    with pytest.raises(vm.ParameterError, match="FIFO"):
        vm.Store(fifo)


def test_a_bad_manifest_row_is_its_own_error_and_the_batch_goes_on(tmp_path):
    """Issue 48: rpm NaN or negative, an unparsable time, a long or multi-line name: each row an error with
    its line and rule; the good rows are analysed."""
    vm.synth.fleet(tmp_path, n_measurements=2)
    good = (tmp_path / "machines.csv").read_text().splitlines()[1:]
    f1, f2, f3 = (line.split(",")[0] for line in good[:3])
    m = tmp_path / "bad.csv"
    m.write_text("file,asset,point,time,rpm\n"
                 f"{f1},pump-1,DE,2026-01-05T00:00:00,1484\n"
                 f"{f2},pump-2,DE,2026-01-05T00:00:00,nan\n"
                 f"{f3},pump-3,DE,someday,1465\n"
                 f'{f1},"pump\nfour",DE,2026-01-05T00:00:00,1484\n'
                 f"{f2},{'x' * 300},DE,2026-01-05T00:00:00,1466\n"
                 f"{f3},pump-3,DE,2026-01-05T00:00:00,-5\n")
    rep = vm.batch(manifest=m, store=tmp_path / "s.db")
    assert (rep["status"] == "done").sum() == 1
    errors = rep[rep["status"] == "error"]["message"].tolist()
    assert len(errors) == 5
    for rule in ("row 3 (the header is row 1): rpm=nan", "row 4 (the header is row 1): time='someday'",
                 "row 5 (the header is row 1): asset=", "row 6 (the header is row 1): asset=",
                 "row 7 (the header is row 1): rpm=-5.0"):
        assert any(rule in e for e in errors), (rule, errors)
    m.write_bytes(b"file,asset\n\xff\xfe.h5,a\n")
    with pytest.raises(vm.ParameterError, match="not UTF-8"):
        vm.read_manifest(m)


@pytest.mark.parametrize("address", ["tcp://", "tcp://host:notaport", "foo"])
def test_a_malformed_scheduler_address_is_named(tmp_path, address):
    vm.synth.fleet(tmp_path, n_measurements=2)
    with pytest.raises(vm.ParameterError, match="not a scheduler address"):
        vm.batch(manifest=tmp_path / "machines.csv", store=tmp_path / "s.db", scheduler=address)


@pytest.mark.parametrize("table,row", [("results", '{"measurement": "m0000001", "task": "diagnose"}'),
                                       ("measurements", '["m0000001"]'),
                                       ("results", '{"measurement": 7, "task": "diagnose", "summary": {}, '
                                                   '"params": {}}')])
def test_a_resealed_store_with_rows_of_the_wrong_shape_is_named(tmp_path, table, row):
    """Issue 48: trend and the queries of a store whose rows were rewritten (and the seal renewed) end in a
    ParameterError naming the table and the misfit, not a raw KeyError or TypeError."""
    from vibmeasure.io.hdf5 import seal
    p = tmp_path / "plant.h5"
    _one_row_store(p)
    with h5py.File(p, "a") as f:
        f[table][0] = row
    seal(p)
    with pytest.raises(vm.ParameterError, match=f"damaged: a row of {table}"):
        st = vm.Store(p)
        vm.trend(st)
