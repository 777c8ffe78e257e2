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
    assert plot_nyquist(fr, band=(18, 25)).panels[0].get_lines()
    ax = plot_stabilisation(est, frf=fr).panels[0]
    assert any(l.get_label() == "stable f" for l in ax.get_lines())
    assert plot_mac(vm.mac(est.shapes), labels=["1", "2"]).panels[0].images
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
    ny = P.plot_nyquist(frf).panels[0]
    labels += [ny.get_xlabel(), ny.get_ylabel()]
    st = P.plot_stabilisation(est_m, frf=frf).panels[0]
    labels += [st.get_xlabel()]
    assert st.get_xlim()[0] >= 2 - 1e-9 and st.get_xlim()[1] <= 45 + 1e-9  # the fitted band, not 0..fs/2
    mac = P.plot_mac(vm.mac(np.eye(2))).panels[0]
    assert mac.get_xlabel() and mac.get_ylabel()
    mrec = vm.synth.machine(fault="bearing_outer_race", rpm=1500.0, fs=12800.0, duration=2.0, seed=1)
    diag = vm.diagnose(mrec, rpm=1500.0, bearing="6205-2RS")
    axes = P.plot_diagnosis(mrec, diag)
    labels += [a.get_ylabel() for a in axes[:3]] + [axes[0].get_xlabel(), axes[1].get_xlabel()]
    for lab in labels:
        assert lab and ("[" in lab and "]" in lab), f"axis label without a unit: {lab!r}"
    assert "unknown" not in labels[0]
    plt.close("all")


def _overlaps(a, b):
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def test_peak_labels_never_print_on_top_of_each_other():
    # ten tones, five of them 1.5 Hz apart: labelled naively their numbers overprint; every label
    # drawn must stand clear of every other, and the strongest peak is always labelled
    import matplotlib.pyplot as plt
    from vibmeasure.plot import plot_spectrum
    fs = 2048.0
    t = np.arange(2 ** 15) / fs
    tones = [(100, 1.0), (101.5, 0.9), (103, 0.8), (104.5, 0.85), (106, 0.7), (300, 0.5), (302, 0.45),
             (304, 0.4), (500, 0.3), (700, 0.2)]
    x = sum(a * np.sin(2 * np.pi * f * t) for f, a in tones)
    spec = vm.amplitude_spectrum(vm.Record.from_array(x, fs=fs, quantity="acceleration", unit="m/s^2"))
    peaks = vm.pick_peaks(spec, n=10)
    ax = plot_spectrum(spec, peaks=peaks).panels[0]
    ax.figure.canvas.draw()
    boxes = [a.get_window_extent() for a in ax.texts]
    assert len(boxes) >= 6  # most are labelled
    for i in range(len(boxes)):
        for j in range(i):
            assert not _overlaps(boxes[i], boxes[j]), (ax.texts[i].get_text(), ax.texts[j].get_text())
    assert "100" in {t.get_text() for t in ax.texts}
    plt.close("all")


def test_envelope_spectrum_axis_ends_where_its_content_ends_and_db_is_labelled():
    # the squared envelope of a 1.2 kHz wide band holds nothing above 1.2 kHz: the axis must not run
    # to fs/2 = 6.4 kHz (reason: the fault lines would be squeezed into the first fifth of the plot)
    import matplotlib.pyplot as plt
    from vibmeasure.plot import plot_spectrum
    rec = vm.synth.machine(fault="bearing_outer_race", rpm=1500.0, fs=12800.0, duration=2.0, seed=1)
    env = vm.envelope_spectrum(rec, band=(2000.0, 3200.0))
    ax = plot_spectrum(env).panels[0]
    assert 1100.0 < ax.get_xlim()[1] < 2200.0, ax.get_xlim()
    ax = plot_spectrum(vm.psd(rec), db=True).panels[0]
    assert "dB re 1" in ax.get_ylabel() and ax.get_yscale() == "linear"
    lo, hi = ax.get_ylim()
    assert hi - lo <= 110  # a readable dynamic range, not 300 dB down to the round-off
    with pytest.raises(vm.ParameterError, match="fmax"):
        plot_spectrum(env, fmax=-1.0)
    plt.close("all")


def test_ringdown_plot_shows_the_band_passed_record_when_the_fit_had_a_band():
    # an impact transient at 150 Hz over a 12 Hz decay: with band=(5, 30) the fit reports the 12 Hz
    # mode, and the picture must show the band's signal so the fit can be seen on the data
    import matplotlib.pyplot as plt
    rec = vm.synth.free_decay(fn=[12.0, 150.0], zeta=[0.01, 0.05], amplitude=[1.0, 20.0], fs=1000.0,
                              duration=6.0, snr_db=50, seed=4)
    est = vm.ringdown(rec, band=(5.0, 30.0))
    ax, axr = plot_ringdown(rec, est)
    data = ax.get_lines()[0]
    assert "band-passed 5-30 Hz" in data.get_label()
    late = data.get_xdata() > 0.3  # after the filter's own start-up at the record's abrupt first sample
    assert np.max(np.abs(data.get_ydata()[late])) < 1.2  # the 20-unit 150 Hz transient is filtered out
    res = axr.get_lines()[0]
    assert np.std(res.get_ydata()[res.get_xdata() > 1.0]) < 0.02  # the fit lies on the band's data (filter settled)
    assert ax.get_ylim()[1] < 2.0  # framed on the decay, not on the filter's start-up
    plt.close("all")


