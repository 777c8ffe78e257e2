"""Confidence calibration of the diagnosis (monitor/calibration.py): the isotonic fit against a known
rate curve, and the shipped map on synthetic machines neither the calibration nor the benchmark used."""

import warnings

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.monitor.calibration import _table, calibrated, fit_isotonic


def test_isotonic_fit_recovers_a_known_rate_curve():
    # oracle: answers right with probability s^2. 40,000 answers make pooled blocks of hundreds, whose
    # rate has a binomial std <= 0.5 / sqrt(100) = 0.05 at worst: tolerance 0.05
    rng = np.random.default_rng(3)
    s = rng.uniform(0, 1, 40_000)
    right = rng.uniform(0, 1, s.size) < s ** 2
    knots, rates = fit_isotonic(s, right)
    assert np.all(np.diff(knots) >= 0) and np.all(np.diff(rates) >= 0)
    q = np.linspace(0.1, 0.95, 18)
    assert np.max(np.abs(np.interp(q, knots, rates) - q ** 2)) < 0.05


def test_isotonic_fit_of_separable_answers_is_a_step_with_the_prior():
    # scores below 0.5 always wrong (10 answers), above always right (30): two blocks, rates
    # (0 + 1) / (10 + 2) and (30 + 1) / (30 + 2) by the Beta(1, 1) prior, never 0 or 1
    s = np.r_[np.linspace(0.1, 0.4, 10), np.linspace(0.6, 0.9, 30)]
    knots, rates = fit_isotonic(s, s > 0.5)
    np.testing.assert_allclose(knots, [0.0, 0.1, 0.4, 0.6, 0.9])
    np.testing.assert_allclose(rates, [0.0, 1 / 12, 1 / 12, 31 / 32, 31 / 32])
    assert np.interp(0.05, knots, rates) == pytest.approx(1 / 24)   # below the data: towards (0, 0)
    assert np.interp(0.95, knots, rates) == pytest.approx(31 / 32)  # above: constant


@pytest.mark.parametrize("score, right, match", [([], [], "non-zero length"), ([0.1, np.nan], [1, 0], "finite"),
                                                 ([0.1, 0.2], [1], "same"), ([0.1, 0.2], [1, 2], "booleans"),
                                                 ([0.1, 0.2], [1, np.nan], "booleans")])
def test_isotonic_fit_bad_input(score, right, match):
    with pytest.raises(vm.ParameterError, match=match):
        fit_isotonic(score, right)


def test_shipped_maps_are_monotone_probabilities():
    table = _table()
    assert {"none|shaft", "none|bearing", "shaft", "bearing", "bearing not checked:none"} <= set(table)
    for kind, (knots, rates) in table.items():
        assert np.all(np.diff(knots) > 0), kind
        assert np.all(np.diff(rates) >= -1e-12) and 0 <= rates.min() and rates.max() < 1, kind
    # an answer without its own map (electrical is never given by the synthetic set) uses its group's
    assert calibrated("electrical", 0.9, "shaft") == pytest.approx(np.interp(0.9, *table["shaft"]))
    with pytest.raises(vm.ParameterError, match="no calibration"):
        calibrated("nonsense", 0.5, "nonsense")
    for bad in (np.nan, -0.1, 1.5):
        with pytest.raises(vm.ParameterError, match=r"score=.* must be a finite evidence score in \[0, 1\]"):
            calibrated("none|shaft", bad, "none|shaft")


def _shaft_and_bearing(d) -> float:
    """The shaft-order and bearing parts of a "none"'s probability, the gear's aside (its map says at most
    0.73 with a gear declared: the gear test can miss a local tooth fault, test below)."""
    parts = d.extras["score_parts"]
    return (calibrated("none|shaft", parts["shaft"], "none|shaft")
            * calibrated("none|bearing", parts["bearing"], "none|bearing"))


