"""Regenerate the bundled sample files with vibmeasure's own synthesiser.

    python sample_data/make_samples.py

ringdown_beam.csv   one mode, 23.7 Hz, zeta 0.012, acceleration in m/s^2, 40 dB SNR, small DC offset
ringdown_3modes.h5  three modes (21.3, 57.9, 110.4 Hz; zeta 0.010, 0.020, 0.015), displacement, 40 dB
coulomb_decay.csv   dry-friction decay, 4.2 Hz, amplitude falls 0.4 mm per cycle
machine.h5          stationary machine vibration in g at 5 kHz, 4 s: 1X = 29.95 Hz with 2X and 3X,
                    a 1200 Hz mesh-like tone with +-1X sidebands, and white noise
"""
import numpy as np

from pathlib import Path

import vibmeasure as vm

HERE = Path(__file__).resolve().parent


def main():
    beam = vm.synth.free_decay(fn=23.7, zeta=0.012, amplitude=2e-3, phase=0.4, fs=1000.0, duration=6.0,
                               quantity="acceleration", snr_db=40, dc_offset=0.05, seed=20261121, name="acc")
    vm.write(HERE / "ringdown_beam.csv", beam)
    three = vm.synth.free_decay(fn=[21.3, 57.9, 110.4], zeta=[0.010, 0.020, 0.015], amplitude=[1e-3, 6e-4, 4e-4],
                                phase=[0.0, 1.0, 2.0], fs=2000.0, duration=5.0, snr_db=40, seed=7, name="disp")
    vm.write(HERE / "ringdown_3modes.h5", three)
    dry = vm.synth.coulomb_decay(fn=4.2, friction_decay=4e-4, amplitude=5e-3, fs=500.0, duration=6.0,
                                 snr_db=50, seed=3, name="disp")
    vm.write(HERE / "coulomb_decay.csv", dry)
    fs, n, f1 = 5000.0, 20000, 29.95
    t = np.arange(n) / fs
    rng = np.random.default_rng(11)
    x = 0.08 * np.sin(2 * np.pi * f1 * t) + 0.03 * np.sin(2 * np.pi * 2 * f1 * t + 1) \
        + 0.015 * np.sin(2 * np.pi * 3 * f1 * t + 2) \
        + 0.05 * (1 + 0.4 * np.cos(2 * np.pi * f1 * t)) * np.sin(2 * np.pi * 1200.0 * t) + rng.normal(0, 0.01, n)
    machine = vm.Record.from_array(x, fs=fs, quantity="acceleration", unit="g", name="acc_de",
                                   meta={"rpm": 60 * f1})
    vm.write(HERE / "machine.h5", machine)


if __name__ == "__main__":
    main()
