"""A gearbox's hunting-tooth comb measured from the envelope spectrum alone (``bearing.grid``), where no
gear is declared: its lines at many places of a fine grid, not a bearing's comb. Oracles: lines placed by
hand on a known grid or comb, and synth.machine's truth (a healthy two-gear gearbox)."""

import warnings

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.monitor.bearing import grid

DF = 1 / 6.0   # Hz: a 6 s record


def _spectrum(hz, n=6000, seed=0):
    """A floor ratio of 1 with lines (ratio 30-300) at the frequencies hz, each on its nearest bin and
    split between it and the next as a line between bins is."""
    rng = np.random.default_rng(seed)
    r = rng.exponential(1.0, n) * 0.5
    for h in hz:
        x = h / DF
        i = int(np.floor(x))
        frac = x - i
        level = rng.uniform(30, 300)
        r[i] = max(r[i], level * (1 - frac) ** 2 + 1)
        r[i + 1] = max(r[i + 1], level * frac ** 2 + 1)
    return np.arange(n) * DF, r


def test_a_dense_grid_is_measured():
    """Lines on 40 % of the places of a 0.7042 Hz grid (a 32/71 gearbox at 3000 rpm: 50 / 71 Hz), 30-700
    Hz: the spacing is found to 1e-4 relative (the least-squares fit over ~300 lines)."""
    g = 50 / 71
    rng = np.random.default_rng(1)
    places = np.flatnonzero(rng.uniform(size=1000) < 0.4)
    hz = [k * g for k in places if 30 < k * g < 700]
    freq, r = _spectrum(hz)
    found = grid.line_grid(freq, r, freq.size, 10.0, 20.0, 2.0)
    assert found is not None and found[0] == pytest.approx(g, rel=1e-4) and found[2] >= grid.GRID_MIN_ON


def test_a_bearing_comb_with_its_sidebands_is_no_grid():
    """A rich inner-race spectrum: BPFI x 1-20 with +-1X and +-2X sidebands and the shaft's harmonics
    1-100 (f1 = 29.95 Hz, BPFI 5.415 x): about 200 lines (more than GRID_MIN_ON) that lie close to
    sub-multiples of their spacings, never densely."""
    f1, bpfi = 29.95, 5.415 * 29.95
    hz = [k * bpfi + s * f1 for k in range(1, 21) for s in (-2, -1, 0, 1, 2)] + [k * f1 for k in range(1, 101)]
    hz = sorted({round(h, 6) for h in hz if 5 < h < 3300})
    assert len(hz) > grid.GRID_MIN_ON
    freq, r = _spectrum(hz, n=20000)
    assert grid.line_grid(freq, r, freq.size, 10.0, 0.4 * f1, 2.0) is None


def test_random_lines_make_no_grid():
    """300 lines at random places: none of the scanned spacings holds them beyond chance (GRID_P)."""
    hz = np.random.default_rng(2).uniform(5, 990, 300)
    freq, r = _spectrum(hz)
    assert (r >= 10).sum() > grid.GRID_MIN_ON
    assert grid.line_grid(freq, r, freq.size, 10.0, 12.0, 2.0) is None


def _healthy_61_19():
    rec = vm.synth.machine(rpm=1800, gear_teeth=61, mating_teeth=19, fs=12000.0, duration=6.0, fault="none",
                           mesh=1.0, tooth_error=0.05, snr_db=30, seed=0)
    return vm.Record.from_array(rec.data[0], fs=12000.0, names=["acc"], unit="g")


def test_a_ball_comb_on_a_gearbox_s_own_grid_is_not_called(monkeypatch):
    """A healthy 61/19 gearbox (the wheel's shaft at 1800 rpm, no gear declared) demodulated in a band of
    the user's (1.2-2.1 kHz, around its mesh): its envelope carries the gears' hunting-tooth comb, a line
    every 30 / 19 Hz, and a 2 x BSF x 0.5, 1, 1.5 comb on three of its lines was called ball at 0.81.
    Not called, the reason names the grid; with the rule off (GRID_MIN_ON out of reach) it is called."""
    x = _healthy_61_19()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        d = vm.diagnose(x, rpm=1800, bearing="6205-2RS", band=(1200.0, 2100.0))
        assert d.top in ("none", "undetermined") and "dense grid" in d.reason and "1.579 Hz" in d.reason
        monkeypatch.setattr(grid, "GRID_MIN_ON", 10 ** 6)
        off = vm.diagnose(x, rpm=1800, bearing="6205-2RS", band=(1200.0, 2100.0))
    assert off.top == "bearing_ball" and off.confidence >= 0.5


def test_an_outer_race_under_a_mesh_is_still_named():
    """Guard: a bearing's comb under a 0.5 g mesh with 5 % tooth errors, no gear declared, lies on the
    measured grid only by chance: the outer race is named."""
    rec = vm.synth.machine(rpm=1800, gear_teeth=32, mating_teeth=71, fs=12000.0, duration=6.0,
                           fault="bearing_outer_race", mesh=0.5, tooth_error=0.05, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        d = vm.diagnose(vm.Record.from_array(rec.data[0], fs=12000.0, names=["acc"], unit="g"), rpm=1800,
                        bearing="6205-2RS")
    assert d.top == "bearing_outer_race" and d.confidence >= 0.9
