"""Damage of the recording chain in the samples: isolated spikes (found, repaired), dropouts, clipping;
and what diagnose does with them."""

import json
import warnings

import numpy as np
import pytest
import scipy.io as sio

import vibmeasure as vm
from vibmeasure.signal import quality as q


def _machine(fault="none", seed=900, **kw):
    kw = {"rpm": 1797, "fs": 12000, "duration": 6.0, "bearing": "6205-2RS", "snr_db": 0, **kw}
    return vm.synth.machine(fault=fault, seed=seed, **kw)


def test_isolated_spikes_are_found_exactly_and_nothing_else(rng):
    """Random single-sample spikes of 30 x the RMS, each sign, 5 a second, on a synthetic bearing fault
    whose impacts ring through a 3.5 kHz resonance: every one found, no sample of the vibration."""
    x = _machine("bearing_outer_race").data[0].astype(float)
    assert q.isolated_spikes(x).size == 0   # the impacts ring over many samples: none is isolated
    idx = np.sort(rng.choice(np.arange(100, x.size - 100), size=30, replace=False))
    y = x.copy()
    y[idx] += 30 * x.std() * rng.choice([-1.0, 1.0], idx.size)
    np.testing.assert_array_equal(q.isolated_spikes(y), idx)


def test_two_spikes_close_together_are_both_found():
    """Two spikes 5 samples apart hide each other from a test against the largest sample near each;
    single candidates do not count against each other."""
    x = _machine().data[0].astype(float)
    y = x.copy()
    y[[5000, 5005, 9000]] += 25 * x.std()
    np.testing.assert_array_equal(q.isolated_spikes(y), [5000, 5005, 9000])


def test_a_regular_spike_train_is_found_whole_on_its_grid(rng):
    """A glitch every 1024 samples whose size varies (6-40 x the residual's robust spread): the test
    alone finds the large ones only; once five or more sit on one grid of a fixed interval, every
    position of the grid that stands out at all (GRID_SIGMA, 3) is one."""
    x = _machine("bearing_inner_race").data[0].astype(float)
    y = x.copy()
    idx = np.arange(300, x.size, 1024)
    y[idx] += rng.uniform(6, 40, idx.size) * q._residual(x)[1]
    strict = q._spikes_once(y, q.SPIKE_SIGMA, q.SPIKE_ISOLATION)
    assert 5 <= strict.size <= 0.9 * idx.size   # the single test misses the smaller ones ...
    assert q._grid(strict) == (300, 1024)       # ... but sees the grid
    np.testing.assert_array_equal(q.isolated_spikes(y), idx)


def test_an_impact_ringing_near_nyquist_is_no_spike():
    """A decaying tone at 0.45 fs (2 % damping) 40 x the noise: every other sample is far out, so the
    candidates make a burst; and a 0.3 % wiggle on a smooth, oversampled ring-down is no spike (it
    stands far above the residual's tiny spread, not above the record's own)."""
    fs, n = 12000.0, 4000
    t = np.arange(n) / fs
    noise = np.random.default_rng(1).normal(size=n)
    ring = np.where(t > 0.1, 40 * np.exp(-2 * np.pi * 0.45 * fs * 0.02 * (t - 0.1)) *
                    np.sin(2 * np.pi * 0.45 * fs * (t - 0.1)), 0.0)
    assert q.isolated_spikes(noise + ring).size == 0
    slow = np.exp(-0.5 * t) * np.sin(2 * np.pi * 5 * t)
    slow[2000] += 0.003 * slow.std()
    assert q.isolated_spikes(slow).size == 0


def test_no_spike_on_any_channel_of_the_real_recordings(shared_data):
    """Every channel of the development recordings (CWRU drive- and fan-end at 12 kHz, impacts of
    seeded faults included; MFPT at 48.8 kHz): no spike found, even with both thresholds lowered to
    8 sigma and 3 x (the first false find is at 6 sigma and 3 x, on one CWRU channel), and no dropout.
    One channel is saturated: CWRU fan-end OR007@12_0's fan-end sensor holds 14 samples at exactly
    +0.66579 and 9 at -0.66584, its converter's range."""
    files = sorted(shared_data("cwru_fe").glob("*.mat")) + sorted(shared_data("cwru").glob("*.mat"))
    n_ch, saturated = 0, []
    for f in files + sorted(shared_data("mfpt").glob("*.mat")):
        m = sio.loadmat(f, squeeze_me=True)
        if "bearing" in m:
            chans = {"gs": np.asarray(m["bearing"]["gs"].item(), float)}
        else:
            chans = {k: np.asarray(v, float).ravel() for k, v in m.items() if k.endswith("_time")}
        for k, x in chans.items():
            n_ch += 1
            assert q.isolated_spikes(x, sigma=8.0, isolation=3.0).size == 0, f.name
            assert not q.flat_runs(x, 12000.0), f.name
            if q.clipped_share(x) > 0:
                saturated.append((f.name, k, round(q.clipped_share(x) * x.size)))
    assert n_ch >= 150
    assert saturated == [("OR007@12_0.mat", "X302_FE_time", 23)]


