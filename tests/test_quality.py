"""Damage of the recording chain in the samples: isolated spikes (found, repaired), dropouts, clipping;
and what diagnose does with them."""

import json
import warnings

import numpy as np
import pytest
import scipy.io as sio

import vibmeasure as vm
from vibmeasure.signal import quality as q
import vibmeasure.monitor.diagnosis.decide as M


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
    assert q.spike_grid(strict) == (300, 1024)       # ... but sees the grid
    np.testing.assert_array_equal(q.isolated_spikes(y), idx)


def test_the_ar_fill_reaches_the_interpolation_error_of_the_true_model():
    """Oracle: for an AR(2) process (a resonance at 0.2 fs driven by white noise of spread s), the
    least-squares interpolation of one missing sample from the true model misses it with spread
    s / sqrt(1 + a1^2 + a2^2) (Janssen et al. 1986). The fill fits its own AR(32) model on the record:
    its errors over 400 isolated samples match that within 10 % (the sampling spread of 400 errors is
    3.5 %); the neighbours' mean misses by 2.5 times more."""
    from scipy.signal import lfilter
    rng = np.random.default_rng(11)
    r, th = 0.95, 2 * np.pi * 0.2
    a1, a2 = 2 * r * np.cos(th), -r * r
    x = lfilter([1.0], [1.0, -a1, -a2], rng.normal(size=200_000))
    idx = np.sort(rng.choice(np.arange(100, x.size - 100, 50), 400, replace=False))
    y = x.copy()
    y[idx] = 1e3    # the samples lost
    err = q.fill(y, idx)[idx] - x[idx]
    oracle = 1.0 / np.sqrt(1 + a1 ** 2 + a2 ** 2)
    assert np.std(err) == pytest.approx(oracle, rel=0.10)
    assert np.std(q._repair(y, idx)[idx] - x[idx]) > 2 * oracle   # measured: 2.5 x
    # two adjacent samples are filled jointly: still a fraction of the signal's spread
    pair = np.array([5000, 5001])
    y2 = x.copy()
    y2[pair] = [1e3, -1e3]
    assert np.max(np.abs(q.fill(y2, pair)[pair] - x[pair])) < 0.5 * x.std()


def test_fill_names_bad_indices_and_samples():
    x = np.sin(np.arange(1000) * 0.3)
    for bad in ([1000], [-1], [2.5]):
        with pytest.raises(vm.ParameterError, match="idx must be sample indices of x"):
            q.fill(x, bad)
    with pytest.raises(vm.ParameterError, match="NaN/inf"):
        q.fill(np.r_[x, np.nan], [3])
    assert np.array_equal(q.fill(x, []), x)
    with pytest.raises(vm.ParameterError, match="x has 0 samples"):
        q.fill(np.zeros(0), [0])


def test_a_record_that_is_only_a_spike_is_refused_not_modelled():
    """Zeros with one spike: no AR model exists (no variation once the spike is filled); the spike is
    found and filled with the neighbours' mean, and diagnose refuses the channel by name instead of
    failing deep inside (a LinAlgError, then a NaN band edge)."""
    z = np.r_[np.zeros(60_000), 5.0, np.zeros(60_000)]
    np.testing.assert_array_equal(q.isolated_spikes(z), [60_000])
    assert np.array_equal(q.fill(z, [60_000]), np.zeros(z.size))
    assert np.array_equal(q.fill(np.ones(1000), [500]), np.ones(1000))
    with pytest.warns(vm.QualityWarning):
        assert not vm.despike(vm.Record.from_array(z, fs=12000.0)).data.any()
    with pytest.raises(vm.ParameterError, match="channel 'acc' is constant once the recording chain's damage"):
        vm.diagnose(vm.Record.from_array(z, fs=12000.0, names=["acc"], unit="g"), rpm=1797, bearing="6205-2RS")


