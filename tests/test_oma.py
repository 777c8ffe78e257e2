"""Output-only modal analysis against simulated ambient responses with known modes, and on a real
record."""

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import vibmeasure as vm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from oma import system  # noqa: E402  (the benchmark's 5-dof chain and 6 sensors)

UFF = Path(__file__).resolve().parents[2] / "shared" / "data" / "uff" / "MPSTD_Set001_2024_10_08.uff"


@pytest.fixture(scope="module")
def chain():
    model, sensors = system()
    rec = vm.synth.ambient(model, fs=200.0, duration=600.0, outputs=sensors, noise=0.05, seed=11)
    return model.modes(), sensors, rec


def _matched(truth, est):
    idx = [int(np.argmin(np.abs(est.fn - f))) for f in truth.fn]
    return np.array(idx)


def test_ambient_is_stationary_with_stated_noise(chain):
    truth, sensors, rec = chain
    assert rec.n_channels == 6 and rec.duration == pytest.approx(600.0)
    # first and second halves have the same RMS (warm-up dropped) within 5 % (random error ~2 %)
    h = rec.n_samples // 2
    np.testing.assert_allclose(np.std(rec.data[:, :h], axis=1), np.std(rec.data[:, h:], axis=1), rtol=0.05)
    np.testing.assert_allclose(rec.meta["truth"]["fn"], truth.fn)


def test_ssi_finds_every_mode(chain):
    truth, sensors, rec = chain
    est = vm.oma_ssi(rec, band=(1, 80))
    assert est.n_modes == 5
    i = _matched(truth, est)
    # fn within 0.2 % (the issue; the stated std is about 0.05 %)
    np.testing.assert_allclose(est.fn[i], truth.fn, rtol=0.002)
    # zeta within 4 of its own std: the std means something
    assert np.all(np.abs(est.zeta[i] - truth.zeta) < 4 * est.zeta_std[i])
    mac = np.diag(vm.mac(sensors @ truth.shapes, est.shapes[:, i]))
    assert np.all(mac >= 0.99)
    assert np.all(np.array(est.extras["mpc"]) > 0.95)
    assert est.extras["std_method"].startswith("block jackknife")
    assert not any("near_harmonic" in f for f in est.mode_flags)   # modes are the peaks of their bands
    assert {row[3] for row in est.extras["stabilisation"]} >= {"o", "s"}


def test_ssi_std_calibration_small_monte_carlo():
    # 8 seeds x 5 modes: the zeta errors normalised by the stated std have an RMS within 0.7-1.4
    # (1 would be exact; the issue asks for agreement within 30 %, and with 40 samples the RMS itself
    # scatters by about 11 %: 1 +- (0.3 + 0.1). Measured 0.99)
    model, sensors = system()
    truth = model.modes()
    z = []
    for seed in range(8):
        rec = vm.synth.ambient(model, fs=200.0, duration=600.0, outputs=sensors, noise=0.05, seed=100 + seed)
        est = vm.oma_ssi(rec, band=(1, 80))
        i = _matched(truth, est)
        z.extend((est.zeta[i] - truth.zeta) / est.zeta_std[i])
    rms = float(np.sqrt(np.mean(np.square(z))))
    assert 0.7 < rms < 1.4


def test_fdd_finds_every_mode(chain):
    truth, sensors, rec = chain
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.oma_fdd(rec, band=(1, 80))
    assert est.n_modes == 5
    i = _matched(truth, est)
    np.testing.assert_allclose(est.fn[i], truth.fn, rtol=0.003)   # EFDD: a little less precise than SSI
    np.testing.assert_allclose(est.zeta[i], truth.zeta, rtol=0.4)
    assert np.all(np.abs(est.zeta[i] - truth.zeta) < 4 * est.zeta_std[i])   # the std means something
    assert all(b["bias_removed_zeta"] is not None for b in est.extras["bells"])
    mac = np.diag(vm.mac(sensors @ truth.shapes, est.shapes[:, i]))
    assert np.all(mac >= 0.99)
    assert len(est.extras["bells"]) == 5 and est.extras["singular_values"]["values"].shape[0] == 6


