"""Order tracking and time-synchronous averaging on a run-up whose speed is known exactly."""
import numpy as np
import pytest

import vibmeasure as vm


def runup(fs=5000.0, T=8.0, seed=0):
    t = np.arange(int(fs * T)) / fs
    rpm = 600 + 150 * t                       # 600 -> 1800 rpm
    rev = np.cumsum(rpm / 60) / fs            # shaft angle in revolutions
    rev -= rev[0]
    x = 1.0 * np.sin(2 * np.pi * rev) + 0.5 * np.sin(2 * np.pi * 3.7 * rev)  # orders 1 and 3.7
    x += 0.2 * np.random.default_rng(seed).normal(size=t.size)
    tach = (np.mod(rev, 1.0) < 0.05).astype(float)  # one pulse per revolution
    return vm.Record(np.vstack([x, tach]), fs=fs, channels=[vm.Channel("acc", "acceleration", "g"), vm.Channel("tach")]), rpm


@pytest.mark.parametrize("how", ["tach", "rpm"])
def test_order_spectrum_is_sharp_through_a_runup(how):
    rec, rpm = runup()
    kw = dict(tach="tach") if how == "tach" else dict(rpm_profile=rpm)
    ang = vm.order_track(rec, channel="acc", samples_per_rev=32, **kw)
    spec = vm.amplitude_spectrum(ang, window="flattop")  # fs is samples per revolution: freq axis in orders
    p = vm.pick_peaks(spec, n=2)
    np.testing.assert_allclose(sorted(p.freq), [1.0, 3.7], atol=0.01)
    np.testing.assert_allclose(sorted(p.amplitude, reverse=True), [1.0, 0.5], rtol=0.03)
    # in the time-frequency spectrum the same lines smear over 10-30 Hz: no line reaches 0.5
    assert vm.amplitude_spectrum(rec, channels=["acc"]).values[0].max() < 0.5


def test_tsa_keeps_what_turns_with_the_shaft():
    rec, rpm = runup(seed=1)
    avg = vm.time_synchronous_average(rec, channel="acc", tach="tach", samples_per_rev=64)
    theta = np.arange(64) / 64  # angle from the tach pulse, which fires as the 1X sine starts
    assert avg.meta["revolutions_averaged"] > 100
    # sin(2 pi theta) survives; order 3.7 (not synchronous) and noise average to a few hundredths
    np.testing.assert_allclose(avg.data[0], np.sin(2 * np.pi * theta), atol=0.06)


def test_order_tracking_bad_input():
    rec, rpm = runup()
    with pytest.raises(vm.ParameterError, match="exactly one of tach"):
        vm.order_track(rec, channel="acc")
    with pytest.raises(vm.ParameterError, match="rpm_profile"):
        vm.order_track(rec, channel="acc", rpm_profile=-rpm)
    with pytest.raises(vm.ParameterError, match="pulse"):
        vm.order_track(rec, channel="acc", tach=np.zeros(rec.n_samples))
    bad = rec.channel("tach").copy()
    bad[7] = np.nan
    with pytest.raises(vm.ParameterError, match="tach has 1 NaN/inf samples .first at index 7.; the rule is finite"):
        vm.order_track(rec, channel="acc", tach=bad)
    empty = vm.Record(np.zeros((2, 0)), fs=rec.fs, channels=rec.channels)
    with pytest.raises(vm.ParameterError, match="tach has 0 samples; pulses need at least 4"):
        vm.order_track(empty, channel="acc", tach="tach")


def test_a_slow_noisy_keyphasor_gives_one_pulse_per_revolution():
    # a proximity-probe keyphasor: a raised-cosine notch over 30 % of a revolution with noise at 3 %
    # of its height. Crossing the mid level plainly counts the noise on the slow edges too (about 1.5
    # pulses per revolution here); with the hysteresis (10 % of the range) each revolution is one pulse
    # and the speed comes out within 1e-4 (the pulse timing error over 124 revolutions)
    fs, f1 = 10_000.0, 25.0
    t = np.arange(int(5 * fs)) / fs
    ph = np.mod(f1 * t, 1.0)
    key = np.where(ph < 0.3, 0.5 - 0.5 * np.cos(2 * np.pi * ph / 0.3), 0.0)
    key += 0.03 * np.random.default_rng(0).normal(size=t.size)
    plain = np.flatnonzero((key[1:] >= 0.5) & (key[:-1] < 0.5)).size
    assert plain > 1.3 * 5 * f1
    x = np.sin(2 * np.pi * 4.0 * f1 * t)
    rec = vm.Record(np.vstack([x, key]), fs, [vm.Channel("acc", "acceleration", "g"), vm.Channel("key")])
    ang = vm.order_track(rec, channel="acc", tach="key", samples_per_rev=32)
    spec = vm.amplitude_spectrum(ang, window="flattop")
    assert spec.freq[np.argmax(spec.values[0])] == pytest.approx(4.0, abs=0.01)   # order 4 stays order 4
    from vibmeasure.signal.demod import shaft_angle
    a = shaft_angle(rec, tach="key")
    ok = np.isfinite(a)
    assert (a[ok][-1] - a[ok][0]) / (t[ok][-1] - t[ok][0]) == pytest.approx(f1, rel=1e-4)