def test_glitches_on_impacts_and_over_two_samples_are_found(rng):
    """Spikes of 30 x the RMS on the impacts of a bearing fault (their neighbours' residuals are
    candidates too, which the former rule, no neighbour a candidate, took for a burst; here the
    neighbours stand over 4 x lower) and two-sample glitches of alternating sign (a seam): all found,
    and nothing else. (The real record's test below needs the AR model's second look.)"""
    x = _machine("bearing_outer_race", snr_db=20).data[0].astype(float)
    assert q.isolated_spikes(x).size == 0
    r = np.abs(x)
    peaks = np.flatnonzero((r > 4 * x.std()) & (r >= np.roll(r, 1)) & (r >= np.roll(r, -1)))
    peaks = peaks[(peaks > 100) & (peaks < x.size - 100)]
    on_impacts = rng.choice(peaks, 10, replace=False) + 2
    pairs = np.array([30_000, 50_000, 60_000])
    y = x.copy()
    y[on_impacts] += 30 * x.std() * np.sign(x[on_impacts])
    y[pairs] += 20 * x.std()
    y[pairs + 1] -= 20 * x.std()
    want = np.sort(np.concatenate((on_impacts, pairs, pairs + 1)))
    np.testing.assert_array_equal(q.isolated_spikes(y), want)


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


def test_random_spikes_on_a_real_fault_record_are_found_and_nothing_else(shared_data, monkeypatch):
    """500 single-sample spikes of 30 x the RMS, alternating sign, in 10 s of CWRU fan-end OR007@6_2's
    fan-end channel (outer-race impacts ringing at 2-4 kHz of 12 kHz): at most 1 % missed (measured:
    none with seed 3, 4 with seed 4: pairs beside an impact) and no sample of the vibration taken. The
    median's residual alone misses 13 with seed 3: those on impacts, which the AR model's second look
    (``_ar_spikes``) finds. (Over every channel of the 53 fault records: 191 of 69,351 missed without
    it, 27 with it.)"""
    m = sio.loadmat(shared_data("cwru_fe") / "OR007@6_2.mat", squeeze_me=True)
    x = np.asarray(m["X296_FE_time"], float)
    for seed in (3, 4):
        idx = np.sort(np.random.default_rng(seed).choice(x.size - 1, size=int(50 * x.size / 12000), replace=False))
        y = x.copy()
        y[idx] += 30 * x.std() * np.where(np.arange(idx.size) % 2, 1.0, -1.0)
        found = q.isolated_spikes(y)
        assert np.setdiff1d(found, idx).size == 0
        assert np.setdiff1d(idx, found).size <= 0.01 * idx.size
        if seed == 3:
            monkeypatch.setattr(q, "_ar_spikes", lambda y, sigma: np.zeros(0, np.int64))
            assert np.setdiff1d(idx, q.isolated_spikes(y)).size >= 10
            monkeypatch.undo()


def test_despike_repairs_and_says_so():
    rec = _machine("bearing_outer_race")
    x = rec.data[0].astype(float)
    y = x.copy()
    y[[1000, 20000]] += 30 * x.std()
    bad = vm.Record.from_array(y, fs=rec.fs, names=["acc"], unit="g")
    with pytest.warns(vm.QualityWarning, match="channel 'acc': 2 isolated spikes replaced"):
        fixed = vm.despike(bad)
    # the repair is the AR interpolation (``fill``): nothing else moves, and each repaired sample is
    # off the true one by about the white noise's spread (this record is at 0 dB: half its power is
    # noise no model predicts), far below the spike
    assert np.array_equal(np.delete(fixed.data[0], [1000, 20000]), np.delete(y, [1000, 20000]))
    assert np.max(np.abs(fixed.data[0] - x)) < 2 * x.std()
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


def _dropped(rec, seed=5):
    """Ten runs of zeros of 10 ms at random places in every channel (as benchmarks/diagnosis_robustness.py)."""
    y = rec.data.astype(float).copy()
    n, m = y.shape[1], int(0.01 * rec.fs)
    for s in np.random.default_rng(seed).choice(n - m, size=int(n / rec.fs), replace=False):
        y[:, s:s + m] = 0.0
    return vm.Record.from_array(y, fs=rec.fs, names=list(rec.names), unit="g")


@pytest.mark.parametrize("name, truth", [("B014_3", "bearing_ball"), ("OR007@3_3", "bearing_outer_race"),
                                         ("B021_3", "undetermined")])
def test_dropouts_are_filled_before_the_envelope_analysis(shared_data, name, truth):
    """A dropout is lost data, and the runs of zeros gate the envelope: left as zeros, B014_3 (ball)
    and OR007@3_3 (outer race) lost their right calls and B021_3 (ball, named by no family as recorded:
    "undetermined") was called
    outer race. Filled by the AR interpolation (``quality.fill``), each keeps its answer as recorded;
    the dropouts are still flagged and counted."""
    rec = vm.read(shared_data(f"cwru_fe/{name}.mat"), fs=12000, unit="g")
    with pytest.warns(vm.QualityWarning, match="10 dropouts"):
        d = vm.diagnose(_dropped(rec), rpm=rec.meta["rpm"], bearing="6203-2RS")
    assert d.top == truth, d.reason
    assert "dropouts" in d.flags
    assert all(v["dropouts"] == 10 for v in d.extras["data_quality"].values())


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