def test_efdd_removes_the_bias_of_cutting_the_bell():
    # oracle: the exact acceleration bell of an SDOF (f^4 / |fn^2 - f^2 + 2i zeta fn f|^2), cut to the
    # lines the benchmark's 57 Hz, 2 % mode keeps (54.6-66.6 Hz at fs 200, 8192-sample segments).
    # The plain EFDD fit of the cut bell is 8 % low in zeta (the cut smears the correlation function);
    # corrected it must be within 0.1 % (measured 0.01 %) and fn within 1e-5 (measured 8e-7)
    from vibmeasure.identify.oma.fdd import _efdd, _efdd_fit
    fs, nper, fn, z = 200.0, 8192, 57.2667, 0.02
    w = np.hanning(nper + 1)[:-1]
    f = np.fft.rfftfreq(2 * nper, 1 / fs)
    cut = (f >= 54.58) & (f <= 66.55)
    bell = np.where(cut, f ** 4 / ((fn ** 2 - f ** 2) ** 2 + (2 * z * fn * f) ** 2), 0.0)
    plain, _ = _efdd_fit(bell, w, fs, nper)
    assert plain.zeta[0] < 0.95 * z
    est, _, bias = _efdd(bell, w, fs, nper, power=4)
    assert est.zeta[0] == pytest.approx(z, rel=1e-3) and est.fn[0] == pytest.approx(fn, rel=1e-5)
    assert bias[1] == pytest.approx(plain.zeta[0] - est.zeta[0])
    # a bell cut so close that the bias would exceed half of zeta is not corrected, and says so
    narrow = np.where((f >= 54.58) & (f <= 60.55), f ** 4 / ((fn ** 2 - f ** 2) ** 2 + (2 * 0.05 * fn * f) ** 2), 0.0)
    assert _efdd(narrow, w, fs, nper, power=4)[2] is None


def _close_modes_model():
    # M = I, K = Phi diag(w^2) Phi^T with an orthonormal Phi: modes exactly at the chosen frequencies
    fn = np.array([181.7, 184.8, 260.0])
    rng = np.random.default_rng(0)
    Phi, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    K = Phi @ np.diag((2 * np.pi * fn) ** 2) @ Phi.T
    return vm.models.MDOF(np.eye(3), (K + K.T) / 2, modal_zeta=[0.004, 0.005, 0.006])


def test_ssi_separates_close_modes():
    # two modes 1.7 % apart (the spacing of the MPSTD record's peaks): both found, each with its std
    model = _close_modes_model()
    sensors = np.vstack([np.eye(3), [0.5, 0.5, 0.0]])
    rec = vm.synth.ambient(model, fs=1000.0, duration=300.0, outputs=sensors, noise=0.05, seed=4)
    est = vm.oma_ssi(rec, band=(150, 300), max_order=30)
    truth = model.modes()
    assert est.n_modes == 3
    np.testing.assert_allclose(est.fn, truth.fn, rtol=0.002)
    assert np.all(np.isfinite(est.zeta_std)) and np.all(est.zeta_std > 0)
    assert np.all(np.abs(est.zeta - truth.zeta) < 4 * est.zeta_std)
    assert abs(vm.mac(est.shapes[:, [0]], est.shapes[:, [1]])[0, 0]) < 0.5


def test_harmonic_is_not_a_mode():
    # a sinusoid added to an ambient response is refused by both methods (band kurtosis 1.5)
    model, sensors = system()
    rec = vm.synth.ambient(model, fs=200.0, duration=600.0, outputs=sensors, noise=0.05, seed=3)
    t = rec.time
    tone = 3 * np.std(rec.data, axis=1, keepdims=True) * np.sin(2 * np.pi * 30.0 * t)
    rec2 = rec.replace(data=rec.data + tone)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        fdd = vm.oma_fdd(rec2, band=(1, 80))
    assert not np.any(np.abs(fdd.fn - 30.0) < 0.2)
    assert any(abs(p["f"] - 30.0) < 0.1 and "harmonic" in p["reason"] for p in fdd.extras["rejected_peaks"])
    ssi = vm.oma_ssi(rec2, band=(1, 80))
    assert not np.any(np.abs(ssi.fn - 30.0) < 0.2)


