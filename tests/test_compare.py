"""Measured versus model and baseline: end to end, verdicts, implied stiffness change, trends, storage."""
import json

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure import models as M
from vibmeasure.cli import main


def test_end_to_end_ringdown_against_model():
    model = M.SDOF(m=2.0, k=2.0 * (2 * np.pi * 12.5) ** 2, zeta=0.015)
    rec = vm.synth.free_decay(fn=model.fn, zeta=model.zeta, fs=500.0, duration=20.0, snr_db=40, seed=1)
    c = vm.compare(vm.ringdown(rec), model)
    assert c.verdict == "ok" and len(c.rows) == 1
    # 5 % softer: the frequency falls by 2.5 % -> alarm; implied stiffness loss 5 % within 0.5 % of 5 %
    soft = M.SDOF(m=2.0, k=0.95 * model.k, zeta=0.015)
    rec = vm.synth.free_decay(fn=soft.fn, zeta=soft.zeta, fs=500.0, duration=20.0, snr_db=40, seed=2)
    c = vm.compare(vm.ringdown(rec), model)
    assert c.verdict == "alarm" and "fn -2.5" in c.reason
    assert c.rows[0]["implied_stiffness_change_pct"] == pytest.approx(-5.0, abs=0.025)  # 0.5 % of 5 %
    assert list(c.to_frame().columns)[:3] == ["fn_measured_hz", "fn_predicted_hz", "fn_dev_pct"]


def test_end_to_end_frf_against_mdof():
    Mm = np.diag([2.0, 1.0, 1.5])
    K = np.array([[30000.0, -10000, 0], [-10000, 20000, -10000], [0, -10000, 10000]])
    model = M.MDOF(Mm, K, modal_zeta=[0.02, 0.015, 0.01])
    f = np.arange(0, 40.05, 0.05)
    measured = vm.FRF(f, model.frf(f)[:, :1], "receptance", estimator="analytic",
                      outputs=("d0", "d1", "d2"), inputs=("d0",))
    est = vm.fit_modes(measured, band=(0.5, 40))
    c = vm.compare(est, model)
    assert c.verdict == "ok" and len(c.rows) == 3 and all(r["mac"] > 0.999 for r in c.rows)
    soft = model.scaled(k_scale=0.95)
    soft = M.MDOF(Mm, 0.95 * K, modal_zeta=[0.02, 0.015, 0.01])
    est2 = vm.fit_modes(vm.FRF(f, soft.frf(f)[:, :1], "receptance", estimator="analytic"), band=(0.5, 40))
    c2 = vm.compare(est2, model)
    assert c2.verdict == "alarm"
    np.testing.assert_allclose([r["implied_stiffness_change_pct"] for r in c2.rows], -5.0, atol=0.025)


def test_watch_zeta_and_unpaired():
    pred = vm.ModalEstimate(fn=[10.0, 30.0], zeta=[0.01, 0.01], fn_std=[0, 0], zeta_std=[0, 0])
    meas = vm.ModalEstimate(fn=[10.12, 55.0], zeta=[0.03, 0.02], fn_std=[0.01, 0.01], zeta_std=[0.001, 0.001])
    c = vm.compare(meas, pred)
    assert c.verdict == "watch" and c.unpaired_measured == (55.0,) and c.unpaired_predicted == (30.0,)
    with pytest.raises(vm.ParameterError, match="rtol_fn"):
        vm.compare(meas, pred, rtol_fn=0)
    with pytest.raises(vm.ParameterError, match="predicted must be"):
        vm.compare(meas, "model.toml")


def test_history_trend_and_hdf5(tmp_path):
    h = vm.History("pump 3 DE", baseline_count=2)
    rng = np.random.default_rng(0)
    for day in range(10):  # stiffness loss: fn falls 0.05 Hz a day from 50 Hz
        fn = 50.0 - 0.05 * day + rng.normal(0, 0.005)
        h.add(vm.ModalEstimate(fn=[fn], zeta=[0.02], fn_std=[0.005], zeta_std=[0.001]), time=float(day))
    tr = h.trend(threshold=49.0, horizon=15.0)
    assert tr["slope_per_time"] == pytest.approx(-0.05, abs=4 * tr["slope_std"])
    assert tr["crossing_time"] == pytest.approx(20.0, abs=1.0) and tr["verdict"] == "watch"
    assert h.baseline().fn[0] == pytest.approx(49.975, abs=0.01)
    p = tmp_path / "pump3.h5"
    h.save(p)
    back = vm.History.load(p)
    assert back.name == "pump 3 DE" and len(back.entries) == 10
    np.testing.assert_array_equal(back.entries[5][1].fn, h.entries[5][1].fn)
    assert vm.compare(h.entries[-1][1], back, rtol_fn=0.01).verdict == "watch"  # -0.87 % against 1 %
    with pytest.raises(vm.ParameterError, match="time=.* must increase"):
        h.add(h.entries[0][1], time=3.0)


def test_cli_model_and_compare(tmp_path):
    model = tmp_path / "m.toml"
    model.write_text('type = "sdof"\n[parameters]\nm = "2 kg"\nk = "12.337 kN/m"\nzeta = 0.015\n')
    s = M.load(model)
    rec = vm.synth.free_decay(fn=s.fn, zeta=0.015, fs=500.0, duration=20.0, snr_db=40, seed=3)
    p = vm.write(tmp_path / "test.csv", rec)
    import io
    out, err = io.StringIO(), io.StringIO()
    assert main(["model", str(model), "--json"], out=out, err=err) == 0
    assert json.loads(out.getvalue())["modes"][0]["fn_hz"] == pytest.approx(s.fn)
    out = io.StringIO()
    png = tmp_path / "cmp.png"
    assert main(["compare", str(p), "--model", str(model), "--json", "--plot", str(png)], out=out, err=err) == 0
    doc = json.loads(out.getvalue())
    assert doc["verdict"] == "ok" and png.exists()
    h = vm.History("beam")
    h.add(vm.ringdown(rec), time=0.0)
    base = tmp_path / "base.h5"
    h.save(base)
    out = io.StringIO()
    assert main(["compare", str(p), "--baseline", str(base), "--json"], out=out, err=err) == 0
    assert json.loads(out.getvalue())["verdict"] == "ok"
    # a structure 10 % softer in stiffness (fn -5 %): alarm, and the exit status says so for scripts
    soft = vm.write(tmp_path / "soft.csv", vm.synth.free_decay(fn=s.fn * 0.95, zeta=0.015, fs=500.0, duration=20.0,
                                                             snr_db=40, seed=4))
    out = io.StringIO()
    assert main(["compare", str(soft), "--model", str(model), "--json"], out=out, err=io.StringIO()) == 1
    assert json.loads(out.getvalue())["verdict"] == "alarm"
    err = io.StringIO()
    bad = tmp_path / "bad.toml"
    bad.write_text('type = "sdof"\n[parameters]\nm = 2\n')
    assert main(["model", str(bad)], out=io.StringIO(), err=err) == 2 and "has no unit" in err.getvalue()
