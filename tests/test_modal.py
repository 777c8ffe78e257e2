"""fit_modes, half-power, circle fit and MAC against analytic FRFs and the FRF-domain Cramer-Rao bound."""
import re
import warnings

import numpy as np
import pytest

import vibmeasure as vm

FN = np.array([21.3, 57.9, 110.4])
ZETA = np.array([0.010, 0.020, 0.015])
PHI = np.array([[0.5, 0.6, 0.4], [0.7, -0.2, -0.6], [0.3, -0.7, 0.6]])
FREQ = np.arange(0, 150.25, 0.25)


def analytic(form="receptance"):
    return vm.synth.modal_frf(FREQ, fn=FN, zeta=ZETA, shapes=PHI, input_dof=0, form=form)


def noisy(frf, seed, level=0.01):
    rng = np.random.default_rng(seed)
    H = frf.h[:, 0]
    s = level * np.abs(H[:, 1:]).max(axis=1)
    n = (rng.normal(size=H.shape) + 1j * rng.normal(size=H.shape)) / np.sqrt(2) * s[:, None]
    return vm.FRF(frf.freq, (H + n)[:, None], frf.form, outputs=frf.outputs, inputs=frf.inputs), s


@pytest.mark.parametrize("form", ["receptance", "mobility", "accelerance"])
def test_noise_free_three_modes_exact(form):
    est = vm.fit_modes(analytic(form), band=(1, 150))
    np.testing.assert_allclose(est.fn, FN, rtol=1e-6)     # issue: 1e-6; observed ~1e-13
    np.testing.assert_allclose(est.zeta, ZETA, rtol=1e-6)
    # shapes: the driving point makes them mass-normalised (receptance) or scaled; MAC with the truth
    m = vm.mac(est.shapes, PHI)
    assert np.all(np.diag(m) > 1 - 1e-9)
    assert min(est.extras["frac"]) > 1 - 1e-12


def test_monte_carlo_against_frf_cramer_rao_fast():
    """25 seeds of 1 % complex noise (the benchmark runs 100): RMSE <= 1.5x bound (25 samples scatter
    an RMSE ratio by ~14 %), |bias| <= 0.6 bound-std (a mean of 25 scatters by 0.2)."""
    frf = analytic()
    wd = 2 * np.pi * FN * np.sqrt(1 - ZETA ** 2)
    R = PHI * PHI[0][None, :] / (2j * wd[None, :])
    errs_f, errs_z = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        for seed in range(25):
            f, s = noisy(frf, seed)
            est = vm.fit_modes(f, band=(1, 150))
            assert est.n_modes == 3
            errs_f.append(est.fn - FN)
            errs_z.append(est.zeta - ZETA)
    crb = vm.modal_crb(FREQ, fn=FN, zeta=ZETA, residues=R, noise_std=s)
    ef, ez = np.array(errs_f), np.array(errs_z)
    assert np.all(np.sqrt((ef ** 2).mean(0)) <= 1.5 * crb["fn_std"])
    assert np.all(np.sqrt((ez ** 2).mean(0)) <= 1.5 * crb["zeta_std"])
    assert np.all(np.abs(ef.mean(0)) <= 0.6 * crb["fn_std"])
    assert np.all(np.abs(ez.mean(0)) <= 0.6 * crb["zeta_std"])
    # the bound for mode 1 matches the figure for this noise (0.49 % of zeta)
    assert crb["zeta_std"][0] / ZETA[0] == pytest.approx(0.0049, rel=0.02)


def test_sdof_efficiency_and_reported_std():
    """SDOF receptance at 20 dB FRF-SNR (noise 10 % of the peak): RMSE within 1.3x the bound over 40
    seeds, and the reported std within 25 % of the observed scatter."""
    f = np.arange(0.5, 60, 0.1)
    frf = vm.synth.modal_frf(f, fn=[20.0], zeta=[0.02], shapes=[[1.0]])
    R = np.array([[1 / (2j * 2 * np.pi * 20.0 * np.sqrt(1 - 0.0004))]])
    errs, stds = [], []
    for seed in range(40):
        fr, s = noisy(frf, seed, level=0.1)
        est = vm.fit_modes(fr, band=(1, 59), n_modes=1)
        errs.append(est.zeta[0] - 0.02)
        stds.append(est.zeta_std[0])
    crb = vm.modal_crb(f, fn=[20.0], zeta=[0.02], residues=R, noise_std=s)
    e = np.array(errs)
    assert np.sqrt(np.mean(e ** 2)) <= 1.3 * crb["zeta_std"][0]
    assert np.mean(stds) / e.std() == pytest.approx(1.0, abs=0.25)