def test_real_mpstd_peaks_are_harmonics():
    # ../shared/data/uff/MPSTD: the peaks near 181.7 and 184.8 Hz have band kurtosis 1.5-1.7 on every
    # channel: deterministic (a sinusoid gives 1.5), not modes under random excitation (3); FDD says so.
    # The one peak whose band kurtosis passes (200.0 Hz, 2.46) has a 5-line bell whose damping the
    # record does not determine (relative std 0.35 > 0.3, the limit of every estimator here). No mode
    # is left: FitError, every peak listed with its reason
    rec = vm.read(UFF)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        with pytest.raises(vm.FitError, match="no mode in band=.* that the data supports") as exc:
            vm.oma_fdd(rec, band=(150, 220))
    msg = str(exc.value)
    for f in ("181.738", "184.766"):
        assert f'({f}, "a harmonic, not a mode: kurtosis 1.' in msg
    assert "(200.0, 'damping relative std 0.3" in msg and "> 0.3: the data does not support the mode" in msg
    # SSI fits a pole in the valley between the 181.7 and 182.8 Hz lines (zeta 0.08 %): it is reported,
    # flagged near_harmonic, with the sinusoids beside it (kurtosis 1.5-1.7, 15-22 dB above the pole)
    with pytest.warns(vm.QualityWarning, match="near_harmonic"):
        ssi = vm.oma_ssi(rec, band=(150, 220))
    for k in range(ssi.n_modes):
        if abs(ssi.fn[k] - 182.5) < 1.5:
            assert "near_harmonic" in ssi.mode_flags[k]
            tones = ssi.extras["near_harmonics"][k]
            assert any(abs(t["f_hz"] - 181.7) < 0.2 for t in tones)
            assert all(t["kurtosis"] < 2.2 and t["above_pole_db"] >= 10 for t in tones)


def test_bad_input():
    model, sensors = system()
    rec = vm.synth.ambient(model, fs=200.0, duration=60.0, outputs=sensors, seed=1)
    with pytest.raises(vm.ParameterError, match="at least 2 output channels"):
        vm.oma_ssi(rec.select([0]))
    with pytest.raises(vm.ParameterError, match="band"):
        vm.oma_ssi(rec, band=(10, 150))
    with pytest.raises(vm.ParameterError, match="band"):
        vm.oma_fdd(rec, band=(10, 150))
    with pytest.raises(vm.ParameterError, match=r"minimum duration of 100 s"):   # even the band's top: 100 cycles
        vm.oma_ssi(rec, band=(0.2, 1.0))
    with pytest.raises(vm.ParameterError, match=r"minimum duration of 100 s"):
        vm.oma_fdd(rec, band=(0.2, 1.0))
    with pytest.raises(vm.ParameterError, match="block_rows"):
        vm.oma_ssi(rec, block_rows=2)
    bad = rec.data.copy()
    bad[2, 50] = np.nan
    with pytest.raises(vm.ParameterError, match="NaN"):
        vm.oma_fdd(rec.replace(data=bad), band=(1, 80))
    with pytest.raises(vm.ParameterError, match="MDOF"):
        vm.synth.ambient("not a model", fs=100.0, duration=10.0)
    with pytest.raises(vm.ParameterError, match="min_prominence_db"):
        vm.oma_fdd(rec, band=(2, 80), min_prominence_db="x")
    with pytest.raises(vm.ParameterError, match="mac_bell"):
        vm.oma_fdd(rec, band=(2, 80), mac_bell=1.5)
    with pytest.raises(vm.ParameterError, match="samples"):
        vm.oma_ssi(vm.Record(np.zeros((2, 0)), 100.0))


def test_plots_have_units(chain):
    import matplotlib
    matplotlib.use("Agg")
    from vibmeasure.plot import plot_singular_values, plot_stabilisation
    truth, sensors, rec = chain
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        ax = plot_singular_values(vm.oma_fdd(rec, band=(1, 80))).panels[0]
    assert ax.get_xlabel() == "frequency [Hz]" and "m/s^2" in ax.get_ylabel()
    ax = plot_stabilisation(vm.oma_ssi(rec, band=(1, 80))).panels[0]
    assert ax.get_ylabel() == "model order" and "PSD" in ax.figure.axes[-1].get_ylabel()


