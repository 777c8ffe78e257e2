"""Draw every vibmeasure plot on synthetic data with known answers, for docs/gallery.md.

    python docs/make_gallery.py               (writes docs/gallery/*.png, about 15 s)
    python docs/make_gallery.py --out DIR     (somewhere else; the tests do this)

Each picture is the figure a user gets from the same call in Python; nothing is drawn here that
plot.py does not draw.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

import vibmeasure as vm
from vibmeasure import plot

# file name -> one-line caption (the gallery page lists them in this order)
PICTURES = {
    "ringdown.png": "vm.ringdown of a two-mode decay with an impact transient, band 10-30 Hz: band-passed record, "
                    "fit, envelope and residual (plot_ringdown)",
    "backbone.png": "fn and zeta versus amplitude of a softening decay with friction, and the fitted nonlinear "
                    "model (plot_backbone)",
    "spectrum.png": "amplitude spectrum with ten picked peaks, labels kept clear of each other (plot_spectrum)",
    "psd_db.png": "PSD in dB re 1 g^2/Hz (plot_spectrum db=True)",
    "envelope.png": "squared-envelope spectrum of an outer-race defect; the axis ends with the content "
                    "(plot_spectrum)",
    "frf.png": "hammer-test FRF: Bode plot with the synthesis from fit_modes (modes and residual terms) and the "
               "coherence (plot_frf)",
    "nyquist.png": "Nyquist plot around the first mode (plot_nyquist)",
    "stabilisation.png": "stabilisation diagram of fit_modes over the fitted band (plot_stabilisation)",
    "mac.png": "MAC between identified and true mode shapes (plot_mac)",
    "diagnosis.png": "bearing diagnosis: squared-envelope spectrum with the BPFO comb, kurtogram, spectrum with "
                     "shaft orders, ISO 10816-3 gauge (plot_diagnosis)",
    "comparison.png": "measured against model: fn deviation per mode with one-std error bars (plot_comparison)",
    "oma_stabilisation.png": "output-only modal analysis (SSI-cov): stabilisation diagram over the mean PSD "
                             "(plot_stabilisation)",
    "singular_values.png": "frequency-domain decomposition: singular values with the EFDD bells "
                           "(plot_singular_values)",
    "srs.png": "shock response spectrum of a 50 g, 2 ms half-sine, tripartite grid (plot_srs)",
    "transmissibility.png": "measured transmissibility of a base-excited mount against its model, isolation "
                            "region shaded (plot_transmissibility)",
    "trend.png": "a growing bearing defect in a fleet store: bearing evidence over 20 weeks with baseline and "
                 "limits (plot_trend)",
}


def draw(out: Path) -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    out.mkdir(parents=True, exist_ok=True)
    written = []

    def save(fig, name):
        plot.save_figure(fig, out / name, dpi=80)
        written.append(out / name)

    # ring-down, backbone
    two = vm.synth.free_decay(fn=[18.0, 150.0], zeta=[0.01, 0.05], amplitude=[1.0, 20.0], fs=1000.0, duration=6.0,
                              snr_db=50, seed=4, quantity="displacement", unit="mm")
    save(plot.plot_ringdown(two, vm.ringdown(two, band=(10.0, 30.0))), "ringdown.png")
    t = np.arange(60000) / 2000.0
    amp = 1.0 * np.exp(-0.25 * t) - 0.01 * t      # friction-like decay of the envelope
    amp = np.clip(amp, 0, None)
    inst = 2 * np.pi * np.cumsum(12.0 * np.sqrt(1 - 0.06 * amp ** 2)) / 2000.0   # softening (Duffing) backbone
    x = amp * np.cos(inst) + 1e-3 * np.random.default_rng(2).normal(size=t.size)
    nl = vm.Record.from_array(x, fs=2000.0, quantity="displacement", unit="mm")
    save(plot.plot_backbone(vm.ringdown(nl)), "backbone.png")

    # spectra
    fs = 2048.0
    tt = np.arange(2 ** 15) / fs
    tones = [(100, 1.0), (101.5, 0.9), (103, 0.8), (104.5, 0.85), (106, 0.7), (300, 0.5), (302, 0.45), (304, 0.4),
             (500, 0.3), (700, 0.2)]
    sig = sum(a * np.sin(2 * np.pi * f * tt) for f, a in tones) + 0.01 * np.random.default_rng(0).normal(size=tt.size)
    rec = vm.Record.from_array(sig, fs=fs, quantity="acceleration", unit="m/s^2")
    spec = vm.amplitude_spectrum(rec)
    save(plot.plot_spectrum(spec, peaks=vm.pick_peaks(spec, n=10)), "spectrum.png")
    machine = vm.synth.machine(fault="bearing_outer_race", rpm=1500.0, fs=12800.0, duration=2.0, seed=1)
    save(plot.plot_spectrum(vm.psd(machine), db=True), "psd_db.png")
    env = vm.envelope_spectrum(machine, band=(2000.0, 3200.0))
    save(plot.plot_spectrum(env, peaks=vm.pick_peaks(env, n=6)), "envelope.png")

    # hammer test, modes
    fn, zeta = [21.3, 57.9, 110.4], [0.010, 0.020, 0.015]
    shapes = [[0.5, 0.6, 0.4], [0.7, -0.2, -0.6], [0.3, -0.7, 0.6]]
    hammer = vm.synth.hammer_test(fn=fn, zeta=zeta, shapes=shapes, fs=1024.0, hits=(0.2, 4.2, 8.2), noise=3e-3,
                                  seed=1)
    frf = vm.impact_frf(hammer, input="hammer")
    est = vm.fit_modes(frf, band=(5, 150))
    save(plot.plot_frf(frf, est=est, output="a1"), "frf.png")
    save(plot.plot_nyquist(frf, band=(18, 25)), "nyquist.png")
    save(plot.plot_stabilisation(est, frf=frf), "stabilisation.png")
    save(plot.plot_mac(vm.mac(est.shapes, np.asarray(shapes)), labels=[f"{f:.1f}" for f in est.fn]),
         "mac.png")

    # diagnosis, comparison
    diag = vm.diagnose(machine, rpm=1500.0, bearing="6205-2RS")
    save(plot.plot_diagnosis(machine, diag), "diagnosis.png")
    model = vm.models.MDOF(np.diag([1.0, 1.0, 1.0]),
                           np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]), modal_zeta=[0.02] * 3)
    softer = vm.models.MDOF(np.diag([1.0, 1.0, 1.0]),
                            0.95 * np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]),
                            modal_zeta=[0.02] * 3)
    amb = vm.synth.ambient(softer, fs=100.0, duration=300.0, noise=0.05, seed=1)
    oma = vm.oma_ssi(amb, band=(1, 40))
    save(plot.plot_comparison(vm.compare(oma, model.modes())), "comparison.png")
    save(plot.plot_stabilisation(oma), "oma_stabilisation.png")
    save(plot.plot_singular_values(vm.oma_fdd(amb, band=(1, 40))), "singular_values.png")

    # shock, isolation
    sfs = 20000.0
    st = np.arange(int(0.05 * sfs)) / sfs
    pulse = np.where(st < 0.002, 50.0 * np.sin(np.pi * st / 0.002), 0.0)
    shock = vm.Record.from_array(np.r_[np.zeros(100), pulse], fs=sfs, quantity="acceleration", unit="g")
    save(plot.plot_srs(vm.srs(shock, Q=10, output="pseudo_velocity")), "srs.png")
    mount = vm.models.SDOF(m=1.0, k=(2 * np.pi * 10.0) ** 2, zeta=0.05)
    be = vm.synth.base_excited(mount, fs=500.0, duration=120.0, seed=1)
    save(plot.plot_transmissibility(vm.transmissibility(be, base=be.names[0], top=be.names[1], model=mount)),
         "transmissibility.png")

    # fleet trend
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        vm.synth.fleet(Path(d) / "fleet", n_measurements=20, fault_onset=10)
        store = Path(d) / "plant.db"
        vm.batch(task="diagnose", store=store, manifest=Path(d) / "fleet" / "machines.csv")
        save(plot.plot_trend(store, asset="pump-3", point="DE", metric="bearing_evidence", baseline_count=6),
             "trend.png")
    return written


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "gallery"), help="folder for the pictures")
    args = ap.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        paths = draw(Path(args.out))
    print(f"wrote {len(paths)} pictures to {args.out}")


if __name__ == "__main__":
    main()
