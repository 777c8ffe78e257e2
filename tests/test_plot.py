import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import vibmeasure as vm  # noqa: E402
from vibmeasure.plot import decay_model, plot_ringdown  # noqa: E402


def test_decay_model_reproduces_a_noise_free_fit():
    rec = vm.synth.free_decay(fn=[10.37, 31.1], zeta=[0.01, 0.02], amplitude=[1.0, 0.5], phase=[0.2, 1.0],
                              fs=1000.0, duration=4.0)
    est = vm.ringdown(rec)
    # the fitted decay is the record (noise-free): round-off only
    np.testing.assert_allclose(decay_model(est, rec.time), rec.data[0], atol=1e-9)


def test_plot_ringdown_draws_fit_and_residual(capsys):
    rec = vm.synth.free_decay(fn=10.37, zeta=0.02, fs=1000.0, duration=5.0, snr_db=40, seed=1)
    ax, axr = plot_ringdown(rec, vm.ringdown(rec))
    labels = [l.get_label() for l in ax.get_lines()]
    assert "fitted decay" in labels and "envelope" in labels
    assert axr.get_visible() and len(axr.get_lines()) == 1
    assert "10.37" in ax.get_title()
    assert capsys.readouterr().out == ""  # the library never prints
    import matplotlib.pyplot as plt
    plt.close("all")


def test_plot_rejects_wrong_objects():
    rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=1000.0, duration=2.0)
    with pytest.raises(vm.ParameterError, match="est must be"):
        plot_ringdown(rec, "estimate")


def test_frf_plots_draw(tmp_path):
    import matplotlib.pyplot as plt
    from vibmeasure.plot import plot_frf, plot_mac, plot_nyquist, plot_stabilisation
    fr = vm.synth.modal_frf(np.arange(0, 150.25, 0.25), fn=[21.3, 57.9], zeta=[0.01, 0.02],
                            shapes=[[0.5, 0.6], [0.7, -0.2]])
    est = vm.fit_modes(fr, band=(1, 150))
    am, ap, ac = plot_frf(fr, est=est)
    assert len(am.get_lines()) >= 2  # measured and synthesised
    assert plot_nyquist(fr, band=(18, 25)).get_lines()
    ax = plot_stabilisation(est, frf=fr)
    assert any(l.get_label() == "stable f" for l in ax.get_lines())
    assert plot_mac(vm.mac(est.shapes), labels=["1", "2"]).images
    plt.close("all")
    with pytest.raises(vm.ParameterError, match="vm.fit_modes"):
        plot_stabilisation(vm.ringdown(vm.synth.free_decay(fn=10.0, zeta=0.02, fs=1000.0, duration=2.0)))


def test_every_plot_labels_its_axes_with_quantity_and_unit():
    # every data axis says what it shows and in which unit ("[...]"), so a picture can be handed over
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from vibmeasure import plot as P
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, snr_db=40, seed=2,
                              quantity="acceleration", unit="m/s^2")
    est = vm.ringdown(rec)
    ax, axr = P.plot_ringdown(rec, est)
    labels = [ax.get_ylabel(), axr.get_ylabel(), axr.get_xlabel()]
    freq = np.arange(0, 50.0625, 0.0625)
    frf = vm.synth.modal_frf(freq, fn=[10.0, 30.0], zeta=[0.02, 0.02], shapes=[[1.0, 0.7]])
    est_m = vm.fit_modes(frf, band=(2, 45))
    am, ap, ac = P.plot_frf(frf, est=est_m)
    labels += [am.get_ylabel(), ap.get_ylabel(), ac.get_xlabel()]
    ny = P.plot_nyquist(frf)
    labels += [ny.get_xlabel(), ny.get_ylabel()]
    st = P.plot_stabilisation(est_m, frf=frf)
    labels += [st.get_xlabel()]
    assert st.get_xlim()[0] >= 2 - 1e-9 and st.get_xlim()[1] <= 45 + 1e-9  # the fitted band, not 0..fs/2
    mac = P.plot_mac(vm.mac(np.eye(2)))
    assert mac.get_xlabel() and mac.get_ylabel()
    mrec = vm.synth.machine(fault="bearing_outer_race", rpm=1500.0, fs=12800.0, duration=2.0, seed=1)
    diag = vm.diagnose(mrec, rpm=1500.0, bearing="6205-2RS")
    axes = P.plot_diagnosis(mrec, diag)
    labels += [a.get_ylabel() for a in axes[:3]] + [axes[0].get_xlabel(), axes[1].get_xlabel()]
    for lab in labels:
        assert lab and ("[" in lab and "]" in lab), f"axis label without a unit: {lab!r}"
    assert "unknown" not in labels[0]
    plt.close("all")