def test_despike_repairs_and_says_so():
    rec = _machine("bearing_outer_race")
    x = rec.data[0].astype(float)
    y = x.copy()
    y[[1000, 20000]] += 30 * x.std()
    bad = vm.Record.from_array(y, fs=rec.fs, names=["acc"], unit="g")
    with pytest.warns(vm.QualityWarning, match="channel 'acc': 2 isolated spikes replaced"):
        fixed = vm.despike(bad)
    for i in (1000, 20000):
        assert fixed.data[0, i] == pytest.approx(0.5 * (y[i - 1] + y[i + 1]), rel=1e-12)
    # the repair is the neighbours' mean: off the true sample by the curvature there, far below the spike
    assert np.max(np.abs(fixed.data[0] - x)) < 3 * x.std()
    assert "despike" in fixed.history[-1]
    clean = vm.Record.from_array(x, fs=rec.fs, names=["acc"], unit="g")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert vm.despike(clean) is clean
    for kw, rule in (({"sigma": 2.0}, "sigma=2.0 must be a number >= 3"), ({"isolation": True}, "isolation=True"),
                     ({"sigma": np.nan}, "sigma=nan")):
        with pytest.raises(vm.ParameterError, match=rule):
            vm.despike(clean, **kw)
    y[5] = np.nan
    with pytest.raises(vm.ParameterError, match="NaN/inf"):
        vm.despike(vm.Record.from_array(y, fs=rec.fs))
    with pytest.raises(vm.ParameterError, match="fs"):
        vm.despike(x)


def test_dropouts_and_clipping_are_measured():
    x = _machine("bearing_outer_race").data[0].astype(float)
    y = x.copy()
    y[3000:3120] = 0.0               # 10 ms held at zero
    assert q.flat_runs(y, 12000.0) == [(3000, 3120)]
    assert q.flat_runs(y[:3000], 12000.0) == []
    c = np.clip(x, -2 * x.std(), 2 * x.std())
    assert 0.0 < q.clipped_share(c) < 0.2 and q.clipped_share(x) == 0.0


def test_diagnose_a_healthy_machine_with_a_glitch_every_1024_samples():
    """At 12 kHz a glitch every 1024 samples repeats at 11.72 Hz, 1.8 % under the 6205's cage frequency at
    1797 rpm: its 9th, 18th and 27th harmonics fall on BPFO x 1-3. Unrepaired, healthy machines were
    called outer race (3 seeds of 3 at confidence 0.99-1.0, 21972bd). The repairs leave a comb at
    fs / 1024 of their own (the samples they rebuild are not the lost ones), which is claimed."""
    for seed in (900, 901):
        rec = _machine(seed=seed)
        x = rec.data[0].astype(float)
        x[::1024] += 30 * x.std()
        with pytest.warns(vm.QualityWarning, match="one every 1024 samples"):
            d = vm.diagnose(vm.Record.from_array(x, fs=rec.fs, names=["acc"], unit="g"), rpm=1797, bearing="6205-2RS")
        assert d.top == "none", (seed, d.reason)
        assert "spikes_removed" in d.flags and d.extras["data_quality"]["acc"]["spike_interval_samples"] == 1024
        assert d.extras["data_quality"]["acc"]["spikes_removed"] == len(range(0, x.size, 1024))
        assert "isolated spikes" in d.reason


