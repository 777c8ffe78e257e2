"""Fast kurtogram and infogram (1/3-binary tree) and the band squared-envelope spectrum: closed-form
envelope of an AM signal, Gaussian noise scores zero, impacts are found in their resonance band."""
import numpy as np
import pytest

import vibmeasure as vm


def test_band_ses_of_an_am_tone_is_exact():
    # x = A (1 + m cos 2 pi fm t) cos 2 pi fc t: squared envelope A^2 (1 + 2 m cos + m^2 cos^2), so the
    # SES has 2 m A^2 at fm and m^2 A^2 / 2 at 2 fm (lines on bins; the symmetric Hann window is 1e-8 off periodic)
    fs, n, A, m, fc, fm = 10000.0, 20000, 1.5, 0.4, 2500.0, 50.0
    t = np.arange(n) / fs
    x = A * (1 + m * np.cos(2 * np.pi * fm * t)) * np.cos(2 * np.pi * fc * t)
    f, v = vm.band_ses(vm.Record.from_array(x, fs=fs), band=(2000, 3000), f_max=200)
    assert f[1] == pytest.approx(fs / n)
    assert v[np.argmin(np.abs(f - fm))] == pytest.approx(2 * m * A ** 2, rel=1e-6)
    assert v[np.argmin(np.abs(f - 2 * fm))] == pytest.approx(m ** 2 * A ** 2 / 2, rel=1e-6)
    assert v[np.argmin(np.abs(f - 3 * fm))] < 1e-6  # no third line: leakage of the symmetric window only


def test_gaussian_noise_has_zero_kurtosis_and_negentropy_everywhere(rng):
    fs = 12000.0
    x = rng.normal(size=2 ** 17)
    kg = vm.kurtogram(vm.Record.from_array(x, fs=fs), min_bandwidth=500.0)
    assert kg.levels[:4] == (0.0, 1.0, 1.6, 2.0) and kg.n_bands[:4] == (1, 2, 3, 4)
    allk = np.concatenate(kg.kurtosis)
    alln = np.concatenate(kg.negentropy)
    # estimator spread ~ 2/sqrt(samples per band) (>= 5400 here): 0.1 is ~4 standard deviations
    assert np.max(np.abs(allk)) < 0.1 and np.max(np.abs(alln)) < 0.1
    assert kg.min_bandwidth == 500.0 and all(fs / 2 / nb >= 500.0 for nb in kg.n_bands)


def test_impacts_are_found_in_their_resonance_band():
    rec = vm.synth.machine(fault="bearing_outer_race", snr_db=-5, seed=3, duration=4.0, resonance_hz=3500.0)
    for criterion in ("kurtosis", "negentropy"):
        kg = vm.kurtogram(rec, min_bandwidth=600.0, criterion=criterion, cyclic_max=800.0)
        lo, hi = kg.band
        assert lo <= 3500.0 <= hi, (criterion, kg.band)
        assert kg.value > 0.5   # far above the noise level of the previous test
    img = kg.image("kurtosis", n_cols=64)
    assert img.shape == (len(kg.levels), 64)


def test_min_frequency_leaves_low_bands_out(rng):
    kg = vm.kurtogram(vm.Record.from_array(rng.normal(size=50000), fs=10000.0), min_bandwidth=600.0,
                      min_frequency=1500.0)
    for nb, vals in zip(kg.n_bands, kg.kurtosis):
        lo_edges = np.arange(nb) * 5000.0 / nb
        assert np.all(np.isnan(vals[lo_edges < 1500.0 - 1e-9]))
    assert kg.band[0] >= 1500.0


def test_bands_above_the_measured_band_are_left_out(rng):
    # the impacts ring at 3.5 kHz; with the measured band ending at 3 kHz, only bands of which at
    # least 3/4 lie below it remain (others NaN) and the chosen band ends by 3000 + 1/3 of its width
    from vibmeasure.signal.kurtogram import kurtogram_of
    x = vm.synth.machine(fault="bearing_outer_race", snr_db=-5, seed=3, duration=4.0, resonance_hz=3500.0).data[0]
    kg = kurtogram_of(x, 12000.0, min_bandwidth=600.0, max_level=None, criterion="kurtosis", cyclic_max=800.0,
                       f_hi=3000.0)
    for nb, vals in zip(kg.n_bands, kg.kurtosis):
        w = 6000.0 / nb
        lo = np.arange(nb) * w
        assert np.all(np.isnan(vals[np.minimum(lo + w, 3000.0) - lo < 0.75 * w - 1e-9]))
    lo, hi = kg.band
    assert hi - 3000.0 <= (hi - lo) / 3 + 1e-9 and kg.params["max_frequency_hz"] == 3000.0
    full = kurtogram_of(x, 12000.0, min_bandwidth=600.0, max_level=None, criterion="kurtosis", cyclic_max=800.0)
    assert full.band[0] <= 3500.0 <= full.band[1] and full.params["max_frequency_hz"] == 6000.0


def test_bad_input(rng):
    rec = vm.Record.from_array(rng.normal(size=4000), fs=1000.0)
    with pytest.raises(vm.ParameterError, match="criterion="):
        vm.kurtogram(rec, criterion="entropy")
    with pytest.raises(vm.ParameterError, match="min_bandwidth="):
        vm.kurtogram(rec, min_bandwidth=900.0)
    with pytest.raises(vm.ParameterError, match="no band is left"):
        vm.kurtogram(rec, min_bandwidth=300.0, min_frequency=400.0)
    with pytest.raises(vm.ParameterError, match="max_level="):
        vm.kurtogram(rec, max_level=40)
    with pytest.raises(vm.ParameterError, match="band"):
        vm.band_ses(rec, band=(300, 200))
