"""Work done faster must give the same answers: a record's channels prepared and their bearing spectra computed in
threads (``core._threads.each_in_threads``), the kurtogram's bands as rows of one FFT, the speed scan's combs
taken from the family test; each must equal the serial, band-by-band, fitted-again computation bit for bit."""

import threading
import time
import warnings

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.core._threads import each_in_threads
from vibmeasure.core.errors import ParameterError
from vibmeasure.monitor.bearing import evidence
from vibmeasure.monitor.diagnosis import job


def test_results_and_the_first_error_come_in_the_items_order():
    # item 0 is the slowest, so the threads finish in the other order: the results must not
    seen = []

    def work(i):
        time.sleep(0.05 * (3 - i))
        seen.append(threading.current_thread().name)
        return i * i

    assert each_in_threads(work, range(4)) == [0, 1, 4, 9]
    assert any(name.startswith("vibmeasure-channel") for name in seen)

    def fails(i):
        time.sleep(0.1 if i == 0 else 0.0)   # item 1 fails first in time, item 0 first in order
        raise ParameterError(f"item {i}")

    with pytest.raises(ParameterError, match="item 0"):
        each_in_threads(fails, range(3))
    assert each_in_threads(lambda i: i + 1, [5]) == [6]   # one item: no thread
    assert each_in_threads(lambda i: i, []) == []


def _serial(func, items):
    return [func(item) for item in items]


def test_a_damaged_three_channel_record_reads_the_same_in_threads_and_in_a_loop(shared_data, monkeypatch):
    """CWRU fan-end IR014_2 with isolated spikes on one channel and a knock on another: each channel's
    repairs are flagged and reported in the serial order (primary first), and the answer, its reason, its
    flags and every family's numbers are the serial loop's exactly (the threads share no state)."""
    rec = vm.read(shared_data("cwru_fe/IR014_2.mat"), fs=12000, unit="g")
    y = rec.data.astype(float).copy()
    y[1, 5000::9000] += 30 * y[1].std()                        # spikes on the second channel
    n0 = rec.n_samples // 3
    y[2, n0:n0 + 2400] += 10 * y[2].std() * np.random.default_rng(3).normal(size=2400)   # a knock on the third
    damaged = vm.Record.from_array(y, fs=rec.fs, names=list(rec.names), unit="g")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        threaded = vm.diagnose(damaged, rpm=rec.meta["rpm"], bearing="6203-2RS")
        monkeypatch.setattr(job, "each_in_threads", _serial)
        monkeypatch.setattr(evidence, "each_in_threads", _serial)
        serial = vm.diagnose(damaged, rpm=rec.meta["rpm"], bearing="6203-2RS")
    assert {"spikes_removed", "transients_gated"} <= set(threaded.flags)
    assert list(threaded.extras["data_quality"]) == list(serial.extras["data_quality"]) == list(rec.names[1:])
    assert (threaded.top, threaded.confidence, threaded.reason, threaded.flags) == \
        (serial.top, serial.confidence, serial.reason, serial.flags)
    assert threaded.faults.equals(serial.faults)


def test_kurtogram_rows_equal_each_band_alone(rng):
    """The bands of one width are transformed as rows of one inverse FFT: each band's kurtosis and
    negentropy must be the one-band computation's to the last bit (a kurtogram's choice between two
    close bands must not hang on how many bands share a width)."""
    from scipy import fft
    from vibmeasure.signal.kurtogram import _band_rows, _band_bins, _complex_envelope
    x = rng.normal(size=30011) + 40 * (np.arange(30011) % 397 == 0)   # noise and an impact train
    X = fft.rfft(x - x.mean())
    starts = [max(_band_bins(X.size - 1, 16, i)[0], 1) for i in range(16)]
    m = 30011 // 2 // 16
    kurt, neg = _band_rows(X, starts, m, x.size, 200)
    for j, k0 in enumerate(starts):
        c = _complex_envelope(X, k0, k0 + m, x.size)
        e = np.abs(c) ** 2
        assert kurt[j] == float(np.mean(e ** 2) / max(float(np.mean(e)) ** 2, 1e-300) - 2.0)
        xn = e / max(float(e.mean()), 1e-300)
        neg_t = float(np.mean(xn * np.log(np.maximum(xn, 1e-300)))) - (1 - np.euler_gamma)
        k = np.arange(1, 201)
        P = np.abs(fft.rfft(e - e.mean())) ** 2
        y = P[k] / (1.0 - k / m)
        y = y / max(float(y.mean()), 1e-300)
        neg_s = float(np.mean(y * np.log(np.maximum(y, 1e-300)))) - (1 - np.euler_gamma)
        assert neg[j] == 0.5 * (neg_t + neg_s)
    assert kurt.max() > 1.0   # the impact train's bands stand out: the rows hold real envelopes


