"""A gearbox's own lines where a bearing or a speed is read: the mesh that measures the speed, the two
gears' hunting-tooth comb. Oracles: synth.machine's truth (a healthy two-gear gearbox, its declared speed
and teeth) and the mesh frequency, teeth x the shaft's speed."""

import math
import warnings

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.monitor.bearing import evidence, grid
from vibmeasure.monitor.diagnosis import bearings, gearbox


def _gearbox(rpm, z1, z2, error, snr, seed):
    rec = vm.synth.machine(rpm=rpm, gear_teeth=z1, mating_teeth=z2, fs=12000.0, duration=6.0, fault="none",
                           mesh=1.0, tooth_error=error, snr_db=snr, seed=seed)
    return vm.Record.from_array(rec.data[0], fs=12000.0, names=["acc"], unit="g")


def _diagnose(x, rpm, gear):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        return vm.diagnose(x, rpm=rpm, bearing="6205-2RS", gear=gear)


@pytest.mark.parametrize("case", [(3600, 40, 83, 0.1, 10, 0), (3600, 40, 83, 0.02, 30, 0), (3000, 32, 71, 0.1, 30, 0)])
def test_the_mesh_line_confirms_a_1x_at_the_line_frequency(case, monkeypatch):
    """A shaft at 3600 or 3000 rpm turns at the line frequency, whose lines are not taken for a 1X; alone,
    the 1X search took the mating shaft's 2X (3470 rpm for 40/83, 2705 rpm for 32/71: 3.6 and 9.8 % off,
    each with its harmonics) or found none. With the gear declared, the mesh line (teeth x the speed)
    and the 1X agree: the speed is the mesh's over the teeth. Tolerance: the mesh line refined on 6 s
    (0.17 Hz lines) over 32-40 teeth, 0.05 % of the speed. Without a gear declared, the pair found in the
    spectrum (``diagnosis.gearbox``) measures it as well; the 1X search alone (that step off) does not."""
    rpm, z1, z2, error, snr, seed = case
    x = _gearbox(rpm, z1, z2, error, snr, seed)
    d = _diagnose(x, rpm, vm.Gear(z1, mating_shaft_ratio=z1 / z2))
    assert d.speed["estimated_rpm"] == pytest.approx(rpm, rel=5e-4)
    assert d.speed["mesh_hz"] == pytest.approx(z1 * rpm / 60, rel=5e-4)
    assert not {"speed_corrected", "speed_unconfirmed", "speed_contradicted"} & set(d.flags)
    found = _diagnose(x, rpm, None)
    assert found.speed["estimated_rpm"] == pytest.approx(rpm, rel=5e-4) and found.speed["gearbox"]["on_shaft"]
    monkeypatch.setattr(gearbox, "find_gearbox", lambda f, A, f1: None)
    alone = _diagnose(x, rpm, None)
    assert alone.speed["estimated_rpm"] is None or abs(alone.speed["estimated_rpm"] / rpm - 1) > 0.03


def test_a_wrong_tooth_count_falls_back_to_the_1x_search(monkeypatch):
    """Declared with 41 teeth where the gear has 40, no 1X stands at the strongest line's 41st
    sub-harmonic: the mesh confirms nothing, and the speed is read as without a gear by the 1X search
    alone (a declared gear, even a wrong one, is not replaced by the pair the spectrum shows)."""
    monkeypatch.setattr(gearbox, "find_gearbox", lambda f, A, f1: None)
    x = _gearbox(3600, 40, 83, 0.1, 10, 0)
    wrong = _diagnose(x, 3600, 41)
    assert "mesh_hz" not in wrong.speed
    assert wrong.speed["estimated_rpm"] == _diagnose(x, 3600, None).speed["estimated_rpm"]