def test_the_gear_part_of_a_none_says_what_the_gear_test_can_miss():
    """The gear part of a "none" is mapped on its own, learnt also on two-gear gearboxes with random
    tooth errors, healthy and with a local tooth fault. The gear test misses local faults: at -10 dB it
    is left nothing (FM4 3.4-5.1, 2-4 wide sidebands; 12 of 12 calibration seeds tried answered "none"
    with the gear at score 0), and on gears with 5-10 % tooth errors the fault's residual may be no more
    impulsive than the surrogates. Of the calibration set's "none" answers with the gear at score 0,
    74 % were right: that "none" was 1.00 (maps learnt before the surrogate test) and is 0.73 now. A
    healthy gearbox whose tooth errors hold the gear test at 0.45 (FM4 8.3, surrogate p 0.0225) was
    healthy "with probability 0.01", the shaft-order map having seen 0.45 on faults only; held gears
    were healthy in 17 % of the calibration's, and it says so. With no gear declared there is no gear
    part."""
    warnings.simplefilter("ignore", vm.QualityWarning)
    buried = vm.diagnose(vm.synth.machine(fault="gear_mesh", snr_db=-10, seed=90001, duration=6.0),
                         bearing="6205-2RS", gear=32)
    assert buried.top == "none" and buried.extras["score_parts"]["gear"] == 1.0
    assert 0.65 < buried.confidence < 0.8
    held = vm.diagnose(vm.synth.machine(fault="none", rpm=1200, mesh=1.0, gear_teeth=19, mating_teeth=61,
                                        tooth_error=0.05, snr_db=30, seed=0, duration=6.0),
                       rpm=1200, bearing="6205-2RS", gear=vm.Gear(19, mating_shaft_ratio=19 / 61))
    assert held.faults.set_index("fault").loc["gear_mesh", "confidence"] == 0.45
    assert held.top == "undetermined" and 0.15 < held.p_healthy < 0.3
    no_gear = vm.diagnose(vm.synth.machine(fault="none", seed=90001, duration=6.0), bearing="6205-2RS")
    assert "gear" not in no_gear.extras["score_parts"] and no_gear.confidence > 0.95


@pytest.mark.parametrize("seed", [90804, 90805, 90806])
def test_none_on_a_buried_resonance_is_not_confident(seed):
    # a structural mode at 1.06 x 1X at -10 dB (seeds outside the calibration's 90500-90649 and the
    # benchmark's 90000-90019): the raw "none" score is 0.5-0.75 (a shaft-order family scored
    # 0.25-0.5), and such "none" answers (score < 0.78) were wrong in 91 of 93 calibration machines:
    # the machine is called healthy with a probability under 0.1: "undetermined", not "none"
    warnings.simplefilter("ignore", vm.QualityWarning)
    d = vm.diagnose(vm.synth.machine(fault="resonance", snr_db=-10, seed=seed, duration=6.0), bearing="6205-2RS",
                    gear=32)
    h = vm.diagnose(vm.synth.machine(fault="none", snr_db=-10, seed=seed, duration=6.0), bearing="6205-2RS",
                    gear=32)
    assert d.top == "undetermined" and d.extras["score"] < 0.78 and d.p_healthy < 0.1
    assert d.confidence == pytest.approx(1 - d.p_healthy) and d.extras["candidates"]
    assert h.top == "none" and h.extras["score"] > 0.9 and _shaft_and_bearing(h) > 0.95 and h.confidence > 0.7
    parts = d.extras["score_parts"]   # the gear declared: its part is mapped on its own
    assert parts["shaft"] * parts["gear"] * parts["bearing"] == pytest.approx(d.extras["score"])
    assert d.p_healthy == pytest.approx(calibrated("none|shaft", parts["shaft"], "none|shaft")
                                         * calibrated("none|gear", parts["gear"], "none|gear")
                                         * calibrated("none|bearing", parts["bearing"], "none|bearing"))
    assert "confidence" in d.to_dict() and d.to_dict()["score"] == pytest.approx(d.extras["score"])


def test_without_a_bearing_a_none_is_weak_evidence_of_health():
    # without a bearing, bearing faults are not looked for: in the calibration mix (one healthy machine
    # in nine, three with bearing faults) a "none" given then was right in 450 of 1893 answers; the same
    # healthy machine with its bearing named is a confident "none"
    warnings.simplefilter("ignore", vm.QualityWarning)
    rec = vm.synth.machine(fault="none", snr_db=0, seed=101060, duration=6.0)
    blind, seen = vm.diagnose(rec, gear=32), vm.diagnose(rec, bearing="6205-2RS", gear=32)
    assert blind.top == "undetermined" and seen.top == "none"
    assert 0.1 < blind.p_healthy < 0.4 and seen.p_healthy > blind.p_healthy + 0.3
    assert "bearing faults not checked" in blind.reason
    # this machine shows a weak BPFO comb (not called): the bearing part of its "none" score is 0.89.
    # Its shaft-order part near 1 says nothing against "none"; the bearing part is a near miss, and in
    # the calibration's edge set (-15 dB) such a "none" hid a bearing fault about 3 times in 10: 0.71,
    # not the 0.99 a map learnt only where bearing faults always show gave it
    parts = seen.extras["score_parts"]
    assert parts["shaft"] > 0.95 and 0.85 < parts["bearing"] < 0.95
    assert 0.6 < _shaft_and_bearing(seen) < 0.85