def test_the_speed_scans_declared_combs_are_the_family_tests_first_pass():
    """The speed scan weighs every family's comb on the lines the shaft and cage left (r_base); it takes
    them from the family test's first pass: each must equal a fresh fit on r_base."""
    from vibmeasure.monitor.bearing import bearing_evidence
    from vibmeasure.monitor.bearing.families import _family
    rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, fs=12000.0, duration=4.0, seed=1)
    b = vm.BEARINGS["6205-2RS"]
    f1 = 1797 / 60
    ev = bearing_evidence({"a": rec.data[0]}, 12000.0, f1, b.frequencies(f1), b.n_balls, speed_search=0.1)
    checked = 0
    for ses in ev.spectra:
        for name, cached in ses.base_results.items():
            saved, ses.r = ses.r, ses.r_base
            try:
                fresh = _family(ses, name, b.frequencies(f1), f1)
            finally:
                ses.r = saved
            assert (cached is None) == (fresh is None)
            if fresh is not None:
                assert (cached["logp"], cached["slip"], cached.get("halves")) == \
                    (fresh["logp"], fresh["slip"], fresh.get("halves"))
                checked += 1
    assert checked >= 4 and ev.families["bearing_outer_race"]["found"]


@pytest.mark.parametrize("x", [[], [1.0] * 5, np.zeros(100), [np.nan] + [1.0] * 40, np.ones((3, 40)), ["a"] * 20])
def test_whitening_what_holds_no_spectrum_is_a_parameter_error(x):
    from vibmeasure.signal.quality import whitened
    with pytest.raises(ParameterError, match="x .*must be"):
        whitened(x)


def test_a_whitened_signal_given_for_another_is_refused(rng):
    """``whitened_x=`` spares the rules a second whitening only when it is this signal's: another length
    or shape is a ParameterError naming the argument, never a judgement of other samples."""
    from vibmeasure.signal import quality as q
    x = rng.normal(size=4096)
    own = q.whitened(x)
    assert q.transients(x, 64, whiten=True, whitened_x=own) == q.transients(x, 64, whiten=True)
    assert q.isolated_events(x, 64, whitened_x=own) == q.isolated_events(x, 64)
    for bad in ((np.zeros(10), 1), (own[0],), "bad", (own[0], 5000)):
        with pytest.raises(ParameterError, match="whitened_x"):
            q.transients(x, 64, whiten=True, whitened_x=bad)
        with pytest.raises(ParameterError, match="whitened_x"):
            q.isolated_events(x, 64, whitened_x=bad)


# --- the bearing test's counts as arrays and its combs taken once (must equal the loops they replace) ---

def _loop_denser(ses, f0, harmonics, own_sidebands=()):
    """``lines._denser`` as a loop over m, the definition the array form must reproduce."""
    from vibmeasure.monitor.bearing.lines import DENSER_MAX, DENSER_SHARE, HALF_SHARE
    if any(h != int(h) for h in harmonics):
        return 0
    df, r, top = ses.freq[1], ses.r, ses.n_valid - 3

    def heights(hz):
        i = (np.asarray(hz) / df).astype(np.int64)
        ok = (i >= 1) & (i < top)
        i = np.where(ok, i, 1)
        return np.where(ok, np.max(np.stack([r[i - 1], r[i], r[i + 1], r[i + 2]]), axis=0), 0.0)
    own = heights(np.arange(1, 4) * f0)
    own = own[own >= ses.r_line]
    if not own.size:
        return 0
    need = max(ses.r_line, HALF_SHARE * float(np.median(own)))
    mods = np.array([h * f0 + k * sp for h in (1, 2, 3) for sp in own_sidebands for k in (-2, -1, 1, 2)])
    for m in range(3, DENSER_MAX + 1):
        hz = np.array([j * f0 / m for j in range(1, 3 * m) if j % m and j * f0 / m / df >= 2])
        if mods.size and hz.size:
            hz = hz[np.all(np.abs(hz[:, None] - mods[None, :]) > np.maximum(1.5 * df, 0.01 * hz[:, None]), axis=1)]
        if hz.size < 3:
            continue
        if int(np.sum(heights(hz) >= need)) >= max(3, DENSER_SHARE * hz.size):
            return m
    return 0


