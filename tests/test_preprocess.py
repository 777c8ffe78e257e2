"""Integration, differentiation, filters and resampling against closed forms; units follow."""
import numpy as np
import pytest

import vibmeasure as vm

FS = 1000.0


def accel(n=10000, f=10.0, unit="m/s^2", a=1.0):
    t = np.arange(n) / FS
    return vm.Record.from_array(a * np.sin(2 * np.pi * f * t), fs=FS, quantity="acceleration", unit=unit, name="a")


def test_frequency_domain_integration_of_a_sine():
    # 1 m/s^2 at 10 Hz -> 1/(2 pi 10) m/s -> 1/(2 pi 10)^2 m; whole periods (the
    # extension past the ends continues the tone; its taper's leakage below the corner is 3e-9 relative):
    # within 1e-8 of the amplitude
    v = vm.integrate(accel())
    d = vm.integrate(v)
    w = 2 * np.pi * 10.0
    t = np.arange(10000) / FS
    np.testing.assert_allclose(v.data[0], -np.cos(w * t) / w, rtol=0, atol=1e-8 / w)
    np.testing.assert_allclose(d.data[0], -np.sin(w * t) / w ** 2, rtol=0, atol=1e-7 / w ** 2)  # twice: 1e-7
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


@pytest.mark.parametrize("f0", [2.5, 3.7, 37.3, 211.9, 1000.3])
def test_frequency_domain_integration_of_a_tone_that_is_not_periodic_in_the_record(f0):
    # issue: 2 m/s^2 at 37.3 Hz, fs 2560 Hz, 16,384 samples gave 0.00866 m/s in the middle instead of
    # 0.00853 (1.5 %). Target: 0.1 % in the middle 80 % for any tone above 1.25 x the corner (2 Hz);
    # the oracle is the closed-form integral -A/w cos(w t + phi)
    fs, n = 2560.0, 16384
    t = np.arange(n) / fs
    w = 2 * np.pi * f0
    r = vm.Record.from_array(2.0 * np.sin(w * t + 0.3), fs=fs, quantity="acceleration", unit="m/s^2")
    v = vm.integrate(r).data[0]
    mid = slice(n // 10, n - n // 10)
    err = np.max(np.abs(v[mid] + 2.0 / w * np.cos(w * t[mid] + 0.3))) / (2.0 / w)
    assert err < 1e-3, err


def test_time_domain_integration_agrees_with_the_frequency_domain_away_from_the_ends(sample_dir):
    # issue: the README's example (machine.h5, method="time", highpass=1.0) gave a velocity RMS of
    # 0.0144 m/s where the frequency method and the analytic 1X give 0.0030: the filters' start-up
    # wandered through the whole 4 s record. Both now run on the record continued past its ends;
    # target: RMS within 1 % away from the ends (the middle 80 %)
    rec = vm.read(sample_dir / "machine.h5")
    for hp in (1.0, 2.0):
        f = vm.integrate(rec, highpass=hp).data[0]
        t = vm.integrate(rec, method="time", highpass=hp).data[0]
        mid = slice(rec.n_samples // 10, rec.n_samples - rec.n_samples // 10)
        assert np.std(t[mid]) == pytest.approx(np.std(f[mid]), rel=0.01)
        assert np.std(f[mid]) == pytest.approx(0.0030, rel=0.03)  # the synthetic machine's velocity RMS


def test_the_extension_past_the_ends_continues_tones_and_never_grows():
    # a Burg AR model is stable (|reflection| < 1): the continuation of noise decays, that of a tone goes
    # on with its phase (checked one period past the end), and the taper brings both to zero
    from vibmeasure.signal.preprocess import extend
    rng = np.random.default_rng(0)
    noise = rng.normal(size=4000)
    e = extend(noise, 3000)
    assert e.size == 10000 and np.max(np.abs(e[:3000])) <= np.max(np.abs(noise)) and e[0] == 0.0 == e[-1]
    t = np.arange(4100) / 1000.0
    tone = np.sin(2 * np.pi * 12.3 * t)
    e = extend(tone[:4000], 1000)
    np.testing.assert_allclose(e[5000:5100], tone[4000:4100], atol=1e-4)  # phase kept to 1e-4 rad


def test_g_is_converted_before_integrating():
    v = vm.integrate(accel(unit="g"))
    assert np.max(np.abs(v.data[0])) == pytest.approx(9.80665 / (2 * np.pi * 10), rel=1e-6)


def test_differentiate_inverts_integrate():
    v = vm.integrate(accel())
    a = vm.differentiate(v)
    np.testing.assert_allclose(a.data[0], accel().data[0], atol=1e-8)  # the taper past the ends: 3e-9
    assert a.channels[0].quantity == "acceleration"


def test_integration_of_a_record_too_short_is_a_named_error():
    # two or three samples used to end in numpy's broadcasting and scipy's padlen errors
    for n in (2, 3, 15):
        r = vm.Record.from_array(np.arange(n, dtype=float), fs=100.0, quantity="acceleration", unit="m/s^2")
        for method in ("frequency", "time"):
            with pytest.raises(vm.ParameterError, match="needs at least 16"):
                vm.integrate(r, method=method)


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


def test_derivative_of_a_tone_and_its_bad_input():
    """Oracle: d/dt sin(2 pi 5 t) = 2 pi 5 cos(2 pi 5 t); continued past its ends, the derivative holds to
    1e-6 of its amplitude even at the record's first and last samples (the tone is continued by
    prediction, so no wrap-around jump rings). Bad input is named."""
    from vibmeasure.signal.preprocess import derivative
    t = np.arange(4000) / 1000.0
    w = 2 * np.pi * 5
    d = derivative(np.sin(w * t) + 3.0, 1000.0)
    assert np.max(np.abs(d - w * np.cos(w * t))) < 1e-6 * w
    assert np.max(np.abs(derivative(np.sin(w * t), 1000.0, 2) + w ** 2 * np.sin(w * t))) < 1e-5 * w ** 2
    for kw, match in ((dict(fs=0.0), "fs"), (dict(fs=1000.0, order=0), "order"),
                      (dict(fs=1000.0, order=1.5), "order")):
        with pytest.raises(vm.ParameterError, match=match):
            derivative(np.sin(w * t), **kw)
    with pytest.raises(vm.ParameterError, match="finite"):
        derivative(np.r_[np.sin(w * t[:-1]), np.nan], 1000.0)
