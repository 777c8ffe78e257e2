"""Integration, differentiation, filters and resampling against closed forms; units follow."""
import numpy as np
import pytest

import vibmeasure as vm

FS = 1000.0


def accel(n=10000, f=10.0, unit="m/s^2", a=1.0):
    t = np.arange(n) / FS
    return vm.Record.from_array(a * np.sin(2 * np.pi * f * t), fs=FS, quantity="acceleration", unit=unit, name="a")


def test_frequency_domain_integration_of_a_sine():
    # 1 m/s^2 at 10 Hz -> 1/(2 pi 10) m/s -> 1/(2 pi 10)^2 m, exact for whole periods
    v = vm.integrate(accel())
    d = vm.integrate(v)
    w = 2 * np.pi * 10.0
    t = np.arange(10000) / FS
    np.testing.assert_allclose(v.data[0], -np.cos(w * t) / w, atol=1e-12)
    np.testing.assert_allclose(d.data[0], -np.sin(w * t) / w ** 2, atol=1e-12)
    assert (v.channels[0].quantity, v.channels[0].unit) == ("velocity", "m/s")
    assert (d.channels[0].quantity, d.channels[0].unit) == ("displacement", "m")
    assert "integrate" in d.history[-1] and "highpass=2 Hz" in d.history[-1]


def test_time_domain_integration_of_a_sine_with_offset():
    # 30 s at 10 Hz with a sensor offset: away from the ends (where the high-pass transient, integrated,
    # wanders at the corner frequency) the velocity is -cos(wt)/w within 0.1 %
    t = np.arange(30000) / FS
    w = 2 * np.pi * 10.0
    r = vm.Record.from_array(np.sin(w * t) + 0.05, fs=FS, quantity="acceleration", unit="m/s^2")
    v = vm.integrate(r, method="time", highpass=2.0)
    mid = slice(9000, 21000)
    np.testing.assert_allclose(v.data[0, mid] * w, -np.cos(w * t[mid]), atol=1e-3)


def test_g_is_converted_before_integrating():
    v = vm.integrate(accel(unit="g"))
    assert np.max(np.abs(v.data[0])) == pytest.approx(9.80665 / (2 * np.pi * 10), rel=1e-6)


def test_differentiate_inverts_integrate():
    v = vm.integrate(accel())
    a = vm.differentiate(v)
    np.testing.assert_allclose(a.data[0], accel().data[0], atol=1e-9)
    assert a.channels[0].quantity == "acceleration"


def test_integration_refusals():
    d = vm.Record.from_array(np.sin(np.arange(100.0)), fs=FS, quantity="displacement", unit="m")
    with pytest.raises(vm.ParameterError, match="cannot be integrated"):
        vm.integrate(d)
    u = vm.Record.from_array(np.sin(np.arange(100.0)), fs=FS)
    with pytest.raises(vm.ParameterError, match="quantity 'unknown'"):
        vm.integrate(u)
    with pytest.raises(vm.ParameterError, match="highpass="):
        vm.integrate(accel(), highpass=600.0)
    with pytest.raises(vm.UnitError, match="measures acceleration"):
        vm.Record.from_array(np.zeros(4), fs=FS, quantity="velocity", unit="g")


def test_filters_pass_and_stop():
    t = np.arange(20000) / FS
    r = vm.Record.from_array(np.sin(2 * np.pi * 5 * t) + np.sin(2 * np.pi * 200 * t), fs=FS)
    lo = vm.filter(r, kind="lowpass", cutoff=50.0, order=6)
    mid = slice(2000, 18000)
    np.testing.assert_allclose(lo.data[0, mid], np.sin(2 * np.pi * 5 * t[mid]), atol=1e-3)
    bp = vm.filter(r, kind="bandpass", cutoff=(150, 250))
    np.testing.assert_allclose(bp.data[0, mid], np.sin(2 * np.pi * 200 * t[mid]), atol=2e-3)
    with pytest.raises(vm.ParameterError, match="cutoff=700"):
        vm.filter(r, kind="lowpass", cutoff=700)
    with pytest.raises(vm.ParameterError, match="kind="):
        vm.filter(r, kind="notch", cutoff=50)


def test_decimate_resample_detrend():
    t = np.arange(30000) / FS
    r = vm.Record.from_array(np.sin(2 * np.pi * 7 * t) + 3.0 + 0.1 * t, fs=FS)
    d = vm.decimate(r, 10)
    assert d.fs == 100.0 and d.n_samples == 3000
    s = vm.resample(r, 250.0)
    assert s.fs == 250.0 and s.n_samples == 7500
    mid = slice(500, 7000)
    np.testing.assert_allclose(s.data[0, mid], np.sin(2 * np.pi * 7 * s.time[mid]) + 3 + 0.1 * s.time[mid],
                               atol=1e-3)
    z = vm.detrend(r, type="linear")
    assert abs(z.data[0].mean()) < 1e-10
    with pytest.raises(vm.ParameterError, match="factor="):
        vm.decimate(r, 0)