def _ses(r, df=0.1):
    from vibmeasure.monitor.bearing.spectra import _SES
    freq = np.arange(r.size) * df
    return _SES("a", "cepstral", (1000.0, 5000.0), freq, np.sqrt(r), r, r.size)


def test_denser_places_counted_as_arrays_equal_the_loop_over_m(rng):
    """``_denser`` counts every m's in-between places at once: on exponential noise with combs planted at
    f0 / m (m = 3 .. 12, some with their sidebands' places asked too) it names the m the loop names."""
    from vibmeasure.monitor.bearing.lines import _denser
    named = set()
    for trial in range(120):
        r = rng.exponential(size=6000)
        f0, m = rng.uniform(40.0, 150.0), int(rng.integers(3, 13))
        for j in range(1, 3 * m + 1):
            if rng.random() < (0.9 if trial % 3 else 0.3):
                r[int(j * f0 / m / 0.1)] = rng.uniform(8.0, 40.0)
        ses = _ses(r)
        sidebands = [(), (29.95,), (29.95, 11.4)][trial % 3]
        got = _denser(ses, f0, (1, 2, 3), sidebands)
        assert got == _loop_denser(ses, f0, (1, 2, 3), sidebands)
        named.add(got)
    assert 0 in named and len(named) >= 4   # both outcomes, and several m, were exercised
    assert _denser(_ses(rng.exponential(size=6000)), 70.0, (0.5, 1, 1.5)) == 0   # half-harmonic sub-model


def test_cage_shared_harmonics_as_arrays_equal_the_loop_over_k():
    """The cage harmonics an inner-race or ball line shares, found as one array comparison: those the
    per-harmonic loop finds, for every catalogue bearing at two speeds."""
    from vibmeasure.monitor.bearing.cage import _cage_shared
    from vibmeasure.monitor.bearing.rules import CONTESTED
    for name, b in vm.BEARINGS.items():
        for f1 in (14.7, 29.95):
            fr = b.frequencies(f1)
            lines = [h * fr["BPFI"] + m * f1 for h in range(1, 6) for m in ((-1, 0, 1) if h <= 3 else (0,))]
            lines += [h * fr["BSF"] for h in range(1, 7)] + [h * fr["2xBSF"] + m * fr["FTF"] for h in (1, 2, 3) for m in (-1, 1)]
            lines = np.asarray(lines)
            loop = {k for k in range(1, 121) if k % b.n_balls
                    and np.any(np.abs(k * fr["FTF"] - lines) <= CONTESTED * lines + 1.5 * 0.1)}
            assert _cage_shared(120, fr, f1, b.n_balls, 0.1) == loop, name


def test_a_familys_carrier_and_modulation_combs_are_its_sub_models_fits(rng):
    """``_family`` takes the comb of its first three harmonics and of its modulation sidebands from the
    sub-models it fitted on the same lines: each equals a fresh ``_comb`` of them."""
    from vibmeasure.monitor.bearing.families import _family
    from vibmeasure.monitor.bearing.lines import _comb
    from vibmeasure.monitor.bearing.rules import R_CAP
    b = vm.BEARINGS["6205-2RS"]
    f1 = 29.95
    fr = b.frequencies(f1)
    for key, name, side in (("BPFI", "bearing_inner_race", (f1, 0.0)), ("2xBSF", "bearing_ball", (fr["FTF"], 1.0)),
                            ("BPFO", "bearing_outer_race", None)):
        r = rng.exponential(size=9000)
        for h in (1, 2, 3):
            for k in (-1, 0, 1):
                hz = h * fr[key] * 1.004 + (k * side[0] * (1 + 0.004 * side[1]) if side else 0.0)
                r[int(round(hz / 0.1))] = 25.0
        ses = _ses(r)
        res = _family(ses, name, fr, f1)
        car = _comb(ses, fr[key], (1, 2, 3))
        vals = [ln["r"] for ln in car["lines"]]
        assert res["order_key"] == (sum(v >= ses.r_line for v in vals), float(np.minimum(vals, R_CAP).sum()),
                                    float(sum(vals)))
        if side is not None:
            mod = _comb(ses, fr[key], (1, 2, 3), side)
            assert res["modulation"] == sum(ln["r"] >= ses.r_line for ln in mod["lines"] if ln["sideband"] != 0) >= 4
        else:
            assert res["modulation"] is None