# --- transients: bursts and settling, gated out -----------------------------------------------------

def test_a_burst_and_a_settling_are_found_where_they_are(rng):
    """Gaussian noise, 10 s at 12 kHz, windows of 800 samples (two revolutions at 1800 rpm). A steady
    record: the RMS of an 800-sample window of Gaussian noise spreads by 1/sqrt(2 x 800) = 2.5 %, so
    nothing comes near 3 x and nothing is marked. A 0.2 s burst at 10 x the RMS is marked from at most
    one window before it to at most one after (a window astride its edges is marked, then half a block
    either side); a settling exponential of 20 x the RMS (tau 0.3 s) from the start to where its mean
    falls under 2 x the RMS (0.3 ln 10 = 0.69 s) plus up to a window and a half."""
    x = rng.standard_normal(120_000)
    assert q.transients(x, 800) == []
    y = x.copy()
    y[40_000:42_400] += 10 * rng.standard_normal(2400)
    runs = q.transients(y, 800)
    assert len(runs) == 1
    (s, e), = runs
    assert 40_000 - 1200 <= s <= 40_000 and 42_400 <= e <= 42_400 + 1200
    t = np.arange(x.size) / 12000.0
    runs = q.transients(x + 20 * np.exp(-t / 0.3), 800)
    assert runs[0][0] == 0 and 0.69 * 12000 <= runs[-1][1] <= 0.69 * 12000 + 1200 + 400


def test_a_level_that_changes_over_much_of_the_record_is_no_transient(rng):
    """More than TRANSIENT_SHARE (a quarter) of the record beyond the thresholds is the machine's own
    state (a run-up, an intermittent machine): nothing is marked. 21 % at 10 x is marked whole: up to
    the last window (800 samples, moved by 400) it reaches, 24,800-25,600, and half a block beyond."""
    x = rng.standard_normal(120_000)
    y = x.copy()
    y[:40_000] *= 10      # a third of the record
    assert q.transients(y, 800) == []
    y = x.copy()
    y[:25_000] *= 10      # 21 %
    assert q.transients(y, 800) == [(0, 26_000)]


def test_gate_sets_the_runs_to_the_mean_with_no_step(rng):
    x = 3.0 + rng.standard_normal(10_000)
    y = q.gate(x, [(4000, 5000)], 50)
    keep = np.r_[0:4000, 5000:10_000]
    assert np.all(y[4000:5000] == pytest.approx(x[keep].mean()))
    # outside the ramps the samples are untouched; inside them they move towards the mean, never past it
    assert np.array_equal(y[:3950], x[:3950]) and np.array_equal(y[5050:], x[5050:])
    m = x[keep].mean()
    assert np.all(np.abs(y[3950:4000] - m) <= np.abs(x[3950:4000] - m) + 1e-12)
    # the step into the run is at most the last ramp weight (1 - cos(pi/51))/2 = 0.1 % of the excursion
    assert abs(y[3999] - m) <= 0.001 * abs(x[3999] - m) + 1e-12
    assert np.array_equal(q.gate(x, [], 50), x)
    for bad in ([(9000, 11_000)], [(5, 5)], [(1.5, 9)], [(1, 2, 3)], [7]):
        with pytest.raises(vm.ParameterError, match=r"runs must be \(start, stop\) sample pairs within x"):
            q.gate(x, bad, 50)
    for bad in (-1, 2.5, True):
        with pytest.raises(vm.ParameterError, match=f"ramp={bad!r} must be a whole number of samples, 0 or more"):
            q.gate(x, [(10, 20)], bad)
    with pytest.raises(vm.ParameterError, match="NaN"):
        q.gate(np.where(np.arange(100) == 3, np.nan, 0.0), [(10, 20)], 5)
    with pytest.raises(vm.ParameterError, match="NaN"):
        q.transients(np.where(np.arange(100) == 3, np.nan, 0.0), 4)
    assert q.transients(np.zeros(0), 800) == [] and q.transients(np.zeros(50_000), 800) == []   # empty, constant
    with pytest.raises(vm.ParameterError, match="block=0 must be a whole number of samples"):
        q.transients(x, 0)
    with pytest.raises(vm.ParameterError, match="block=True must be a whole number of samples"):
        q.transients(x, True)