def test_diagnose_makes_no_wrong_call_from_a_glitch_train_on_real_records(shared_data):
    """A spike of 30 x each channel's RMS every 1024 samples on CWRU fan-end records: unrepaired
    (21972bd), B007_2 (ball, "none" as recorded) was called inner race and OR007@3_3 (outer race) ball.
    Repaired, with the glitch comb claimed: no wrong call. OR007@3_3's outer race stays the strongest
    bearing candidate (p below 0.001) but shows in one view only and is not called (as recorded it is
    called at p = 4e-8 in three): what the repairs cannot restore costs it evidence."""
    for name, truth in (("B007_2", "bearing_ball"), ("OR007@3_3", "bearing_outer_race")):
        rec = vm.read(shared_data(f"cwru_fe/{name}.mat"), fs=12000, unit="g")
        data = rec.data.astype(float).copy()
        data[:, 512::1024] += 30 * data.std(axis=1, keepdims=True)
        bad = vm.Record.from_array(data, fs=rec.fs, names=list(rec.names), unit="g")
        with pytest.warns(vm.QualityWarning, match="isolated spikes"):
            d = vm.diagnose(bad, rpm=rec.meta["rpm"], bearing="6203-2RS")
        assert d.top in ("none", truth), (name, d.reason)
        assert set(d.extras["data_quality"]) == set(rec.names)
        assert all(v["spike_interval_samples"] == 1024 for v in d.extras["data_quality"].values())
    fam = d.extras["bearing"]["bearing_outer_race"]
    assert fam["p_value"] < 1e-3


def test_diagnose_reports_dropouts_and_saturation():
    rec = _machine("bearing_outer_race")
    x = rec.data[0].astype(float)
    x[6000:6120] = 0.0
    x = np.clip(x, -4 * x.std(), 4 * x.std())
    with pytest.warns(vm.QualityWarning, match=r"1 dropout .*0\.01 s in all.*saturated"):
        d = vm.diagnose(vm.Record.from_array(x, fs=rec.fs, names=["acc"], unit="g"), rpm=1797, bearing="6205-2RS")
    assert {"dropouts", "saturated"} <= set(d.flags)
    assert d.top == "bearing_outer_race"
    clean = vm.diagnose(rec, rpm=1797, bearing="6205-2RS")
    assert "data_quality" not in clean.extras and not {"spikes_removed", "dropouts", "saturated"} & set(clean.flags)
    # the clipped peaks are lost: the severity reads lower than the clean record's and says it is a bound
    assert d.severity["lower_bound"] and "lower bound" in d.severity["note"]
    assert d.severity["velocity_rms_mm_s"] < clean.severity["velocity_rms_mm_s"]
    assert "lower_bound" not in clean.severity


def test_the_command_line_prints_the_damage_as_a_warning(tmp_path):
    """vibmeasure diagnose: the damage found goes to stderr as "vibmeasure: warning: ..." and into the
    JSON document's "warnings" (as the other commands' quality warnings do), not as Python's raw
    warning with a source line."""
    from tests.test_cli import run
    rec = _machine()
    x = rec.data[0].astype(float)
    x[::1024] += 30 * x.std()
    f = tmp_path / "glitchy.h5"
    vm.write(f, vm.Record.from_array(x, fs=rec.fs, names=["acc"], unit="g"))
    code, out, err = run(["diagnose", str(f), "--rpm", "1797", "--bearing", "6205-2RS"])
    assert code == 0 and out.startswith(f"{f}: NONE")
    assert err.startswith("vibmeasure: warning: diagnose: channel 'acc': 71 isolated spikes") and "cli.py" not in err
    code, out, err = run(["diagnose", str(f), "--rpm", "1797", "--bearing", "6205-2RS", "--json"])
    doc = json.loads(out)
    assert doc["flags"] == ["spikes_removed"] and "one every 1024 samples" in doc["warnings"][0]


def test_the_measures_refuse_bad_input():
    x = np.zeros(100)
    for f in (q.isolated_spikes, q.clipped_share, lambda a: q.flat_runs(a, 100.0)):
        with pytest.raises(vm.ParameterError, match=r"x must be one channel's samples \(1-D\), got shape \(2, 50\)"):
            f(x.reshape(2, 50))
        with pytest.raises(vm.ParameterError, match="x has NaN/inf samples .first at index 3."):
            f(np.where(np.arange(100) == 3, np.nan, 0.0))
        with pytest.raises(vm.ParameterError, match="x must be an array of numbers"):
            f("abc")
    with pytest.raises(vm.ParameterError, match="isolation=1.0 must be a number >= 1.5"):
        q.isolated_spikes(x, isolation=1.0)
    for bad in (0, -1.0, np.inf):
        with pytest.raises(vm.ParameterError, match="fs="):
            q.flat_runs(x, bad)
    # too short to judge a sample against its 16 neighbours on each side, and empty: nothing found
    assert q.isolated_spikes(np.arange(32.0)).size == 0 and q.clipped_share(np.zeros(0)) == 0.0
