"""A record's channels are prepared and their bearing spectra computed in threads (``core._threads.
each_in_threads``): the answer must be the serial loop's, bit for bit, flags and findings in its order."""

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