def test_every_plot_shares_the_one_style():
    # one style module: constrained layout (no clipped labels) and the same fonts in every figure
    import matplotlib.pyplot as plt
    from matplotlib.layout_engine import ConstrainedLayoutEngine
    from vibmeasure import plot as P
    from vibmeasure.plotstyle import STYLE
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, snr_db=40, seed=2,
                              quantity="acceleration", unit="m/s^2")
    freq = np.arange(0, 50.0625, 0.0625)
    frf = vm.synth.modal_frf(freq, fn=[10.0, 30.0], zeta=[0.02, 0.02], shapes=[[1.0, 0.7]])
    est_m = vm.fit_modes(frf, band=(2, 45))
    figs = [P.plot_ringdown(rec, vm.ringdown(rec)), P.plot_spectrum(vm.psd(rec)), P.plot_frf(frf, est=est_m),
            P.plot_nyquist(frf), P.plot_stabilisation(est_m, frf=frf), P.plot_mac(vm.mac(np.eye(2)))]
    for fig in figs:
        assert isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)
        ax = fig.axes[0]
        assert ax.xaxis.label.get_fontsize() == STYLE["axes.labelsize"]
    plt.close("all")


def test_the_kurtogram_marks_where_the_measured_band_ends():
    # an outer-race machine resampled 12.8 -> 51.2 kHz: the kurtogram panel draws a dashed line at the
    # measured band's edge (about 7 kHz, where the resampling filter has cut 25 dB) and says so; the
    # record as sampled has content to Nyquist and no such line
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.signal import resample_poly
    from vibmeasure import plot as P
    rec = vm.synth.machine(fault="bearing_outer_race", rpm=1500.0, fs=12800.0, duration=2.0, seed=1)
    up = vm.Record.from_array(resample_poly(rec.data[0], 4, 1, window=("kaiser", 10.0)), fs=51200.0,
                              names=["acc"], unit="g")
    for r, edged in ((rec, False), (up, True)):
        d = vm.diagnose(r, rpm=1500.0, bearing="6205-2RS")
        ax_k = P.plot_diagnosis(r, d)[3]
        top = d.extras["measured_top_hz"]["acc"]
        dashed = [ln for ln in ax_k.get_lines() if ln.get_linestyle() == "--"]
        assert ("measured band ends at" in ax_k.get_title()) == edged and len(dashed) == int(edged)
        if edged:
            assert 6400.0 < top < 8000.0 and dashed[0].get_xdata()[0] == pytest.approx(top)
    plt.close("all")


@pytest.mark.parametrize("name", [r"$\foo$", "$" + "{" * 400 + "x" + "}" * 400 + "$"])
def test_names_are_text_not_math(tmp_path, name):
    """Issue 48: a channel name with math markup is printed as written; mathtext would refuse the first
    and recurse past Python's limit on the second."""
    import matplotlib.pyplot as plt
    rec = vm.Record(np.sin(np.arange(4096) / 7.0)[None], 1000.0, channels=[vm.Channel(name, "acceleration", "m/s^2")])
    ax = vm.plot.plot_spectrum(vm.amplitude_spectrum(rec)).panels[0]
    ax.figure.savefig(tmp_path / "s.png")
    texts = [t.get_text() for t in ax.figure.findobj(lambda o: hasattr(o, "get_text"))]
    assert any(name in t for t in texts)
    plt.close(ax.figure)


def test_every_plot_function_returns_its_figure_with_the_panels_in_the_documented_order(tmp_path):
    # one return type for every picture (issue 49): the Figure, its axes in fig.panels. A figure the
    # function made unpacks into its panels (scripts written for the axes-returning 0.1 keep working);
    # on axes the caller gives, the caller's own figure comes back
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure
    from vibmeasure import plot as P
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, snr_db=40, seed=2)
    fig = P.plot_ringdown(rec, vm.ringdown(rec))
    assert isinstance(fig, Figure) and len(fig.panels) == 2 and set(fig.panels) <= set(fig.axes)
    ax, axr = fig
    assert fig[1] is axr and axr.get_xlabel() == "time [s]"
    spec = vm.psd(rec)
    fig = P.plot_spectrum(spec)
    assert isinstance(fig, Figure) and fig.panels == (fig.axes[0],)
    with pytest.raises(AttributeError, match=r"fig\.panels"):   # an Axes method on the Figure says where the axes are
        fig.set_xlim(0, 10)
    own, mine = plt.subplots()
    assert P.plot_spectrum(spec, ax=mine) is own and own.panels == (mine,)
    P.save_figure(fig, tmp_path / "s.png")       # a figure that unpacks is still saved like any other
    assert (tmp_path / "s.png").stat().st_size > 1000
    plt.close("all")
