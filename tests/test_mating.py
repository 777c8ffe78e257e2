"""The mating gear's teeth measured from the mesh's sidebands where a gear is declared without its ratio
(``diagnosis.mating``). Oracle: synth.machine's truth, the two gears' tooth counts."""

import warnings

import numpy as np
import pytest
from scipy import fft

import vibmeasure as vm
from vibmeasure.monitor.diagnosis import mating, pipeline


def _gearbox(rpm, z1, z2, error, snr, seed, fault="none"):
    kw = dict(mesh=1.0) if fault == "none" else {}
    rec = vm.synth.machine(rpm=rpm, gear_teeth=z1, mating_teeth=z2, fs=12000.0, duration=6.0, fault=fault,
                           tooth_error=error, snr_db=snr, seed=seed, **kw)
    return vm.Record.from_array(rec.data[0], fs=12000.0, names=["acc"], unit="g")


def _spectrum(x):
    w = np.hanning(x.size)
    return fft.rfftfreq(x.size, 1 / 12000.0), np.abs(fft.rfft((x - x.mean()) * w)) * 2 / w.sum()


@pytest.mark.parametrize("case", [(1800, 32, 71, 0.05, 10, 0), (1200, 19, 61, 0.2, 10, 2), (2400, 23, 67, 0.02, 10, 0),
                                  (1800, 61, 19, 0.05, 10, 0), (3600, 40, 83, 0.1, 30, 1), (1500, 25, 47, 0.1, 30, 1)])
def test_the_mating_gear_s_teeth_are_measured(case):
    """Six pairs (the measured shaft's gear 19-61 teeth, the mating one 19-83), 2-20 % tooth errors, 10 and
    30 dB: the count found is the mating gear's (46 of 48 records of benchmarks/gearbox.py's pairs when
    written, none wrong)."""
    rpm, z1, z2, error, snr, seed = case
    f, A = _spectrum(_gearbox(rpm, z1, z2, error, snr, seed).data[0])
    assert mating.mating_teeth(f, A, z1 * rpm / 60, z1) == z2


def test_no_mesh_measures_no_mating_gear():
    """A machine without a gear (synth.machine's healthy one): no count holds the places: None."""
    rec = vm.synth.machine(fault="none", fs=12000.0, duration=6.0, snr_db=10, seed=0)
    f, A = _spectrum(rec.data[0])
    assert mating.mating_teeth(f, A, 32 * rec.meta["rpm"] / 60, 32) is None


def test_a_rough_gearbox_s_mating_orders_are_not_an_outer_race(monkeypatch):
    """A healthy 32/71 gearbox at 1800 rpm with rough gears (20 % tooth errors, 10 dB, seed 2) declared
    with its pinion's teeth only: the wheel's orders 8, 16, 24, 32 stand 0.6 % from BPFO, and an outer
    race was called at 1.00. With the wheel's 71 teeth measured its shaft's lines are set apart: no
    bearing call, the reason says so; with the measurement off (MATING_HITS out of reach), the call
    comes back."""
    x = _gearbox(1800, 32, 71, 0.2, 10, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        d = vm.diagnose(x, rpm=1800, bearing="6205-2RS", gear=32)
        assert d.speed["mating_teeth"] == 71 and "mating gear's 71 teeth measured" in d.reason
        assert not d.top.startswith("bearing")
        monkeypatch.setattr(mating, "MATING_HITS", 99)
        held = vm.diagnose(x, rpm=1800, bearing="6205-2RS", gear=32)
        assert held.confidence <= 0.45 and "bearing_call_unstable" in held.flags   # not made on the cut record
        monkeypatch.setattr(pipeline, "survives_a_cut", lambda run, rows, ev: rows)
        off = vm.diagnose(x, rpm=1800, bearing="6205-2RS", gear=32)
    assert off.top == "bearing_outer_race" and off.confidence >= 0.5 and "mating_teeth" not in off.speed