def test_steady_real_recordings_have_transients_only_where_a_ball_defect_strikes_loudly(shared_data):
    """Every channel of the 57 development recordings, windows of two revolutions: nothing is marked,
    except one to three short loud stretches (3-4.8 x the median window's RMS) in the fan-end channel of
    six fan-end ball-fault records, 1.3-6.2 % of each; at 5 x the RMS nothing at all."""
    marked = {}
    for d in ("cwru_fe", "cwru"):
        for f in sorted(shared_data(d).glob("*.mat")):
            rec = vm.read(f, fs=12000, unit="g")
            block = int(round(2 * 12000 * 60 / rec.meta["rpm"]))
            for name in rec.names:
                runs = q.transients(rec.channel(name).astype(float), block)
                if runs:
                    marked[(d, f.stem, name[-7:])] = sum(e - s for s, e in runs) / rec.n_samples
    for f in sorted(shared_data("mfpt").glob("*.mat")):
        m = sio.loadmat(f, squeeze_me=True)["bearing"]
        x = np.asarray(m["gs"].item(), float)
        assert q.transients(x, int(round(2 * float(m["sr"].item()) / float(m["rate"].item())))) == [], f.name
    assert sorted(k[1] for k in marked) == ["B007_0", "B007_1", "B014_1", "B021_0", "B021_1", "B021_3"]
    assert all(k[0] == "cwru_fe" and k[2] == "FE_time" for k in marked)
    assert 0.012 <= min(marked.values()) and max(marked.values()) <= 0.063


def _resonant_noise(rng, n=120_000, fs=12000.0):
    """Noise through one lightly damped resonance at 3 kHz (pole radius 0.995), unit RMS, over a white
    floor at 1 % of it: an accelerometer's signal, loud in its structure's band and quiet elsewhere."""
    from scipy.signal import lfilter
    r, th = 0.995, 2 * np.pi * 3000 / fs
    x = lfilter([1.0], [1, -2 * r * np.cos(th), r * r], rng.standard_normal(n))
    return x / x.std() + 0.01 * rng.standard_normal(n)


def test_a_burst_under_the_level_is_found_in_the_whitened_signal(rng):
    """A 0.2 s burst of white noise at 2 x the RMS of a resonant signal: its windows reach about
    sqrt(1 + 4) = 2.2 x the others' RMS, under TRANSIENT_LEVEL, so the RMS rule misses it; but away
    from the resonance it is 4 / 1e-4 = 40,000 x the signal's power, and whitened (what the envelope
    analysis demodulates) it stands far above the rest. Windows of 2,100 samples (two turns of a 6203's
    cage at 1800 rpm): marked from at most a window and a half before it to as much after, and to the
    record's end where it reaches the tapered ends. Steady, in 20 records of the same noise, nothing is
    marked; nor in an empty or a constant record. Bad block, whiten or NaN input: a named error."""
    x = _resonant_noise(rng)
    assert q.transients(x, 2100, whiten=True) == []
    y = x.copy()
    y[40_000:42_400] += 2 * rng.standard_normal(2400)
    assert q.transients(y, 800) == []
    (s, e), = q.transients(y, 2100, whiten=True)
    assert 40_000 - 3 * 1050 <= s <= 40_000 and 42_400 <= e <= 42_400 + 3 * 1050
    for seed in range(20):
        assert q.transients(_resonant_noise(np.random.default_rng(100 + seed)), 2100, whiten=True) == [], seed
    # just past the tapered 2.5 % at either end (3,000 samples): the run takes the tapered samples too
    y = x.copy()
    y[3000:5400] += 2 * rng.standard_normal(2400)
    (s, e), = q.transients(y, 2100, whiten=True)
    assert s == 0 and 5400 <= e <= 5400 + 3 * 1050
    y = x.copy()
    y[-5400:-3000] += 2 * rng.standard_normal(2400)
    (s, e), = q.transients(y, 2100, whiten=True)
    assert x.size - 5400 - 3 * 1050 <= s <= x.size - 5400 and e == x.size
    assert q.transients(np.zeros(50_000), 2100, whiten=True) == []
    assert q.transients(np.zeros(0), 2100, whiten=True) == []
    with pytest.raises(vm.ParameterError, match="block=1 must be a whole number of samples, at least 2"):
        q.transients(x, 1, whiten=True)
    with pytest.raises(vm.ParameterError, match="whiten='yes' must be True or False"):
        q.transients(x, 2100, whiten="yes")
    with pytest.raises(vm.ParameterError, match="NaN"):
        q.transients(np.where(np.arange(50_000) == 3, np.nan, 0.0), 2100, whiten=True)