@pytest.mark.parametrize("fault, seed, low", [("bearing_ball", 85809, True), ("none", 85800, False),
                                              ("none", 85801, False)])
def test_a_none_beside_a_near_miss_is_not_confident(fault, seed, low):
    # at -15 dB (seeds outside the calibration's 85500-85649) a ball defect leaves its family a near miss:
    # not called, bearing part of the "none" score 0.80 (p about 0.003). The map of that part is learnt
    # down to -15 dB, where such near misses were bearing faults: its "none" is weak (below 0.7; a map
    # learnt at -10 dB and above, where bearing faults always show, said 0.99). A healthy machine at the
    # same SNR, its families at p = 1 (part 0.971), stays a confident "none" (> 0.95)
    warnings.simplefilter("ignore", vm.QualityWarning)
    d = vm.diagnose(vm.synth.machine(fault=fault, snr_db=-15, seed=seed, duration=6.0), bearing="6205-2RS",
                    gear=32)
    parts = d.extras["score_parts"]
    assert d.top in ("none", "undetermined")
    if low:
        assert parts["bearing"] < 0.9 and d.p_healthy < 0.7
        assert "strongest bearing candidate bearing_ball" in d.reason
    else:
        assert parts["bearing"] > 0.96 and _shaft_and_bearing(d) > 0.95 and d.confidence > 0.7


def test_a_none_on_real_ball_records_with_a_near_miss_is_not_confident(shared_data):
    # CWRU fan-end B021_0 (ball fault): no ball comb passes (p = 0.0011 after every correction; one line
    # at 7.8 dB; no smeared comb), so the answer is "none", but its confidence now says the candidate is
    # there (below 0.7; 0.94 with the map learnt at -10 dB and above). (B014_1, at 0.996 before, is now
    # called ball from its smeared comb.)
    warnings.simplefilter("ignore", vm.QualityWarning)
    for name in ("B021_0.mat",):
        d = vm.diagnose(vm.read(shared_data(f"cwru_fe/{name}"), fs=12000, unit="g"), bearing="6203-2RS")
        assert d.top in ("none", "undetermined") and d.p_healthy < 0.7, name
        assert "strongest bearing candidate bearing_ball p = 0.00" in d.reason, name


def test_report_flags_an_unlikely_none_for_a_look():
    # the HTML report's verdict: "undetermined" (here the buried resonance of seed 90804, healthy with
    # probability 0.04) is "watch", a confident "none" "ok"
    from vibmeasure.reporting.sections import diagnosis_section
    warnings.simplefilter("ignore", vm.QualityWarning)
    classes = []
    for fault in ("resonance", "none"):
        rec = vm.synth.machine(fault=fault, snr_db=-10, seed=90804, duration=6.0)
        d = vm.diagnose(rec, bearing="6205-2RS", gear=32)
        assert d.top == ("undetermined" if fault == "resonance" else "none")
        sec = diagnosis_section(rec, d, fault)
        classes.append(sec["verdict_class"])
        assert f"(confidence {d.confidence:.2f})" in sec["verdict_text"]
    assert classes == ["watch", "ok"]


@pytest.mark.parametrize("text, match", [(None, "missing or damaged"),
                                         ("kind,score,probability\nnone,0.5,x\n", "missing or damaged"),
                                         ("kind,score\nnone,0.5\n", "missing or damaged"),
                                         ("kind,score,probability\nnone,0.5,0.2\nnone,0.4,0.3\n", "not increasing"),
                                         ("kind,score,probability\nnone,0.5,1.2\n", "not increasing")])
def test_a_missing_or_damaged_table_is_named(tmp_path, text, match):
    path = tmp_path / "calibration.csv"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    with pytest.raises(vm.VibMeasureError, match=match):
        _table(path)