def test_cli_oma(tmp_path):
    import io
    import json
    from vibmeasure.cli import main
    model, sensors = system()
    path = tmp_path / "ambient.h5"
    vm.write(path, vm.synth.ambient(model, fs=200.0, duration=600.0, outputs=sensors, seed=5))
    out = io.StringIO()
    png = tmp_path / "stab.png"
    assert main(["oma", str(path), "--band", "1", "80", "--json", "--plot", str(png)], out=out,
                err=io.StringIO()) == 0
    doc = json.loads(out.getvalue())
    assert doc["method"] == "oma_ssi" and len(doc["modes"]) == 5
    assert png.stat().st_size > 10_000
    out = io.StringIO()
    assert main(["oma", str(path), "--method", "fdd", "--band", "1", "80"], out=out, err=io.StringIO()) == 0
    assert "oma_fdd" in out.getvalue()
    out = io.StringIO()
    assert main(["oma", str(path), "--method", "both", "--band", "1", "80", "--json"], out=out, err=io.StringIO()) == 0
    doc = json.loads(out.getvalue())
    assert doc["method"] == "oma_ssi" and len(doc["extras"]["cross_check"]) == len(doc["modes"]) == 5
    assert all(c["other_fn_hz"] is not None and c["zeta_sigma"] < 3 for c in doc["extras"]["cross_check"])
    # a CSV of bare columns carries no unit: --unit gives it (issue 49: every option a real file needs)
    rec = vm.read(path)
    np.savetxt(tmp_path / "bare.csv", np.column_stack([rec.time, rec.data.T]), delimiter=",",
               header=",".join(["time"] + [f"s{i}" for i in range(rec.n_channels)]), comments="")
    out = io.StringIO()
    assert main(["oma", str(tmp_path / "bare.csv"), "--band", "1", "80", "--unit", "g", "--json"], out=out,
                err=io.StringIO()) == 0
    assert json.loads(out.getvalue())["unit"] == "g"


