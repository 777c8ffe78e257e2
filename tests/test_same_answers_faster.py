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