def _ses_of_lines(hz, fs=2000.0, duration=6.0, seed=0):
    """The SES of unit lines at ``hz`` over noise 40 dB down, Hann-windowed as the bearing test's."""
    from vibmeasure.monitor.bearing.spectra import _SES
    t = np.arange(int(fs * duration)) / fs
    rng = np.random.default_rng(seed)
    x = sum(np.cos(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in hz) + 0.01 * rng.normal(size=t.size)
    amp = np.abs(np.fft.rfft(x * np.hanning(t.size)))
    P = amp ** 2
    return _SES("acc", "cepstral", (1000.0, 6000.0), np.fft.rfftfreq(t.size, 1 / fs), amp, P / np.median(P), P.size)


def test_a_comb_whose_lines_all_stand_on_the_hunting_tooth_grid_is_the_gearboxs():
    """Oracle: lines placed on the grid of a 40/83 pair at 3600 rpm (a line every 60 / 83 = 0.723 Hz,
    4.3 lines of 1/6 Hz) at grid lines 373, 456 and 539 (a BPFI +-1X triplet at 329.6 Hz) stand on it:
    their refined frequencies lie within 0.05 line of the grid (the parabola's error on clean lines),
    HUNT_TOL is 0.25. The same triplet 0.4 line off the grid (0.067 Hz) does not; one line alone says
    nothing; a grid finer than HUNT_MIN_SPACING lines holds every line and is not asked."""
    sp = 60 / 83
    on = [373 * sp, 456 * sp, 539 * sp]
    fam = {"lines": [{"hz": hz + 0.04, "r": 50.0} for hz in on]}   # the comb model's positions, a slip off
    assert evidence._on_hunting_grid(_ses_of_lines(on), fam, sp)
    off = [hz + 0.4 / 6 for hz in on]
    assert not evidence._on_hunting_grid(_ses_of_lines(off), {"lines": [{"hz": hz, "r": 50.0} for hz in off]}, sp)
    one = {"lines": [dict(fam["lines"][0]), {"hz": on[1], "r": 1.0}]}
    assert not evidence._on_hunting_grid(_ses_of_lines(on), one, sp)
    assert not evidence._on_hunting_grid(_ses_of_lines(on), fam, 0.3)
    assert not evidence._on_hunting_grid(_ses_of_lines(on), fam, None)


def test_a_bearing_comb_on_the_hunting_tooth_grid_is_not_called(monkeypatch):
    """A healthy 23/67 gearbox at 2400 rpm with rough gears (20 % tooth errors, 30 dB, seed 4): the two
    gears' errors repeat together every 67 pinion turns, a line every 40 / 67 = 0.597 Hz (3.6 lines of
    1/6 Hz). The 6205's BPFI comb found lines on it (p = 9e-7) and was called inner race at 0.99. Every
    standing line of it lies within HUNT_TOL of the grid: not called, the reason says why; with the
    tolerance at 0 it is called again."""
    x = _gearbox(2400, 23, 67, 0.2, 30, 4)
    gear = vm.Gear(23, mating_shaft_ratio=23 / 67)
    d = _diagnose(x, 2400, gear)
    inner = d.faults.set_index("fault").loc["bearing_inner_race"]
    assert d.top != "bearing_inner_race" and inner.p_value < 1e-5
    assert "hunting-tooth comb (a line every 0.597 Hz" in inner.not_called
    monkeypatch.setattr(grid, "HUNT_TOL", 0.0)
    monkeypatch.setattr(grid, "HUNT_TOL_MAX", 0.0)
    assert _diagnose(x, 2400, gear).top == "bearing_inner_race"


@pytest.mark.parametrize("fault", ["bearing_outer_race", "bearing_inner_race", "bearing_ball"])
def test_a_bearing_fault_under_a_mesh_is_off_the_hunting_tooth_grid(fault):
    """A bearing's defect frequency is no multiple of the hunting-tooth spacing: its comb under a 0.5 g
    two-gear mesh (32/71 at 1800 rpm, a line every 30 / 71 = 0.42 Hz, 2.5 lines on 6 s) is still named
    with the ratio declared, at 0.9 or more."""
    rec = vm.synth.machine(fault=fault, rpm=1800, gear_teeth=32, mating_teeth=71, fs=12000.0, duration=6.0,
                           mesh=0.5, tooth_error=0.05, seed=1)
    x = vm.Record.from_array(rec.data[0], fs=12000.0, names=["acc"], unit="g")
    d = _diagnose(x, 1800, vm.Gear(32, mating_shaft_ratio=32 / 71))
    assert d.top == fault and d.confidence >= 0.9


def test_the_hunting_tooth_spacing_needs_whole_teeth():
    """f1 x gcd(z1, z2) / z2 for a ratio that makes whole teeth on the mating gear; none otherwise, and
    none without a ratio."""
    class J:
        gear = vm.Gear(40, mating_shaft_ratio=40 / 83)
    assert bearings._hunting(J, 60.0) == pytest.approx(60 / 83)
    J.gear = vm.Gear(42, mating_shaft_ratio=42 / 84)
    assert bearings._hunting(J, 30.0) == pytest.approx(30 * math.gcd(42, 84) / 84)
    J.gear = vm.Gear(40, mating_shaft_ratio=0.4837)
    assert bearings._hunting(J, 60.0) is None
    J.gear = vm.Gear(40)
    assert bearings._hunting(J, 60.0) is None
    with pytest.raises(vm.ParameterError, match="hunting_hz"):
        b = vm.BEARINGS["6205-2RS"]
        evidence.bearing_evidence({"a": np.random.default_rng(0).normal(size=24000)}, 12000.0, 30.0,
                                  b.frequencies(30.0), b.n_balls, hunting_hz=np.nan)


@pytest.mark.parametrize("case", [(1800, 32, 71), (2400, 23, 67)])
def test_a_speed_declared_half_the_mesh_s_is_doubted(case):
    """A healthy gearbox (5 % tooth errors, 10 dB, seed 0) declared at half its speed reads its true 1X
    as 2X: "2X/1X" of 10-14, misalignment at 1.00, unflagged. With the gear declared, its mesh stands at
    twice where the declared speed puts it, with a 1X there: flag speed_doubtful, the answer held at 0.45
    and the reason saying so. (Without a gear the pattern alone cannot tell a factor 2 from
    misalignment: left as it was.) Oracle: the mesh at teeth x the true speed."""
    rpm, z1, z2 = case
    x = _gearbox(rpm, z1, z2, 0.05, 10, 0)
    for gear in (z1, vm.Gear(z1, mating_shaft_ratio=z1 / z2)):
        d = _diagnose(x, rpm / 2, gear)
        assert "speed_doubtful" in d.flags and d.confidence <= 0.45
        assert d.speed["mesh_factor"] == 2.0 and d.speed["mesh_hz"] == pytest.approx(z1 * rpm / 60, rel=5e-4)
        assert "2 x where the declared" in d.reason
    right = _diagnose(x, rpm, z1)
    assert "mesh_factor" not in right.speed and "speed_doubtful" not in right.flags


def test_weak_lines_on_the_grid_widen_the_tolerance_while_chance_stays_under_one_per_cent():
    """Oracle: a comb of n lines falls on a grid of s lines by chance as often as (2 tol / s)^n. Two lines
    keep HUNT_TOL (0.25: on a 4.3-line grid 1.3 % by chance); four lines on it reach HUNT_TOL_MAX (0.35:
    0.07 %); three on a 2.5-line grid stop where the chance is 1 % (0.27). A rough 40/83 gearbox at 30
    dB (20 % tooth errors, no gear declared: the pair found) put a four-line ball comb on its grid, the
    lines 8-13 dB over their floor and up to 0.30 line off it (the parabola's error on weak lines):
    called ball at 0.52 before, now not."""
    assert grid.grid_tolerance(2, 4.34) == pytest.approx(0.25)
    assert grid.grid_tolerance(4, 4.34) == pytest.approx(0.35)
    assert grid.grid_tolerance(3, 2.5) == pytest.approx(1.25 * 0.01 ** (1 / 3))
    assert (2 * grid.grid_tolerance(3, 2.5) / 2.5) ** 3 == pytest.approx(0.01)
    d = _diagnose(_gearbox(3600, 40, 83, 0.2, 30, 0), 3600, None)
    assert not (d.top.startswith("bearing") and d.confidence >= 0.5), d.reason
    assert "hunting-tooth comb" in d.faults.set_index("fault").loc["bearing_ball", "not_called"]
