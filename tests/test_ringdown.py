"""Maximum-likelihood ring-down identification against closed-form decays and the Cramer-Rao bound."""
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vibmeasure as vm
from vibmeasure.identify.ringdown import ringdown_crb

# noise-free float64 decays: the fit converges to round-off, far below this
EXACT = 1e-8


def _quiet(fn, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        return fn(*a, **k)


@pytest.mark.parametrize("zeta", [1e-3, 0.01, 0.1, 0.5])
@pytest.mark.parametrize("fn,fs", [(10.37, 1000.0), (3.3171, 1000.0), (97.13, 1000.0), (10.37, 104.0)])
def test_noise_free_exact(zeta, fn, fs):
    dur = max(12 / fn, 10.0 if zeta < 0.05 else 12 / fn)
    rec = vm.synth.free_decay(fn=fn, zeta=zeta, fs=fs, duration=dur, phase=0.3, amplitude=2.0)
    est = _quiet(vm.ringdown, rec)
    assert est.n_modes == 1
    assert est.fn[0] == pytest.approx(fn, rel=EXACT)
    assert est.zeta[0] == pytest.approx(zeta, rel=EXACT)
    assert est.amplitude[0] == pytest.approx(2.0, rel=1e-6)


@pytest.mark.parametrize("quantity", ["velocity", "acceleration"])
def test_quantity_does_not_change_modal_parameters(quantity):
    rec = vm.synth.free_decay(fn=[12.1, 33.7], zeta=[0.01, 0.03], fs=1000.0, duration=8.0, quantity=quantity)
    est = vm.ringdown(rec)
    np.testing.assert_allclose(est.fn, [12.1, 33.7], rtol=EXACT)
    np.testing.assert_allclose(est.zeta, [0.01, 0.03], rtol=EXACT)
    assert est.unit == ("m/s" if quantity == "velocity" else "m/s^2")


def test_monte_carlo_against_cramer_rao_fast():
    """60 seeds of the issue's cell (10.37 Hz, zeta 0.02, 1 kHz, 10 s, 40 dB); the full table with 400
    seeds per cell is benchmarks/ringdown_accuracy.py. Tolerances: with 60 samples an RMSE ratio
    scatters by about 9 %, a mean by 0.13 bound-std; 1.3x and 0.45 are about 3 sigma above the targets
    (1.15x, 0.2)."""
    fn, z = 10.37, 0.02
    crb = ringdown_crb(fn=fn, zeta=z, fs=1000.0, duration=10.0, snr_db=40, phase=0.7)
    ef, ez, sf, sz = [], [], [], []
    for seed in range(60):
        rec = vm.synth.free_decay(fn=fn, zeta=z, fs=1000.0, duration=10.0, snr_db=40, phase=0.7, seed=seed)
        e = vm.ringdown(rec)
        ef.append(e.fn[0] - fn); ez.append(e.zeta[0] - z); sf.append(e.fn_std[0]); sz.append(e.zeta_std[0])
    ef, ez = np.array(ef), np.array(ez)
    assert np.sqrt(np.mean(ef ** 2)) <= 1.3 * crb["fn_std"]
    assert np.sqrt(np.mean(ez ** 2)) <= 1.3 * crb["zeta_std"]
    assert abs(ef.mean()) <= 0.45 * crb["fn_std"]
    assert abs(ez.mean()) <= 0.45 * crb["zeta_std"]
    # the reported std agrees with the observed scatter (60 samples: +-9 %, so 30 % is 3 sigma)
    assert np.mean(sf) / ef.std() == pytest.approx(1.0, abs=0.3)
    assert np.mean(sz) / ez.std() == pytest.approx(1.0, abs=0.3)


def test_crb_matches_fisher_std_at_truth():
    rec = vm.synth.free_decay(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0)
    crb = ringdown_crb(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40)
    # closed-form cross-check: for light damping and a record much longer than the decay, the (sigma, A)
    # block of the Fisher information gives var(sigma) = 16 sigma^3 s^2 / (fs A^2); zeta ~ sigma / wn.
    # The asymptotic form neglects the sigma-w coupling and the finite record: 5 %.
    s, sig, wn = crb["noise_std"], 0.02 * 2 * np.pi * 10.37, 2 * np.pi * 10.37
    approx = 4 * s * np.sqrt(sig ** 3 / 1000.0) / wn
    assert crb["zeta_std"] == pytest.approx(approx, rel=0.05)
    assert rec.n_samples == 10000


def test_three_modes_at_40db():
    fns, zetas = np.array([21.3, 57.9, 110.4]), np.array([0.010, 0.020, 0.015])
    for seed in range(5):
        rec = vm.synth.free_decay(fn=fns, zeta=zetas, amplitude=[1.0, 0.8, 0.6], phase=[0.0, 1.0, 2.0],
                                  fs=2000.0, duration=6.0, snr_db=40, seed=seed)
        est = vm.ringdown(rec)
        assert est.n_modes == 3
        np.testing.assert_allclose(est.fn, fns, rtol=5e-4)   # 0.05 %
        np.testing.assert_allclose(est.zeta, zetas, rtol=0.03)  # 3 %


def test_offset_drift_and_band_and_n_modes():
    rec = vm.synth.free_decay(fn=[15.2, 40.4], zeta=[0.01, 0.02], fs=1000.0, duration=8.0, snr_db=40,
                              dc_offset=0.7, drift=0.05, seed=4)
    est = vm.ringdown(rec)
    assert est.n_modes == 2
    for f, z, fs_, zs in zip(est.fn, est.zeta, est.fn_std, est.zeta_std):
        ft, zt = (15.2, 0.01) if f < 30 else (40.4, 0.02)
        assert abs(f - ft) < 4 * fs_ and abs(z - zt) < 4 * zs  # unbiased within 4 std
    only = vm.ringdown(rec, band=(30, 50))
    assert only.n_modes == 1 and only.fn[0] == pytest.approx(40.4, rel=1e-3)
    one = vm.ringdown(rec, n_modes=1)
    assert one.n_modes == 1 and one.fn[0] == pytest.approx(15.2, rel=1e-3)  # the stronger one


def test_clipped_samples_are_excluded_and_flagged():
    rec = vm.synth.free_decay(fn=10.37, zeta=0.01, fs=1000.0, duration=5.0, snr_db=40, clip=0.7, seed=2)
    with pytest.warns(vm.QualityWarning, match="clipped"):
        est = vm.ringdown(rec)
    assert "clipped" in est.flags
    assert abs(est.fn[0] - 10.37) < 4 * est.fn_std[0]
    assert abs(est.zeta[0] - 0.01) < 4 * est.zeta_std[0]


def test_few_cycles_resolution_and_close_modes_flags():
    with pytest.warns(vm.QualityWarning, match="few_cycles"):
        e = vm.ringdown(vm.synth.free_decay(fn=10.0, zeta=0.2, fs=1000.0, duration=2.0, snr_db=40, seed=2))
    assert "few_cycles" in e.flags
    with pytest.warns(vm.QualityWarning, match="resolution_limited"):
        e = vm.ringdown(vm.synth.free_decay(fn=10.37, zeta=0.01, fs=60.0, duration=10.0, snr_db=40, seed=2))
    assert "resolution_limited" in e.flags and e.fn[0] == pytest.approx(10.37, rel=1e-3)
    with pytest.warns(vm.QualityWarning, match="close_modes"):
        e = vm.ringdown(vm.synth.free_decay(fn=[10.0, 10.15], zeta=0.005, fs=1000.0, duration=10.0,
                                            snr_db=40, seed=2))
    assert e.n_modes == 2 and all("close_modes" in m for m in e.mode_flags)
    np.testing.assert_allclose(e.fn, [10.0, 10.15], rtol=1e-4)


def test_stationary_tone_is_not_a_mode():
    rec = vm.synth.free_decay(fn=10.37, zeta=0.01, fs=1000.0, duration=5.0, snr_db=40, seed=2)
    x = rec.data[0] + 0.1 * np.sin(2 * np.pi * 50.0 * rec.time)  # mains pick-up
    est = vm.ringdown(vm.Record.from_array(x, fs=1000.0))
    assert est.n_modes == 1 and est.fn[0] == pytest.approx(10.37, rel=1e-4)
    assert est.extras["tones_hz"] == [pytest.approx(50.0, rel=1e-5)]


def test_only_a_tone_is_a_fit_error_that_names_it():
    # a steady sinusoid in noise holds no decay: FitError, carrying the tone (EFDD tells a harmonic by it)
    t = np.arange(20000) / 1000.0
    x = np.sin(2 * np.pi * 50.0 * t) + np.random.default_rng(3).normal(0, 0.01, t.size)
    with pytest.raises(vm.FitError, match="only stationary tones") as exc:
        vm.ringdown(vm.Record.from_array(x, fs=1000.0))
    assert exc.value.tones_hz == [pytest.approx(50.0, rel=1e-5)]


def test_impact_with_force_channel_starts_after_the_pulse():
    fs, n = 2500.0, 10000
    t = np.arange(n) / fs
    t_hit = 0.5
    force = np.where((t >= t_hit) & (t < t_hit + 0.004), np.sin(np.pi * (t - t_hit) / 0.004), 0.0)
    resp = vm.synth.free_decay(fn=[34.1, 212.3], zeta=[0.002, 0.004], fs=fs, duration=(n / fs) - t_hit,
                               phase=np.pi / 2, amplitude=[1.0, 0.3]).data[0]
    x = np.concatenate([np.zeros(int(t_hit * fs)), resp]) + np.random.default_rng(1).normal(0, 1e-3, n)
    rec = vm.Record(np.vstack([force, x]), fs=fs, channels=[vm.Channel("hammer", "force", "N"),
                                                            vm.Channel("acc", "acceleration", "m/s^2")])
    est = vm.ringdown(rec)
    assert "start_detected" in est.flags and est.extras["channel"] == "acc"
    assert est.extras["start_s"] == pytest.approx(t_hit + 0.004, abs=2 / fs)
    np.testing.assert_allclose(est.fn, [34.1, 212.3], rtol=1e-4)
    np.testing.assert_allclose(est.zeta, [0.002, 0.004], rtol=0.05)


def test_overdamped_reported_without_frequency():
    rec = vm.synth.free_decay(fn=10.0, zeta=1.5, fs=1000.0, duration=2.0, noise_std=1e-4, seed=1)
    with pytest.warns(vm.QualityWarning, match="overdamped"):
        est = vm.ringdown(rec)
    assert "overdamped" in est.flags and np.isnan(est.fn[0])
    assert est.zeta[0] == pytest.approx(1.5, abs=4 * est.zeta_std[0])


def test_coulomb_friction_detected():
    rec = vm.synth.coulomb_decay(fn=4.2, friction_decay=4e-4, amplitude=5e-3, fs=500.0, duration=6.0,
                                 snr_db=50, seed=3)
    with pytest.warns(vm.QualityWarning, match="Coulomb"):
        est = vm.ringdown(rec)
    assert "coulomb_friction" in est.flags and np.isnan(est.zeta[0])
    d = est.extras["friction_decay_per_cycle"]
    assert abs(d - 4e-4) < 4 * est.extras["friction_decay_per_cycle_std"]
    assert abs(est.fn[0] - 4.2) < 4 * est.fn_std[0]


def test_amplitude_dependent_damping_reported_as_table():
    # quadratic (drag) damping: the equivalent viscous zeta grows with amplitude
    fn, fs = 5.0, 500.0
    wn = 2 * np.pi * fn
    t = np.arange(6000) / fs
    sol = solve_ivp(lambda _, y: [y[1], -2 * 0.003 * wn * y[1] - 0.1 * abs(y[1]) * y[1] - wn ** 2 * y[0]],
                    (0, t[-1]), [1.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-12)
    x = sol.y[0] + np.random.default_rng(1).normal(0, 1e-3, t.size)
    with pytest.warns(vm.QualityWarning, match="amplitude_dependent"):
        est = vm.ringdown(vm.Record.from_array(x, fs=fs))
    assert est.n_modes == 1 and "amplitude_dependent" in est.flags
    table = est.extras["zeta_vs_amplitude"]
    amps = [r["amplitude"] for r in table]
    zs = [r["zeta"] for r in table]
    assert amps == sorted(amps, reverse=True) and zs[0] > 2 * zs[-1]
    # drag kappa|v|v dissipates (8/3) kappa A^3 w^2 per cycle: c_eq = 8 kappa A w / (3 pi), so
    # zeta_eq = zeta0 + 4 kappa A / (3 pi) at amplitude A (first-harmonic balance; 15 % covers the
    # amplitude change within each group of cycles)
    for a, z in zip(amps, zs):
        assert z == pytest.approx(0.003 + 4 * 0.1 * a / (3 * np.pi), rel=0.15)


def test_linear_damping_not_called_amplitude_dependent():
    for seed in range(10):
        est = vm.ringdown(vm.synth.free_decay(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40, seed=seed))
        assert "amplitude_dependent" not in est.flags


# --- refusals and bad input -------------------------------------------------------------------
def test_pure_noise_refused(rng):
    with pytest.raises(vm.FitError, match="noise"):
        vm.ringdown(vm.Record.from_array(rng.normal(size=5000), fs=1000.0))


def test_too_uncertain_refused():
    rec = vm.synth.free_decay(fn=10.0, zeta=0.1, fs=1000.0, duration=2.0, snr_db=0, seed=1)
    with pytest.raises(vm.FitError, match="too uncertain|relative std"):
        vm.ringdown(rec)


def test_shorter_than_two_cycles_refused():
    rec = vm.synth.free_decay(fn=10.0, zeta=0.01, fs=1000.0, duration=0.15, snr_db=40, seed=1)
    with pytest.raises(vm.FitError, match="too short.*1.5 cycles"):
        vm.ringdown(rec)


@pytest.mark.parametrize("data,match", [
    (np.array([]), "empty"),
    (np.ones(1000), "constant"),
    (np.r_[np.sin(np.arange(1000) / 5.0), np.nan], "NaN/inf.*index 1000"),
    (np.r_[np.sin(np.arange(1000) / 5.0), np.inf], "NaN/inf"),
    (np.arange(5.0), "at least 16"),
])
def test_bad_data(data, match):
    with pytest.raises(vm.ParameterError, match=match):
        vm.ringdown(vm.Record.from_array(data, fs=100.0))


def test_bad_arguments():
    rec = vm.synth.free_decay(fn=10.0, zeta=0.01, fs=1000.0, duration=2.0)
    with pytest.raises(vm.ParameterError, match="fs .Hz. is required"):
        vm.ringdown(rec.data[0])
    with pytest.raises(vm.ParameterError, match="fs="):
        vm.ringdown(rec.data[0], fs=-5.0)
    with pytest.raises(vm.ParameterError, match="'nope' is not in this record"):
        vm.ringdown(rec, channel="nope")
    with pytest.raises(vm.ParameterError, match="n_modes"):
        vm.ringdown(rec, n_modes=0)
    with pytest.raises(vm.ParameterError, match="band="):
        vm.ringdown(rec, band=(10, 900))
    with pytest.raises(TypeError):
        vm.ringdown(rec, nmodes=2)  # unknown keywords are rejected, not swallowed


# --- real recordings --------------------------------------------------------------------------
def test_real_nimt_single_light_mode(shared_data):
    rec = vm.read(shared_data("ringdown/NIMT_lab1_DanHendata_009.lvm"), fs=10000)
    with pytest.warns(vm.QualityWarning):
        est = vm.ringdown(rec)
    assert est.n_modes == 1 and "amplitude_dependent" in est.flags
    # one mode near 439.1 Hz (origin's analysis); our std is 2e-4 Hz, the reference is given to 0.1 Hz
    assert est.fn[0] == pytest.approx(439.1, abs=0.1)
    # zeta about 5e-5 (19x in 24 s gives 4.5e-5); damping falls with amplitude from 6.3e-5 to 4.7e-5 here,
    # so the average lies in that range and the table spans it
    assert 4.5e-5 < est.zeta[0] < 6.5e-5
    zs = [r["zeta"] for r in est.extras["zeta_vs_amplitude"]]
    assert zs[0] > 1.2 * zs[-2]
    # the classic methods agree with the ML average within 5 % (they weight the cycles differently)
    ld = vm.log_decrement(rec)
    assert ld.zeta[0] == pytest.approx(est.zeta[0], rel=0.05)
    assert ld.fn[0] == pytest.approx(est.fn[0], abs=0.01)


@pytest.mark.parametrize("struct,fn_ref,zeta_lo,zeta_hi", [("Fe", 7.89, 0.006, 0.012), ("Al", 6.89, 0.004, 0.0075)])
def test_real_dexpilab_beams(shared_data, struct, fn_ref, zeta_lo, zeta_hi):
    rec = vm.read(shared_data("ringdown/dexpilab1_VDeXpiLab1_Exp.mat"), channels=[f"{struct}.Out.Acc[0]"])
    with pytest.warns(vm.QualityWarning, match="amplitude_dependent"):
        est = vm.ringdown(rec, band=(4, 12))
    assert est.n_modes == 1
    # references (about 7.89 Hz / 0.9 % and 6.89 Hz / 0.5 %) are averages of an amplitude-dependent
    # damping (1 % at the start, 0.3-0.4 % late): fn within 1 %, zeta inside the range the table spans
    assert est.fn[0] == pytest.approx(fn_ref, rel=0.01)
    assert zeta_lo < est.zeta[0] < zeta_hi
    zs = [r["zeta"] for r in est.extras["zeta_vs_amplitude"]]
    assert max(zs) > 1.5 * min(zs)


def test_real_case1_hammer_response(shared_data):
    rec = vm.read(shared_data("impact/case1.mat"))
    rec = rec.replace(channels=(vm.Channel("Time_chan_1", "force"), vm.Channel("Time_chan_2")))
    with pytest.warns(vm.QualityWarning):
        est = vm.ringdown(rec)
    i1 = int(np.argmin(abs(est.fn - 34.06)))
    i2 = int(np.argmin(abs(est.fn - 212.1)))
    # frequencies to the references' last digit; our std is about 1e-3 Hz
    assert est.fn[i1] == pytest.approx(34.06, abs=0.01)
    assert est.fn[i2] == pytest.approx(212.1, abs=0.01)
    # zeta near 0.0002 and 0.0009 (one significant digit in the references): within 3 std or 10 %
    assert abs(est.zeta[i1] - 0.0002) < max(3 * est.zeta_std[i1], 2e-5)
    assert abs(est.zeta[i2] - 0.0009) < max(3 * est.zeta_std[i2], 9e-5)


# --- backbone: fn and zeta versus amplitude (nonlinear decays) -------------------------------------

def _duffing_decay(k3_over_k, zeta=0.005, fn=10.0, fs=1000.0, T=12.0, noise=1e-4, friction=0.0, seed=0):
    from scipy.integrate import solve_ivp
    w0 = 2 * np.pi * fn
    k, k3, c = w0 ** 2, k3_over_k * w0 ** 2, 2 * zeta * w0
    t = np.arange(int(T * fs)) / fs

    def f(_, y):  # unit mass; dry friction smoothed over 1e-3 of the initial velocity amplitude
        return [y[1], -c * y[1] - k * y[0] - k3 * y[0] ** 3 - friction * np.tanh(y[1] / (1e-3 * w0))]
    sol = solve_ivp(f, (0, T), [1.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-12, method="DOP853")
    x = sol.y[0] + noise * np.random.default_rng(seed).standard_normal(t.size)
    return vm.Record.from_array(x, fs=fs)


def _duffing_frequency(A, k, k3):
    """Exact frequency of the undamped Duffing oscillator x'' + k x + k3 x^3 = 0 at peak amplitude A:
    T = 4 int_0^A dx / sqrt(k (A^2 - x^2) + k3 / 2 (A^4 - x^4)) (x = A sin u removes the singularity)."""
    from scipy.integrate import quad
    per = 4 * quad(lambda u: 1 / np.sqrt(k + k3 / 2 * A ** 2 * (1 + np.sin(u) ** 2)), 0, np.pi / 2)[0]
    return 1 / per


def test_backbone_of_a_duffing_decay_follows_the_exact_backbone():
    # stiffening cubic spring: fn rises 1.8 % at the start. Oracle: the exact period of the undamped
    # Duffing oscillator at each window's amplitude. Tolerance: 4 std of each window, or 2e-4 relative
    # (the window fits the fundamental of a decaying, slightly non-sinusoidal motion: harmonics of order
    # k3 A^2 / 32 k = 0.2 % shift the amplitude it reads)
    k3k = 0.04 / 0.75
    est = vm.ringdown(_duffing_decay(k3k))
    assert "amplitude_dependent_frequency" in est.mode_flags[0]
    bb = est.extras["backbone"]
    assert len(bb) >= 20 and set(bb["mode"]) == {0}
    k = (2 * np.pi * 10.0) ** 2
    true = np.array([_duffing_frequency(a, k, k3k * k) for a in bb["amplitude"]])
    assert np.all(np.abs(bb["fn_hz"] - true) <= np.maximum(4 * bb["fn_std_hz"], 2e-4 * true))
    assert np.all(np.abs(bb["zeta"] - 0.005) <= 4 * bb["zeta_std"] + 2e-4)  # viscous: zeta flat
    m = est.extras["backbone_model"][0]
    assert m["k3_over_k"] == pytest.approx(k3k, rel=0.02)  # first-order harmonic balance: 1 % model error here
    assert m["fn0_hz"] == pytest.approx(10.0, rel=1e-4)


def test_backbone_of_a_linear_decay_is_flat_and_unflagged():
    est = vm.ringdown(_duffing_decay(0.0))
    assert "amplitude_dependent_frequency" not in est.mode_flags[0]
    m = est.extras["backbone_model"][0]
    assert abs(m["k3_over_k"]) < 4 * m["k3_over_k_std"] + 1e-5


def test_backbone_of_a_decay_with_dry_friction_recovers_the_friction_term():
    # viscous zeta 0.005 plus a friction force F (unit mass): equivalent zeta(A) = zeta + 2 F / (pi k A)
    # (harmonic balance); the fitted friction term must match 2 F / (pi k) within 3 std + 10 %
    F = 3.0  # friction term 2F/(pi k) = 4.8e-4: equal to the viscous zeta at A = 0.1
    est = vm.ringdown(_duffing_decay(0.0, friction=F, T=6.0))
    m = est.extras["backbone_model"][0]
    k = (2 * np.pi * 10.0) ** 2
    expect = 2 * F / (np.pi * k)
    assert abs(m["friction_term"] - expect) <= 3 * m["friction_term_std"] + 0.1 * expect
    bb = est.extras["backbone"]
    assert bb["zeta"].iloc[-1] > bb["zeta"].iloc[0]  # damping ratio grows as the amplitude falls


def test_plot_backbone_draws_both_panels_with_units():
    import matplotlib
    matplotlib.use("Agg")
    from vibmeasure.plot import plot_backbone
    est = vm.ringdown(_duffing_decay(0.04 / 0.75))
    ax = plot_backbone(est)
    assert ax[0].get_ylabel() == "natural frequency fn [Hz]" and ax[1].get_xlabel().startswith("amplitude [")
    assert len(ax[0].lines) >= 1  # the model curve over the windows


def test_band_limited_fit_follows_the_band_noise_not_the_broadband_noise(shared_data):
    # issue: with band 5-20 Hz on dexpilab Al.Out.Acc[1] the fit stopped at 6.7 s while the 6.9 Hz
    # oscillation stands out of the band's noise to about 12 s: the span was set by the broadband
    # level (raised by the 46 and 215 Hz components). The band's modes now end where they sink into the
    # band's own noise floor; the span must reach past 10 s, and the estimate keeps its accuracy
    rec = vm.read(shared_data("ringdown/dexpilab1_VDeXpiLab1_Exp.mat"), channels=["Al.Out.Acc[1]"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.ringdown(rec, band=(5, 20))
    assert est.extras["fit_span_s"] > 10.0
    assert est.n_modes == 1 and 6.8 < est.fn[0] < 6.95
    assert est.zeta_std[0] < 0.05 * est.zeta[0]


def test_an_oversampled_decay_is_fitted_on_a_decimated_copy_at_the_bound():
    # 31.7 Hz sampled at 10 kHz (315 samples per cycle): the noise outside the mode's band carries no
    # information, so the fit runs on every q-th sample after an anti-alias filter and stays at the
    # Cramer-Rao bound (over 24 seeds the errors scatter like the bound: RMSE within 1.5 x, reason:
    # 24 samples of a chi distribution) while the stated std matches the scatter
    fs, n, fn = 10_000.0, 100_000, 31.7
    zeta = 0.5 / (2 * np.pi * fn * n / fs)
    crb = ringdown_crb(fn=fn, zeta=zeta, fs=fs, duration=n / fs, snr_db=40)
    ef, ez, stated = [], [], []
    for seed in range(24):
        rec = vm.synth.free_decay(fn=fn, zeta=zeta, fs=fs, duration=n / fs, snr_db=40, seed=seed, phase=0.4)
        est = vm.ringdown(rec)
        assert est.extras["decimation"] >= 10 and est.n_modes == 1
        ef.append(est.fn[0] - fn)
        ez.append(est.zeta[0] - zeta)
        stated.append(est.zeta_std[0])
    assert np.sqrt(np.mean(np.square(ef))) < 1.5 * crb["fn_std"]
    assert np.sqrt(np.mean(np.square(ez))) < 1.5 * crb["zeta_std"]
    assert 0.7 < np.mean(stated) / crb["zeta_std"] < 1.3
    assert est.extras["n_samples_used"] > 0.99 * n and "every" in " ".join(est.extras["notes"])


def test_decimation_keeps_a_weak_mode_far_above_the_strong_one():
    # the copy keeps ten times the highest line the periodogram shows: a weak 400 Hz mode beside a
    # strong 20 Hz one at fs 20 kHz is still found (and with it no decimation below 8 kHz)
    rec = vm.synth.free_decay(fn=[20.0, 400.0], zeta=[0.002, 0.002], amplitude=[1.0, 0.01], fs=20_000.0,
                              duration=5.0, snr_db=60, seed=3)
    est = vm.ringdown(rec)
    np.testing.assert_allclose(est.fn, [20.0, 400.0], rtol=1e-4)
    assert 20_000.0 / est.extras["decimation"] >= 20 * 400.0


def test_backbone_model_is_reported_only_where_it_fits():
    """A weakly nonlinear model (Duffing stiffness, viscous + friction + quadratic damping) fitted to a
    decay it does not describe gave numbers with small stds (k3/k 1.70 +- 0.24 with chi-square 5384).
    The model stands only when both fits' reduced chi-square pass (4x their 99 % quantile) and the
    friction term is not materially negative; else its terms are NaN, ``fits`` False and ``reason``
    says why. The cases the model was built for (Duffing, linear, dry friction) still fit; a decay
    whose frequency rises with the logarithm of its falling amplitude (2 % per neper, as a softening
    joint might) does not (reduced chi-square 1.8e5)."""
    for kw in (dict(k3_over_k=0.04 / 0.75), dict(k3_over_k=0.0), dict(k3_over_k=0.0, friction=3.0, T=6.0),
               dict(k3_over_k=0.55)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", vm.QualityWarning)
            m = vm.ringdown(_duffing_decay(**kw)).extras["backbone_model"][0]
        assert m["fits"] and m["reason"] is None and np.isfinite(m["k3_over_k"]), kw
    fs = 1000.0
    t = np.arange(int(12 * fs)) / fs
    a = np.exp(-0.005 * 2 * np.pi * 10 * t)
    w = 2 * np.pi * 10 * (1 - 0.02 * np.log(a))
    x = a * np.cos(np.cumsum(w) / fs) + 1e-4 * np.random.default_rng(0).standard_normal(t.size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.ringdown(vm.Record.from_array(x, fs=fs))
    m = est.extras["backbone_model"][0]
    assert not m["fits"] and np.isnan(m["k3_over_k"]) and "chi-square" in m["reason"]


def _windowed_fn(x, fs, t0, length=3.0):
    """fn of one 3 s window, fitted alone (the reference a backbone must agree with)."""
    seg = vm.Record.from_array(x[int(t0 * fs):int((t0 + length) * fs)], fs=fs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        return float(vm.ringdown(seg, n_modes=1, band=(5, 12)).fn[0])


@pytest.mark.parametrize("struct", ["Fe", "Al"])
def test_real_beam_is_followed_as_far_as_the_data_carries_it(shared_data, struct):
    """The beams soften as they decay (fn rises 1 % as the amplitude falls tenfold) and their damping
    falls with amplitude, so the start's decay rate says they sink into the noise after 4.6 s (Fe) and
    2 s (Al), while the fundamental stands 20-40 dB over the floor at the end of the 20 s record. The
    fit follows the decay while its band holds 20 dB over the noise (to 18 s of 20), and the backbone
    past 14 s; its late windows agree with independent 3 s windowed fits within 0.1 % (the backbone's
    windows are shorter and centred differently: measured 0.02-0.06 %), and it rises as they do.
    The Duffing backbone model does not describe a softening beam: it is reported as not fitting."""
    rec = vm.read(shared_data("ringdown/dexpilab1_VDeXpiLab1_Exp.mat"), channels=[f"{struct}.Out.Acc[0]"])
    x = rec.data[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.ringdown(rec)
    assert est.extras["fit_span_s"] > 15.0
    bb = est.extras["backbone"]
    b = bb[bb["mode"] == 0]
    assert b["t_s"].max() > 14.0
    late = b[(b["t_s"] > 12.0) & (b["t_s"] < 15.0)]
    ref = _windowed_fn(x, rec.fs, 12.0)
    assert abs(late["fn_hz"].mean() / ref - 1) < 1e-3
    early = b[(b["t_s"] > 1.0) & (b["t_s"] < 4.0)]
    assert late["fn_hz"].mean() > early["fn_hz"].mean() * 1.004
    assert est.extras["backbone_model"][0]["fits"] is False


@pytest.mark.parametrize("offset,drift", [(1.5, 0.05), (0.0, 0.08)])
def test_real_beam_with_offset_and_drift_keeps_its_fundamental(shared_data, offset, drift):
    """An offset of 1.5 m/s^2 and a drift of 0.05-0.08 m/s^2/s (a few % of the 53 m/s^2 peak) took the
    start values' leading subspace directions: the 7.8 Hz fundamental was lost (a 306 Hz 'mode' with
    zeta 0.68 reported instead; with band=(5, 20) a FitError), and on the aluminium beam a raw
    LinAlgError. The start values now see the record without its line, and the fit models the line:
    the same fundamental as without drift (fn within 1e-5 relative, zeta within 1 %)."""
    rec = vm.read(shared_data("ringdown/dexpilab1_VDeXpiLab1_Exp.mat"), channels=["Fe.Out.Acc[0]"])
    t = np.arange(rec.n_samples) / rec.fs
    drifting = vm.Record.from_array(rec.data[0] + offset + drift * t, fs=rec.fs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        clean = vm.ringdown(rec, band=(5, 20))
        got = vm.ringdown(drifting, band=(5, 20))
        full = vm.ringdown(drifting)
    assert got.fn[0] == pytest.approx(clean.fn[0], rel=1e-5) and got.zeta[0] == pytest.approx(clean.zeta[0], rel=0.01)
    assert full.fn[0] == pytest.approx(clean.fn[0], rel=1e-5)


def test_strongly_stiffening_decay_is_one_mode_with_its_backbone():
    """fn 19 % higher at the start (k3/k 0.55): the cycle groups counted their half periods against the
    average line's, miscounted, and the decay was reported as five 'modes' 10.05-11.28 Hz. Counted
    extreme by extreme it is one mode, flagged, whose backbone model fits and holds k3/k within 3 of
    its stds."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.ringdown(_duffing_decay(0.55))
    assert est.n_modes == 1 and "amplitude_dependent_frequency" in est.mode_flags[0]
    m = est.extras["backbone_model"][0]
    assert m["fits"] and abs(m["k3_over_k"] - 0.55) < 3 * m["k3_over_k_std"]