def test_a_combs_counts_in_one_pass_equal_their_definitions(rng):
    """The comb's standing lines, carriers, odd harmonics and step, counted in one pass over its terms,
    are what their definitions give on the lines it reports."""
    from vibmeasure.monitor.bearing.lines import _comb, _step
    for _ in range(60):
        r = rng.exponential(size=9000) * rng.uniform(0.5, 4.0)
        ses = _ses(r)
        harmonics = [(1, 2, 3), (1, 2, 3, 4, 5), (0.5, 1, 1.5)][int(rng.integers(3))]
        side = None if rng.random() < 0.5 else (29.95, float(rng.integers(2)))
        res = _comb(ses, rng.uniform(60.0, 170.0), harmonics, side)
        st = [ln for ln in res["lines"] if ln["r"] >= ses.r_line]
        assert res["n_lines"] == len(st)
        assert res["n_carriers"] == sum(ln["sideband"] == 0 and ln["harmonic"] <= 3 for ln in st)
        assert res["n_odd"] == sum(ln["harmonic"] != int(ln["harmonic"]) or int(ln["harmonic"]) % 2 for ln in st)
        assert res["step"] == _step(ln["harmonic"] for ln in st)
        assert res["edge"] in (True, False) and res["strength"] == float(
            np.sum([ln["r"] for ln in res["lines"] if ln["sideband"] == 0]))


def test_the_speed_scan_weighs_the_declared_speed_only_against_a_significant_comb_elsewhere(monkeypatch):
    """Without a significant comb at another speed there is neither contradiction nor rival, so the
    declared speed's best comb is not computed; with one (a fault declared at half its speed), the
    declared p-value reported is the best of every spectrum's."""
    from vibmeasure.monitor.bearing import bearing_evidence, decoys
    b = vm.BEARINGS["6205-2RS"]
    f1 = 1797 / 60
    healthy = vm.synth.machine(fault="none", rpm=1797, fs=12000.0, duration=4.0, seed=2)
    calls = []
    real = decoys._declared_best
    monkeypatch.setattr(decoys, "_declared_best", lambda *a: calls.append(a) or real(*a))
    ev = bearing_evidence({"a": healthy.data[0]}, 12000.0, f1, b.frequencies(f1), b.n_balls, speed_search=0.12)
    assert ev.speed_scan is None and ev.factor_rival is None and not calls
    fault = vm.synth.machine(fault="bearing_outer_race", rpm=1797, fs=12000.0, duration=4.0, seed=1)
    half = f1 / 2
    ev = bearing_evidence({"a": fault.data[0]}, 12000.0, half, b.frequencies(half), b.n_balls, speed_search=0.12,
                          f1_known=False)
    found = ev.speed_scan or ev.factor_rival
    assert found is not None and abs(found["factor"] - 2.0) < 0.1 and calls
    declared = min([0.0] + [real(s, b.frequencies(half), half, 0.12, len(ev.spectra)) for s in ev.spectra])
    assert found["declared_p_value"] == float(np.exp(declared))


def test_kept_windows_and_floor_maps_are_the_ones_computed_afresh():
    """The windows and the floor ratio's exact map are kept per length (read-only): each equals the one
    computed afresh."""
    from scipy.signal.windows import tukey
    from vibmeasure.monitor.bearing.spectra import _exponential_map
    from vibmeasure.signal.spectral import symmetric_window
    for n in (1001, 4096, 120617, 2 ** 17 + 1):
        w = symmetric_window(("tukey", 0.05), n)
        assert np.array_equal(w, tukey(n, 0.05)) and not w.flags.writeable
        assert np.array_equal(symmetric_window("hann", n), np.hanning(n))
    grid, g = _exponential_map(101)
    fresh = np.log1p(grid[:, None] / (np.log(2.0) * (100 - np.arange(51)[None, :]))).sum(axis=1)
    assert np.array_equal(g, fresh) and not g.flags.writeable and _exponential_map(101)[1] is g
