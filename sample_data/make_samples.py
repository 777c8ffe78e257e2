"""Regenerate the bundled sample files with vibmeasure's own synthesiser.

    python sample_data/make_samples.py

ringdown_beam.csv   one mode, 23.7 Hz, zeta 0.012, acceleration in m/s^2, 40 dB SNR, small DC offset
ringdown_3modes.h5  three modes (21.3, 57.9, 110.4 Hz; zeta 0.010, 0.020, 0.015), displacement, 40 dB
coulomb_decay.csv   dry-friction decay, 4.2 Hz, amplitude falls 0.4 mm per cycle
"""

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


if __name__ == "__main__":
    main()