def test_the_duration_rule_is_on_the_modes_and_fdd_has_ssis_defaults():
    """A record of 10 s holds 89 cycles of the 8.89 Hz mode: it is identified and flagged few_cycles (its
    damping rests on fewer than the 100 cycles the rule asks), while the band's lower edge (1 Hz, which
    would ask 100 s) refuses nothing. oma_fdd takes the same defaults as oma_ssi (no band: the whole
    range) and lists what it refused under the one documented key, rejected_modes."""
    model, sensors = system()
    short = vm.synth.ambient(model, fs=200.0, duration=10.0, outputs=sensors, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ssi = vm.oma_ssi(short, band=(1, 80), n_blocks=5)   # 10 s: five jackknife blocks
        fdd = vm.oma_fdd(vm.synth.ambient(model, fs=200.0, duration=60.0, outputs=sensors, seed=1))
    low = int(np.argmin(np.abs(ssi.fn - 8.89)))
    assert abs(ssi.fn[low] - 8.89) < 0.1 and "few_cycles" in ssi.mode_flags[low]
    assert all("few_cycles" not in fl for f, fl in zip(ssi.fn, ssi.mode_flags) if f * 10.0 >= 100)
    assert fdd.n_modes >= 3 and fdd.extras["rejected_modes"] is fdd.extras["rejected_peaks"]
    true = model.modes().fn
    assert (np.min(np.abs(fdd.fn[:, None] - true[None, :]), axis=1) / fdd.fn).max() < 0.01   # each a true mode


def _close_pair_tower(seed):
    from edges import tower   # the edge benchmark's tower (benchmarks/ is on the path, as for `system`)
    return tower(seed)


def test_fdd_reports_close_modes_it_cannot_resolve_and_the_cross_check_names_them():
    """Two modes 0.06 Hz apart, 2 half-power bandwidths, are closer than FDD's default resolution
    (0.0195 Hz lines, a Hann main lobe of 0.08 Hz). FDD must not drop them in silence: its peak there
    stands 30 dB over the noise while its singular vector turns, which is close modes, not noise, so
    the estimate carries ``unresolved_close_modes`` with a QualityWarning naming the frequency (before:
    rejected as 'not coherent', unflagged). SSI separates the pair (within 0.5 % of the truth: 3 of its
    stds); the cross-check marks the two SSI modes FDD does not confirm, and confirms the others."""
    rec = _close_pair_tower(0)
    with pytest.warns(vm.QualityWarning, match="close modes near 1.2"):
        fdd = vm.oma_fdd(rec, band=(0.8, 5))
    assert "unresolved_close_modes" in fdd.flags
    assert all(1.2 < f < 1.3 for f in fdd.extras["unresolved_close_modes_hz"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        ssi = vm.oma_ssi(rec, band=(0.8, 5))
        both = vm.oma_cross_check(ssi, fdd)
    assert ssi.n_modes == 4
    np.testing.assert_allclose(ssi.fn[:2], [1.23, 1.29], rtol=0.005)
    assert [("not_confirmed" in fl) for fl in both.mode_flags] == [True, True, False, False]
    assert all("methods_disagree" not in fl for fl in both.mode_flags)


def test_cross_check_flags_disagreement_beyond_three_stds():
    """The rule on two estimates with known numbers: zeta 0.020 +- 0.001 against 0.030 +- 0.001 is 7.1
    combined stds apart (flagged); 0.022 +- 0.001 is 1.4 (not); a mode 5 % away is another mode."""
    a = vm.ModalEstimate(fn=[10.0, 30.0], zeta=[0.02, 0.02], fn_std=[0.01, 0.01], zeta_std=[0.001, 0.001],
                         method="oma_ssi")
    b = vm.ModalEstimate(fn=[10.005, 31.5], zeta=[0.03, 0.022], fn_std=[0.01, 0.01], zeta_std=[0.001, 0.001],
                         method="oma_fdd")
    with pytest.warns(vm.QualityWarning, match="disagree"):
        c = vm.oma_cross_check(a, b)
    assert c.mode_flags == (("methods_disagree",), ("not_confirmed",))
    assert c.extras["cross_check"][0]["zeta_sigma"] == pytest.approx(0.01 / np.hypot(0.001, 0.001))
    b2 = vm.ModalEstimate(fn=[10.005, 30.01], zeta=[0.022, 0.021], fn_std=[0.01, 0.01], zeta_std=[0.001, 0.001])
    assert vm.oma_cross_check(a, b2).mode_flags == ((), ())
    with pytest.raises(vm.ParameterError, match="other must be a ModalEstimate"):
        vm.oma_cross_check(a, [10.0])


def test_fdd_keeps_the_guides_chain_modes_with_a_stable_jackknife():
    """The guide's 3-DOF chain (seed 1): FDD refused its 7.08 Hz mode with a relative zeta std of 0.38,
    because one jackknife replicate of eight chose its decay length again (261 samples against ~420)
    and tripled the spread. With the full data's decay length in every replicate the mode is kept
    (std 0.0046, rel 0.27), on every seed 1-5 within 3 stds of zeta 0.02, and SSI confirms every mode."""
    chain = vm.models.MDOF(np.eye(3), np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]),
                           modal_zeta=[0.02] * 3)
    truth = chain.modes().fn
    for seed in range(1, 6):
        amb = vm.synth.ambient(chain, fs=100.0, duration=300.0, noise=0.05, seed=seed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", vm.QualityWarning)
            fdd = vm.oma_fdd(amb)
            both = vm.oma_cross_check(vm.oma_ssi(amb), fdd)
        assert fdd.n_modes == 3, seed
        np.testing.assert_allclose(fdd.fn, truth, rtol=0.005)
        assert np.all(np.abs(fdd.zeta - 0.02) < 3 * fdd.zeta_std), seed
        assert all(fl == () or "close_modes" not in fl and "not_confirmed" not in fl for fl in both.mode_flags)


def test_a_jackknife_replicate_is_the_full_fits_point_estimate():
    """EFDD's replicates skip the ring-down's stds and classification (replicate_decay), not its fit:
    a decay with an offset and a weaker second component, started from the poles of another noise
    realisation's fit (about a std away, as a replicate starts from the full data's), gets the fn and
    zeta linear_decay gets from the same start, to round-off (the same preparation, trim and
    Levenberg-Marquardt rule: two steps alone leave zeta 1e-5 off here); a decay that grows is no
    replicate (None)."""
    from vibmeasure.identify._rd_linear import linear_decay, replicate_decay
    fs = 200.0
    t = np.arange(3000) / fs
    x = (np.exp(-0.015 * 2 * np.pi * 7.0 * t) * np.cos(2 * np.pi * 7.0 * t + 0.3)
         + 0.2 * np.exp(-0.02 * 2 * np.pi * 19.0 * t) * np.sin(2 * np.pi * 19.0 * t) + 0.01)
    noisy = [vm.Record.from_array(x + 0.05 * np.random.default_rng(s).normal(size=t.size), fs=fs) for s in range(4)]
    poles = linear_decay(noisy[0], 1).extras["fitted_poles"]
    for rep in noisy[1:]:
        ref = linear_decay(rep, 1, poles=poles)
        assert replicate_decay(rep, poles, 7.0) == pytest.approx((ref.fn[0], ref.zeta[0]), rel=1e-12)
    grow = vm.Record.from_array(np.exp(0.05 * t) * np.cos(2 * np.pi * 7.0 * t), fs=fs)
    assert replicate_decay(grow, [complex(0.05, 2 * np.pi * 7.0)], 7.0) is None


def test_fdd_refuses_an_nperseg_too_long_to_average():
    rec = _close_pair_tower(1)
    with pytest.raises(vm.ParameterError, match="at least 7 segments"):
        vm.oma_fdd(rec, nperseg=4096)


def test_ssi_narrow_low_band_decimates_no_further_than_the_record_allows():
    """band=(1, 2) on a 600 s record at 20 Hz decimated it by 4 to 3000 samples, under the 4800 its
    covariance blocks need, and was refused with a demand for a 960 s record. The decimation stops
    where the blocks keep their samples: the three modes in the band are found, with the same damping
    as in a wider band (within 2 combined stds), and without a band the same modes and dampings."""
    rec = _close_pair_tower(0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        narrow = vm.oma_ssi(rec, band=(1, 2))
        wide = vm.oma_ssi(rec, band=(0.8, 5))
        whole = vm.oma_ssi(rec)
    assert narrow.n_modes == 3
    np.testing.assert_allclose(narrow.fn, wide.fn[:3], rtol=0.005)
    assert np.all(np.abs(narrow.zeta - wide.zeta[:3]) < 2 * np.hypot(narrow.zeta_std, wide.zeta_std[:3]))
    np.testing.assert_allclose(whole.zeta[:4], wide.zeta, atol=1e-12)


def test_the_psd_decomposition_equals_the_svd_of_a_cross_spectral_matrix():
    # oracle: numpy's general SVD; for a Hermitian positive semi-definite matrix the eigen-decomposition
    # gives the same singular values (descending) and the same vectors up to a phase (|v_eig^H u_svd| = 1
    # where the singular values are distinct); tolerance: round-off of 5 x 5 double-precision LAPACK
    from vibmeasure.identify.oma.fdd import _psd_svd
    rng = np.random.default_rng(4)
    A = rng.standard_normal((64, 5, 12)) + 1j * rng.standard_normal((64, 5, 12))
    G = A @ A.conj().transpose(0, 2, 1)
    U, S = _psd_svd(G)
    U0, S0, _ = np.linalg.svd(G)
    np.testing.assert_allclose(S, S0, rtol=1e-12)
    np.testing.assert_allclose(np.abs(np.einsum("fik,fik->fk", U.conj(), U0)), 1.0, atol=1e-9)


def test_the_bias_iteration_stops_on_the_contraction_of_its_steps():
    # oracle: a fixed-point iteration contracting by rho has at most rho / (1 - rho) x the last step to go
    from vibmeasure.identify.oma.fdd import _remaining
    assert _remaining(0.01, 0.1) == pytest.approx(0.1 / 0.9 * 0.01, rel=1e-12)
    assert _remaining(-0.01, 0.1) == pytest.approx(0.1 / 0.9 * 0.01, rel=1e-12)   # alternating steps alike
    assert _remaining(0.2, 0.1) == np.inf and _remaining(0.01, 0.0) == np.inf      # no contraction: no claim
