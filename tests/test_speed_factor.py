"""A speed declared twice or half the true one on a gearbox, where the 1X is the weakest of its lines:
each answer that rests on the declared orders is held (<= 0.45) with a flag saying the speed may be off
by 2, and the same machine at its true speed is not. Oracles: synth.machine's truth (the gearbox's
speed and teeth; the misaligned and loose machines' lines at 1X, 2X, 3X and 0.5X, 1.5X)."""

import warnings

import pytest

import vibmeasure as vm
from vibmeasure.monitor.diagnosis import doubts

HELD = doubts.DOUBT_CONFIDENCE


def _gearbox(rpm, z1, z2, error, snr, seed=0):
    rec = vm.synth.machine(rpm=rpm, gear_teeth=z1, mating_teeth=z2, fs=12000.0, duration=6.0, fault="none",
                           mesh=1.0, tooth_error=error, snr_db=snr, seed=seed)
    return vm.Record.from_array(rec.data[0], fs=12000.0, names=["acc"], unit="g")


def _diagnose(x, rpm, gear=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        return vm.diagnose(x, rpm=rpm, bearing="6205-2RS", gear=gear)


@pytest.mark.parametrize("case", [(1800, 32, 71, 0.05), (2400, 23, 67, 0.05), (1500, 25, 47, 0.1)])
def test_misalignment_from_a_2x_without_a_1x_is_held(case):
    """A healthy gearbox (10 dB) declared at half its speed, no gear declared: its true 1X reads as a 2X
    over a declared 1X that does not stand, "2X/1X" 10 or more, and was called misalignment at 0.83-1.00.
    Held at 0.45 with speed_unconfirmed; at its true speed no such flag."""
    rpm, z1, z2, error = case
    x = _gearbox(rpm, z1, z2, error, 10, seed=1)
    d = _diagnose(x, rpm / 2)
    assert d.top != "misalignment" or (d.confidence <= HELD and "speed_unconfirmed" in d.flags
                                       and "2X the call rests on" in d.reason)
    assert not (d.top not in ("none", "undetermined") and d.confidence >= 0.5)
    assert "speed_unconfirmed" not in _diagnose(x, rpm).flags


@pytest.mark.parametrize("snr", [-10, 10])
def test_a_misaligned_shaft_keeps_its_confidence(snr):
    """Guard: synth's misalignment carries a 1X (0.08 g under a 0.5 g 2X), found at -10 dB too, so the
    2X-without-1X doubt does not touch it (12 of 12 seeds at -10, 0 and 10 dB when written)."""
    rec = vm.synth.machine(fault="misalignment", snr_db=snr, seed=3)
    d = _diagnose(rec, rec.meta["rpm"])
    assert d.top == "misalignment" and d.confidence >= 0.5 and "speed_unconfirmed" not in d.flags


@pytest.mark.parametrize("case", [(2400, 23, 67, 0.05, 30), (1797, 32, 71, 0.1, 10)])
def test_a_strong_line_at_half_the_declared_speed_holds_the_answer(case):
    """Declared at twice its speed, a healthy gearbox shows its true 1X at 0.5X, 18-28 dB over the
    declared 1X (its true 2X), and its 3X too weak (or on the 120 Hz supply harmonic) for the 0.5X-1.5X
    time-base test: called looseness at 1.00 unflagged. Held with speed_doubtful; the line is where the
    true speed puts it."""
    rpm, z1, z2, error, snr = case
    x = _gearbox(rpm, z1, z2, error, snr)
    for gear in (None, vm.Gear(z1, mating_shaft_ratio=z1 / z2)):
        d = _diagnose(x, 2 * rpm, gear)
        assert "speed_doubtful" in d.flags or "speed_inconsistent" in d.flags
        assert d.top in ("none", "undetermined") or d.confidence <= HELD
        assert d.speed["half_line"][0] == pytest.approx(rpm / 60, abs=0.2)   # a line, 1/6 Hz apart
    assert "half_line" not in _diagnose(x, rpm).speed


def test_a_loose_machine_s_sub_harmonic_is_no_half_line():
    """Guard: synth's looseness has its 0.5X under its 1X (0.08 against 0.1 g): no speed doubt."""
    rec = vm.synth.machine(fault="looseness", snr_db=10, seed=2)
    d = _diagnose(rec, rec.meta["rpm"])
    assert d.top == "looseness" and "half_line" not in d.speed and "speed_doubtful" not in d.flags


@pytest.mark.parametrize("case", [(3000, 32, 71, 0.05, 30), (3600, 40, 83, 0.1, 10)])
def test_a_mesh_at_the_declared_speed_with_one_at_half_it_is_its_second_harmonic(case):
    """Declared at twice its speed with its gear, a gearbox's second mesh harmonic stands where the
    declared speed puts the mesh, with a 1X (the true 2X) under it: the speed seemed confirmed, and a
    bearing inner race was called at 1.00. The mesh at half that, with its own 1X, makes the declared
    speed doubtful (mesh_factor 0.5), held. Oracle: the mesh at teeth x the true speed."""
    rpm, z1, z2, error, snr = case
    x = _gearbox(rpm, z1, z2, error, snr)
    d = _diagnose(x, 2 * rpm, vm.Gear(z1, mating_shaft_ratio=z1 / z2))
    assert d.speed["mesh_factor"] == 0.5
    assert d.speed["mesh_factor_hz"] == pytest.approx(z1 * rpm / 60, rel=5e-4)
    assert d.speed["mesh_hz"] == pytest.approx(2 * z1 * rpm / 60, rel=5e-4)
    assert "speed_doubtful" in d.flags and (d.top in ("none", "undetermined") or d.confidence <= HELD)
    assert "mesh_factor" not in _diagnose(x, rpm, vm.Gear(z1, mating_shaft_ratio=z1 / z2)).speed


def test_a_mesh_at_four_times_the_declared_speed_s_doubts_the_time_base():
    """A gearbox record whose sampling rate is declared 4 x the true one reads every line at 4 x its
    frequency: the declared gear's mesh stands at 4 x where the declared speed puts it, with a 1X there.
    A bearing fault's lines, 4 x off, were lost without a flag ("undetermined"); now speed_doubtful,
    mesh_factor 4. Oracle: the mesh at teeth x the true speed x 4."""
    rec = vm.synth.machine(rpm=1800, gear_teeth=32, mating_teeth=71, fs=12000.0, duration=6.0,
                           fault="bearing_outer_race", mesh=0.5, tooth_error=0.05, seed=0)
    x = vm.Record.from_array(rec.data[0], fs=48000.0, names=["acc"], unit="g")
    d = _diagnose(x, 1800, vm.Gear(32, mating_shaft_ratio=32 / 71))
    assert d.speed["mesh_factor"] == 4.0 and d.speed["mesh_factor_hz"] == pytest.approx(4 * 32 * 30, rel=5e-4)
    assert "speed_doubtful" in d.flags and "fs 4 x" in d.reason


def test_a_speed_no_1x_checks_is_said():
    """A healthy gearbox at 3000 rpm declared at 2400 (no gear): no 1X stands within 12 % of 2400 rpm
    (the true 1X, 25 % away, sits on the 50 Hz supply line): speed_unchecked, the reason saying the speed
    was used as declared. At 1800 rpm, declared so, its 1X is found: no such flag."""
    d = _diagnose(_gearbox(3000, 32, 71, 0.05, 30), 2400)
    assert "speed_unchecked" in d.flags and "used as declared, unchecked" in d.reason
    assert d.speed["estimated_rpm"] is None
    assert "speed_unchecked" not in _diagnose(_gearbox(1800, 32, 71, 0.05, 30), 1800).flags


@pytest.mark.parametrize("q", [0.8, 1.2])
def test_the_mesh_corrects_a_speed_a_fifth_off(q):
    """A local tooth fault (32/71 at 1800 rpm, 5 % tooth errors, 10 dB) declared at 0.8 or 1.2 x its speed
    with its gear: the 1X lies outside its 12 % search, and the fault was lost ("none" at 0.73). The mesh,
    looked for within 30 %, and a 1X at its speed over the teeth give the speed (speed_corrected, within
    0.1 %) and the fault is named."""
    rec = vm.synth.machine(rpm=1800, gear_teeth=32, mating_teeth=71, fs=12000.0, duration=6.0, fault="gear_mesh",
                           tooth_error=0.05, snr_db=10, seed=1)
    x = vm.Record.from_array(rec.data[0], fs=12000.0, names=["acc"], unit="g")
    d = _diagnose(x, 1800 * q, vm.Gear(32, mating_shaft_ratio=32 / 71))
    assert d.top == "gear_mesh" and "speed_corrected" in d.flags
    assert d.speed["estimated_rpm"] == pytest.approx(1800, rel=1e-3)


def test_a_gear_whose_mesh_is_not_seen_is_said():
    """A machine without a mesh (synth.machine, healthy, 10 dB) declared with a 32-tooth gear: no mesh
    line at 32 x 1X, the gear is not checked: flag gear_not_seen and the reason says so; the answer
    stands ("none": the flag says what was not looked at, it doubts nothing else). Without the gear, no
    such flag."""
    rec = vm.synth.machine(fault="none", snr_db=10, seed=0)
    rpm = rec.meta["rpm"]
    d = _diagnose(rec, rpm, vm.Gear(32))
    assert "gear_not_seen" in d.flags and "the gear was not checked" in d.reason
    assert d.top == "none" and d.confidence >= 0.5
    assert "gear_not_seen" not in _diagnose(rec, rpm).flags


@pytest.mark.parametrize("fault", ["bearing_outer_race", "bearing_ball"])
def test_a_bearing_comb_at_four_times_an_unconfirmed_speed_contradicts_it(fault):
    """A bearing fault under a gearbox's mesh at 3000 rpm (its 1X on the supply's 50 Hz, so no 1X
    confirms the speed), read with fs declared 4 x the true rate: every line stands 4 x higher, and the
    bearing's comb with them. At the true rate it is named; at 4 x fs the speed is contradicted near
    12,000 rpm (within the scan's 6 % window) and the advice names fs, instead of "none" or a fault
    unflagged. Oracle: synth.machine's fault and the factor the mistake makes."""
    rec = vm.synth.machine(rpm=3000, gear_teeth=32, mating_teeth=71, fs=12000.0, duration=6.0, fault=fault,
                           mesh=0.5, tooth_error=0.05, seed=0)
    x = rec.data[0]
    assert _diagnose(vm.Record.from_array(x, fs=12000.0, names=["acc"], unit="g"), 3000).top == fault
    d = _diagnose(vm.Record.from_array(x, fs=48000.0, names=["acc"], unit="g"), 3000)
    assert "speed_contradicted" in d.flags and d.top not in (fault, "none"), d.reason
    assert d.speed["contradicting_rpm"] == pytest.approx(12000.0, rel=0.06)
    assert "check fs: a sampling rate declared 4 x too high" in d.reason