def test_steady_real_recordings_whitened_have_transients_only_in_one_ball_record(shared_data):
    """Every channel of the 57 development recordings, whitened, in windows of two turns of its
    bearing's cage (a rolling element's defect passes the load zone once a turn, so shorter windows
    would take its own rhythm for transients): only CWRU fan-end B007_1's drive-end and fan-end channels
    have a stretch over 3 x the median window's RMS (3.6 x and 3.1 x, at most 0.5 s of each)."""
    marked = {}
    sets = [("cwru_fe", "6203-2RS"), ("cwru", "6205-2RS")]
    for d, bearing in sets:
        b = vm.models.bearing.bearing_from(bearing)
        for f in sorted(shared_data(d).glob("*.mat")):
            rec = vm.read(f, fs=12000, unit="g")
            block = int(round(2 * 12000 / b.frequencies(rec.meta["rpm"] / 60)["FTF"]))
            for name in rec.names:
                runs = q.transients(rec.channel(name).astype(float), block, whiten=True)
                if runs:
                    marked[(f.stem, name[-7:])] = sum(e - s for s, e in runs) / rec.fs
    ftf = vm.BEARINGS["MFPT"].frequencies(1.0)["FTF"]
    for f in sorted(shared_data("mfpt").glob("*.mat")):
        m = sio.loadmat(f, squeeze_me=True)["bearing"]
        x, fs = np.asarray(m["gs"].item(), float), float(m["sr"].item())
        assert q.transients(x, int(round(2 * fs / (ftf * float(m["rate"].item())))), whiten=True) == [], f.name
    assert sorted(marked) == [("B007_1", "DE_time"), ("B007_1", "FE_time")]
    assert max(marked.values()) <= 0.5


def _burst(rec, seconds, amp, seed=2):
    y = rec.data.astype(float).copy()
    n, s = int(seconds * rec.fs), rec.n_samples // 3
    y[:, s:s + n] += amp * y.std(axis=1, keepdims=True) * np.random.default_rng(seed).normal(size=(y.shape[0], n))
    return vm.Record.from_array(y, fs=rec.fs, names=list(rec.names), unit="g")


@pytest.mark.parametrize("name, truth", [("OR007@6_0", "bearing_outer_race"), ("IR014_2", "bearing_inner_race"),
                                         ("B014_2", "bearing_ball")])
def test_a_knock_on_a_real_faulty_machine_is_gated_out(shared_data, monkeypatch, name, truth):
    """A 0.2 s burst of noise at 10 x the RMS a third of the way into a CWRU fan-end fault record (a knock,
    a touched cable) on every channel: it lifts the envelope spectrum's floor about 200 x, and without the
    gate the record's right answer became "none" (on the 53 development fault records, 39 right fell to 0).
    Gated out, the answer is the record's own, the transient is flagged and the warning names its length."""
    rec = vm.read(shared_data(f"cwru_fe/{name}.mat"), fs=12000, unit="g")
    knocked = _burst(rec, 0.2, 10.0)
    with pytest.warns(vm.QualityWarning, match=r"1 transient .*gated out"):
        d = vm.diagnose(knocked, rpm=rec.meta["rpm"], bearing="6203-2RS")
    assert d.top == truth, d.reason
    assert "transients_gated" in d.flags
    # the burst, a window astride each edge (up to two revolutions) and half a block (one) beyond it
    assert all(0.2 <= v["transient_seconds"] <= 0.2 + 6 * 60 / rec.meta["rpm"]
               for v in d.extras["data_quality"].values())
    monkeypatch.setattr(q, "TRANSIENT_LEVEL", np.inf)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        assert vm.diagnose(knocked, rpm=rec.meta["rpm"], bearing="6203-2RS").top == "none"