def test_random_excitation_resolution_flag_and_periodic_accuracy():
    fs = 512.0
    rng = np.random.default_rng(2)
    # (a) Hann averaging at 0.25 Hz: mode 1's half-power band (0.43 Hz) spans 1.7 lines -> flagged
    f = rng.normal(size=2 ** 16)
    y = vm.synth.modal_response(f, fs=fs, fn=FN, zeta=ZETA, shapes=PHI)
    y += 0.01 * y.std(axis=1, keepdims=True) * rng.normal(size=y.shape)
    chans = [vm.Channel("F", "force", "N")] + [vm.Channel(f"x{i}", "displacement", "m") for i in range(3)]
    frf = vm.estimate_frf(vm.Record(np.vstack([f, y]), fs=fs, channels=chans), nperseg=2048)
    with pytest.warns(vm.QualityWarning, match="resolution_limited.*leakage biases zeta upwards"):
        est = vm.fit_modes(frf, band=(5, 150))
    k = int(np.argmin(abs(est.fn - 21.3)))
    assert "resolution_limited" in est.mode_flags[k]
    # (b) periodic random (a multisine repeated; rectangular window over whole periods): no leakage
    n_per = 12288  # 24 s period: 0.0417 Hz lines, >= 10 across every half-power band
    k_lines = np.arange(1, int(150 * n_per / fs))
    spec = np.zeros(n_per // 2 + 1, complex)
    spec[k_lines] = np.exp(2j * np.pi * rng.random(k_lines.size))
    period = np.fft.irfft(spec, n_per)
    force = np.tile(period, 6)
    y = vm.synth.modal_response(force, fs=fs, fn=FN, zeta=ZETA, shapes=PHI)
    y += 0.01 * y.std(axis=1, keepdims=True) * rng.normal(size=y.shape)
    rec = vm.Record(np.vstack([force, y])[:, 2 * n_per:], fs=fs, channels=chans)  # transient gone
    frf = vm.estimate_frf(rec, nperseg=n_per, noverlap=0, window="boxcar")
    assert np.isnan(frf.h[0, 0, -1])  # lines the multisine leaves out are NaN, not noise ratios
    est = vm.fit_modes(frf, band=(5, 145))
    np.testing.assert_allclose(est.fn, FN, rtol=5e-4)    # 0.05 %
    np.testing.assert_allclose(est.zeta, ZETA, rtol=0.03)  # 3 %


@pytest.mark.parametrize("form", ["receptance", "mobility", "accelerance"])
@pytest.mark.parametrize("zeta", [0.01, 0.1, 0.3])
def test_half_power_exact_relations(form, zeta):
    # fine lines: the interpolated crossings are exact to ~1e-5; the relations themselves are exact
    f = np.arange(0.01, 60, 0.002)
    frf = vm.synth.modal_frf(f, fn=[20.0], zeta=[zeta], shapes=[[1.0]], form=form)
    est = vm.half_power(frf)
    assert est.zeta[0] == pytest.approx(zeta, rel=2e-4)
    assert est.fn[0] == pytest.approx(20.0, rel=1e-4)


def test_half_power_refusals_and_flags():
    f = np.arange(0.01, 60, 0.01)
    with pytest.raises(vm.FitError, match="lower half-power point does not exist"):
        vm.half_power(vm.synth.modal_frf(f, fn=[20.0], zeta=[0.45], shapes=[[1.0]]))
    coarse = np.arange(0.25, 60, 0.25)
    with pytest.raises(vm.FitError, match=r"spans .* lines \(< 3\)"):
        vm.half_power(vm.synth.modal_frf(coarse, fn=[20.0], zeta=[0.01], shapes=[[1.0]]))
    with pytest.warns(vm.QualityWarning, match="resolution_limited"):
        est = vm.half_power(vm.synth.modal_frf(coarse, fn=[20.0], zeta=[0.04], shapes=[[1.0]]))
    assert "resolution_limited" in est.flags
    with pytest.warns(vm.QualityWarning, match="close_modes"):
        vm.half_power(vm.synth.modal_frf(f, fn=[20.0, 21.5], zeta=[0.02, 0.02], shapes=[[1.0, 1.0]]), band=(15, 20.7))


def test_circle_fit_sdof():
    f = np.arange(10, 30, 0.02)
    frf = vm.synth.modal_frf(f, fn=[20.0], zeta=[0.02], shapes=[[1.0]])
    est = vm.circle_fit(frf, band=(18, 22))
    assert est.fn[0] == pytest.approx(20.0, rel=1e-3)
    assert est.zeta[0] == pytest.approx(0.02, rel=0.01)


def test_circle_fit_is_exact_on_exact_data_and_gives_both_stds():
    # the case: 20 Hz, zeta 0.02, 0.125 Hz lines, band 18-25 Hz (before: 19.938 Hz, zeta 0.0228,
    # fn_std NaN). Viscous mobility obeys tan(theta/2) = (w^2 - wn^2) / (2 zeta wn w) exactly.
    f = np.arange(0, 50, 0.125)
    sd = vm.models.SDOF(m=1.0, k=(2 * np.pi * 20) ** 2, zeta=0.02)
    est = vm.circle_fit(vm.FRF(f, sd.frf(f, form="receptance"), form="receptance"), band=(18, 25))
    assert est.fn[0] == pytest.approx(20.0, rel=1e-9) and est.zeta[0] == pytest.approx(0.02, rel=1e-9)
    assert 0 <= est.fn_std[0] < 1e-9 and 0 <= est.zeta_std[0] < 1e-9   # residual scale: round-off only
    rng = np.random.default_rng(2)
    h = sd.frf(f, form="receptance")
    h = h + 0.01 * np.abs(h).max() * (rng.normal(size=f.size) + 1j * rng.normal(size=f.size)) / np.sqrt(2)
    noisy = vm.circle_fit(vm.FRF(f, h, form="receptance"), band=(18, 25))
    # measured over 40 seeds the errors are about 1.6 of these stds (circle centre taken as known):
    # 5 stds is a bound the estimate must meet, not a calibration
    assert abs(noisy.fn[0] - 20.0) < 5 * noisy.fn_std[0] and abs(noisy.zeta[0] - 0.02) < 5 * noisy.zeta_std[0]


def test_mac_properties():
    m = vm.mac(PHI)
    assert np.allclose(np.diag(m), 1.0) and m[0, 1] < 0.2
    with pytest.raises(vm.ParameterError, match="equal n_dof"):
        vm.mac(PHI, PHI[:2])


def test_fit_modes_bad_input():
    frf = analytic()
    with pytest.raises(vm.ParameterError, match="outside the FRF"):
        vm.fit_modes(frf, band=(10, 300))
    h = frf.h.copy()
    h[0, 0, 100] = np.nan
    with pytest.raises(vm.ParameterError, match="NaN/inf line"):
        vm.fit_modes(vm.FRF(frf.freq, h), band=(1, 150))
    flat = vm.FRF(FREQ, np.ones(FREQ.size) * (1 + 0.01 * np.random.default_rng(0).normal(size=FREQ.size)))
    with pytest.raises(vm.FitError, match="no stable mode|no physical mode"):
        vm.fit_modes(flat, band=(1, 150))
    with pytest.raises(vm.ParameterError, match="band=.* is required"):
        vm.fit_modes(frf, band=None)


# --- real data ------------------------------------------------------------------------------------
def _case1_frf(shared_data):
    rec = vm.read(shared_data("impact/case1.mat"))
    rec = rec.replace(channels=(vm.Channel("Time_chan_1", "force"), vm.Channel("Time_chan_2")))
    return vm.impact_frf(rec, input="Time_chan_1")


def test_case1_hammer_frf_modes(shared_data):
    frf = _case1_frf(shared_data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.fit_modes(frf, band=(10, 600))
    i2 = int(np.argmin(abs(est.fn - 212.1)))
    assert est.fn[i2] == pytest.approx(212.1, abs=max(3 * est.fn_std[i2], 0.02))
    # 212 Hz: zeta 0.0009 within 10 % (one significant figure) and its std is stated
    assert est.zeta[i2] == pytest.approx(0.0009, rel=0.1) and est.zeta_std[i2] < 1e-4
    # 34 Hz: its half-power band (0.016 Hz) is far below the 0.31 Hz lines, but the exponential window
    # (tau 0.69 s, known exactly) widens the peak to 1.5 lines and is taken off the pole: zeta 0.0002
    # (the independent fits' one figure) within 3 of its stds, flagged resolution_limited
    i1 = int(np.argmin(abs(est.fn - 34.06)))
    assert est.fn[i1] == pytest.approx(34.06, abs=0.02)
    assert abs(est.zeta[i1] - 0.0002) < max(3 * est.zeta_std[i1], 0.00005)
    assert "resolution_limited" in est.mode_flags[i1]
    assert list(est.fn) == sorted(est.fn)  # frequency order


def test_case1_modes_do_not_depend_on_how_far_the_band_reaches(shared_data):
    """Each mode is fitted again from its own neighbourhood (60 decay rates or 20 lines), the others
    subtracted: a band that reaches further does not move a mode's zeta or std. Before, the 34 Hz mode was 2.1e-4 +- 1.8e-5 in 20-50 Hz, refused as
    'damping too uncertain' (3.7e-4 +- 2.3e-4) in 10-300 Hz and (1.7e-3 +- 1.8e-3) in 10-600 Hz, and the
    212 Hz std moved fivefold (1.6e-6 to 9e-6). Now, over nested bands: the same modes, zeta within
    one std of each other, stds within 10 % (the issue's target; measured within 2 %)."""
    frf = _case1_frf(shared_data)
    got = {34.06: [], 212.1: []}
    for band in ((20, 50), (10, 100), (10, 300), (10, 600), (150, 250), (100, 300)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", vm.QualityWarning)
            est = vm.fit_modes(frf, band=band)
        for f0, lst in got.items():
            if band[0] < f0 < band[1]:
                k = int(np.argmin(abs(est.fn - f0)))
                assert abs(est.fn[k] - f0) < 0.05, (band, est.fn)
                lst.append((est.zeta[k], est.zeta_std[k]))
    for f0, lst in got.items():
        z, s = np.array(lst).T
        assert len(z) >= 4
        assert z.max() - z.min() <= s.mean(), (f0, lst)
        assert s.max() <= 1.10 * s.min(), (f0, lst)


def test_case2_spurious_pole_is_refused_with_its_test(shared_data):
    # before: 194.07 Hz with zeta 3.5e-21 +- 4.1e-4, a pole with no damping and no significant residue.
    # The Wald test of its residue against chi-square(2) at 1 % per fit (Bonferroni over the band's lines)
    # refuses it, and the error names the candidate and the statistic
    rec = vm.read(shared_data("impact/case2.mat"))
    rec = rec.replace(channels=(vm.Channel("Time_chan_1", "force"), vm.Channel("Time_chan_2")))
    frf = vm.estimate_frf(rec, input="Time_chan_1", nperseg=512)
    # the band holds no resonance: the pole either never stabilises (its appearance in the diagram turns
    # on round-off: FRFs equal to 7e-13 take either route) or is refused by its Wald test; nothing is reported
    with pytest.raises(vm.FitError) as info:
        vm.fit_modes(frf, band=(150, 250))
    msg = str(info.value)
    assert "no stable mode in band=(150.0, 250.0)" in msg or re.search(
        r"no mode in band=\(150.0, 250.0\) that the data supports: 19[0-9.]+ Hz: amplitude not significant: Wald", msg)


def test_wald_screen_refuses_a_pole_whose_residue_is_noise_and_keeps_a_real_one():
    # two poles polished on a noisy FRF (0.3 % of the peak, complex Gaussian): the 90 Hz mode with a residue
    # 1e-5 of the first is below the noise: its Wald statistic stays under the chi-square(2) level for a
    # 1 % false alarm over the band's lines (Bonferroni) and it is refused with the statistic named; with a
    # residue of 0.3 it is kept (reason: the test must separate "weak" from "not there")
    from vibmeasure.identify import modal as M
    freq = np.arange(0.25, 150, 0.25)
    w = 2 * np.pi * freq
    fn, zeta = np.array([30.0, 90.0]), np.array([0.02, 0.02])
    lam0 = -zeta * 2 * np.pi * fn + 1j * 2 * np.pi * fn * np.sqrt(1 - zeta ** 2)
    for amp2, refused in ((1e-5, [1]), (0.3, [])):
        H = vm.synth.modal_frf(freq, fn=fn, zeta=zeta, shapes=[[1.0, amp2]]).h[:, 0, :]
        s = 0.003 * np.abs(H).max()
        rng = np.random.default_rng(3)
        Hn = H + s * (rng.normal(size=H.shape) + 1j * rng.normal(size=H.shape)) / np.sqrt(2)
        sw = np.array([np.sqrt(2) / s])
        theta, coef, r = M._polish(w, Hn, lam0, sw)
        cov, _ = M._covariance(w, theta, coef, r, sw)
        out = M._unsupported(theta, coef, cov, sw, None, freq.size, 1, (5, 145), 0.25)
        assert [k for k, _ in out] == refused
        for _, d in out:
            assert d["reason"].startswith("amplitude not significant: Wald") and d["wald"] < 22.0


def test_low_coherence_is_flagged():
    # a real mode (20 Hz, zeta 0.02, 1 % noise) measured with coherence 0.5 around it: reported, flagged
    freq = np.arange(0, 50.0625, 0.0625)
    clean = vm.synth.modal_frf(freq, fn=[20.0], zeta=[0.02], shapes=[[1.0]], input_dof=0)
    rng = np.random.default_rng(2)
    h = clean.h + 0.01 * np.abs(clean.h).max() * (rng.normal(size=clean.h.shape) + 1j * rng.normal(size=clean.h.shape))
    coh = np.where(np.abs(freq - 20) < 2, 0.5, 0.99)[None, :]
    frf = vm.FRF(freq, h, "receptance", coherence=coh, estimator="H1")
    with pytest.warns(vm.QualityWarning, match="low_coherence"):
        est = vm.fit_modes(frf, band=(5, 45))
    assert est.n_modes == 1 and "low_coherence" in est.mode_flags[0]
    assert abs(est.zeta[0] - 0.02) < 4 * est.zeta_std[0]  # flagged, and still right within its std


def test_chowdhury_spectrum_peaks_and_resolution(shared_data):
    spec = vm.read_spectrum(shared_data("frf/Chowdhury_beam_impulse_FFT_data.lvm"))
    assert spec.unit == "g" and spec.df == pytest.approx(0.085333, rel=1e-4)
    peaks = vm.pick_peaks(spec, n=4, band=(1, 150))
    got = sorted(peaks.freq[:3])
    np.testing.assert_allclose(got, [6.62, 41.4, 117.5], rtol=0.01)  # published natural frequencies
    for f0 in (6.62, 41.4):
        try:
            est = vm.half_power(spec, band=(f0 - 2, f0 + 2))
            assert "resolution_limited" in est.flags
        except vm.FitError as exc:
            assert "lines" in str(exc)
        except vm.QualityWarning:
            pass


def test_poly_reference_one_set_of_poles():
    # two inputs (a MIMO test), 3 modes of which two are 5 % apart: input="all" gives one set of poles,
    # at least as precise as either input alone (it uses all FRFs), shapes MAC > 0.999 with the truth
    import warnings
    fn = np.array([20.0, 21.0, 35.0])
    z = np.array([0.01, 0.012, 0.015])
    phi = np.array([[1, 0.8, 0.3], [0.9, -1, 0.6], [0.2, 0.7, -1], [0.5, 0.3, 0.9]])
    f = np.arange(0, 60, 0.05)
    h = np.stack([vm.synth.modal_frf(f, fn=fn, zeta=z, shapes=phi, input_dof=q).h[:, 0, :] for q in (0, 2)], axis=1)
    rng = np.random.default_rng(0)
    h = h + (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) * 0.01 * np.abs(h).mean()
    frf = vm.FRF(f, h, "receptance", outputs=("o0", "o1", "o2", "o3"), inputs=("o0", "o2"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        single = [vm.fit_modes(frf, band=(10, 50), input=k) for k in (0, 1)]
        both = vm.fit_modes(frf, band=(10, 50), input="all")
    np.testing.assert_allclose(both.fn, fn, rtol=1e-4)
    np.testing.assert_allclose(both.zeta, z, rtol=0.05)
    assert np.all(both.zeta_std <= np.minimum(single[0].zeta_std, single[1].zeta_std) * 1.05)
    assert np.all(np.diag(np.abs(vm.mac(phi, both.shapes))) > 0.999)
    part = np.array(both.extras["participation"])
    assert part.shape == (2, 3) and part[1, 0] == pytest.approx(0.2, abs=0.02)   # phi[2,0] / phi[0,0]
    assert len(both.extras["rows"]) == 8
    with pytest.raises(vm.ParameterError, match="distinct inputs"):
        vm.fit_modes(frf, band=(10, 50), input=["o0", "o0"])