@pytest.mark.parametrize("name, truth", [("OR007@3_0", "bearing_outer_race"), ("IR007_0", "bearing_inner_race")])
def test_a_knock_under_the_level_is_gated_out_from_the_whitened_signal(shared_data, monkeypatch, name, truth):
    """A 0.2 s burst at 2 x the RMS on every channel of a CWRU fan-end fault record: under the 3 x level
    of the RMS rule, but whitened it stands 8-25 x above the base channels' median window, and its
    envelope buried every line (the inner race of IR007_0, p = 1e-180 as recorded, had p = 1; on the
    53 development fault records 39 right answers fell to 14). Found in the whitened signal and gated
    out, the answer is the record's own; without that second look it is "none". The gated stretch:
    the burst, a window of two cage turns astride each edge, half a window beyond, and the whitening
    filter's own spread (the inverse of the structure's resonances rings too): under 4 windows more.
    (The ball record B014_2, gated alike, reads "none": its ball comb and an inner-race comb, BPFI
    at 143.1 Hz with its +-1X at 113.9 and 172.3 Hz, the first of them also 2 x BSF within 1 %, are
    equally likely there. It was called ball while the cage comb's stretch around its 16th harmonic,
    half a cage order wide, also divided the line at 172.3 Hz, 4.6 Hz from it.)"""
    rec = vm.read(shared_data(f"cwru_fe/{name}.mat"), fs=12000, unit="g")
    knocked = _burst(rec, 0.2, 2.0)
    with pytest.warns(vm.QualityWarning, match=r"1 transient .*gated out"):
        d = vm.diagnose(knocked, rpm=rec.meta["rpm"], bearing="6203-2RS")
    assert d.top == truth, d.reason
    cage_window = 2 * 60 / (vm.BEARINGS["6203-2RS"].frequencies(1.0)["FTF"] * rec.meta["rpm"])
    assert all(0.2 <= v["transient_seconds"] <= 0.2 + 4 * cage_window for v in d.extras["data_quality"].values())
    plain = q.transients
    monkeypatch.setattr(q, "transients", lambda x, block, whiten=False, whitened_x=None: [] if whiten else plain(x, block))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        assert vm.diagnose(knocked, rpm=rec.meta["rpm"], bearing="6203-2RS").top == "none"


def test_a_sensor_settling_is_no_looseness_and_lifts_the_severity_far_less(shared_data, monkeypatch):
    """CWRU fan-end B007_0 (its fan-end channel primary) with an ICP sensor's bias settling at the start
    (20 x the RMS, tau 0.3 s): its low frequencies lifted the ISO velocity and let the shaft orders
    through, and "looseness" was called (so on 4 of the 53 development fault records). Gated out (until its mean is within 2 x the RMS, about
    0.7-0.9 s), the answer is the record's own ("none"). The velocity RMS, 19.7 x the clean record's
    without the gate, is 1.7 x with it: the settling's tail under the offset threshold still carries
    low frequencies (a limit, asserted as such: under 2.5 x, and over 10 x without the gate). Without
    the gate "looseness" is no longer called either: its harmonics carry a small share of the velocity
    power the settling makes (``diagnosis.shaft.SHAFT_SHARE``), so its score stays under TOP_CONFIDENCE."""
    rec = vm.read(shared_data("cwru_fe/B007_0.mat"), fs=12000, unit="g")
    fe = next(n for n in rec.names if n.endswith("_FE_time"))   # the fault-side channel, as diagnosis_real
    t = np.arange(rec.n_samples) / rec.fs
    settled = vm.Record.from_array(rec.data + 20 * rec.data.std(axis=1, keepdims=True) * np.exp(-t / 0.3),
                                   fs=rec.fs, names=list(rec.names), unit="g")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        clean = vm.diagnose(rec, rpm=rec.meta["rpm"], bearing="6203-2RS", channel=fe)
        d = vm.diagnose(settled, rpm=rec.meta["rpm"], bearing="6203-2RS", channel=fe)
        monkeypatch.setattr(q, "TRANSIENT_OFFSET", np.inf)
        monkeypatch.setattr(q, "TRANSIENT_LEVEL", np.inf)
        raw = vm.diagnose(settled, rpm=rec.meta["rpm"], bearing="6203-2RS", channel=fe)
    assert d.top == clean.top == "none", d.reason
    assert raw.top == "none" and "transients_gated" in d.flags and "transients_gated" not in raw.flags
    loose = raw.faults.set_index("fault").loc["looseness"]
    assert 0 < loose.confidence < M.TOP_CONFIDENCE and "of the velocity power" in loose.note
    v0 = clean.severity["velocity_rms_mm_s"]
    assert d.severity["velocity_rms_mm_s"] < 2.5 * v0 and raw.severity["velocity_rms_mm_s"] > 10 * v0
