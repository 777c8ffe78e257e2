"""A gear's history in the fleet: the manifest's ``gear`` column reaches the diagnosis, its synchronous
residual (FM4 and variance) is stored, and the trend's NA4 sees distributed wear that FM4 cannot."""

import re
import warnings

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.monitor.trend import with_na4


def _pattern(th: np.ndarray, teeth: int, seed: int) -> np.ndarray:
    """A gear's own tooth-to-tooth pattern on its shaft angle ``th``: sinusoids at shaft orders 3-149, none
    a mesh harmonic (``teeth`` x 1, 2, 3) or its +-1 sidebands, random amplitudes and phases fixed for the
    gear (``seed``); many such orders sum to a Gaussian residual."""
    rng = np.random.default_rng(seed)
    k = np.arange(3, 150)
    k = k[np.all(np.abs(k[:, None] - teeth * np.array([1, 2, 3])[None]) > 1.5, axis=1)]
    amp, phase = rng.rayleigh(1.0, k.size), rng.uniform(0, 2 * np.pi, k.size)
    # sum_k amp cos(k th + phase) = Re(sum_k c_k z^k), z = exp(i th), by Horner's rule in z (|z| = 1, so
    # stable): a multiply-add per order instead of a cosine per order and sample
    c = np.zeros(k.max() + 1, complex)
    c[k] = amp * np.exp(1j * phase)
    z, s = np.exp(1j * th), np.zeros(th.size, complex)
    for ck in c[::-1]:
        s = s * z + ck
    return s.real


def _gearbox(wear: float, seed: int, mating_wear: float = 0.0) -> vm.Record:
    """A 32-tooth gear on the 1797 rpm shaft meshing with a 71-tooth one, over a healthy machine: the
    mesh, the 32-tooth gear's tooth-to-tooth pattern at ``wear`` x its new level and the 71-tooth gear's
    at ``mating_wear`` x. Wear spread over every tooth keeps each residual Gaussian (FM4 near 3) and
    grows its variance as wear squared."""
    rec = vm.synth.machine(fault="none", seed=seed, duration=6.0)
    th = 2 * np.pi * (1797 / 60) * np.arange(rec.n_samples) / rec.fs
    mesh = sum(a * np.cos(m * 32 * th) for m, a in ((1, 1.0), (2, 1 / 3), (3, 1 / 6)))
    x = rec.data[0] + mesh + 0.02 * wear * _pattern(th, 32, 1234)
    if mating_wear:
        x = x + 0.02 * mating_wear * _pattern(th * 32 / 71, 71, 4321)
    return vm.Record.from_array(x, fs=rec.fs, names=["acc"], unit="g")


def test_na4_is_fm4_scaled_by_the_residuals_growth_over_the_baseline():
    """NA4 = FM4 x (variance / the baseline's mean variance)^2, per point, from the first measurements
    that have the gear's values; NaN until the baseline is complete, and for measurements without them."""
    import pandas as pd
    df = pd.DataFrame({"asset": ["g"] * 5 + ["h"] * 2, "point": "p",
                       "gear_fm4": [3.0, None, 4.0, 3.0, 5.0, 3.0, 3.0],
                       "gear_residual_var": [1.0, 1.0, 3.0, 2.0, 4.0, 1.0, 1.0]})
    got = with_na4(df, 2)["gear_na4"].to_numpy()
    # g: the baseline is measurements 0 and 2 (1 has no FM4): mean variance 2
    np.testing.assert_allclose(got[:5], [3.0 / 4, np.nan, 4.0 * 9 / 4, 3.0, 5.0 * 4], rtol=1e-12)
    np.testing.assert_allclose(got[5:], [3.0, 3.0], rtol=1e-12)
    assert "gear_na4" not in with_na4(df.drop(columns="gear_fm4"), 2)
    for bad in (0, 1, 1.5, True, "8"):
        with pytest.raises(vm.ParameterError, match="baseline_count=.* must be an integer >= 2"):
            with_na4(df, bad)
    for bad in ([1, 2], df.drop(columns="point")):
        with pytest.raises(vm.ParameterError, match="df must be a results DataFrame with asset and point"):
            with_na4(bad, 2)


@pytest.mark.parametrize("wear", [1.0, 2.5])
def test_distributed_wear_alarms_by_na4_where_fm4_stays_gaussian(tmp_path, wear):
    """Ten measurements of a new gear, then three with its tooth-to-tooth pattern at ``wear`` x: the
    residual stays Gaussian (FM4 within 0.3 of 3 throughout: FM4 alone names nothing), its variance
    grows 6.25 x at wear 2.5, so NA4 = 3 x 6.25^2 ~ 117 against a baseline near 3 (alarm at twice it);
    an unchanged gear stays ok. The gear's teeth come from the manifest's ``gear`` column."""
    rows = ["file,asset,point,rpm,bearing,gear,time"]
    for i in range(13):
        path = vm.write(tmp_path / f"g{i:02d}.h5", _gearbox(wear if i >= 10 else 1.0, seed=i))
        rows.append(f"{path.name},gearbox-1,input,1797,6205-2RS,32,2026-01-{i + 1:02d}T08:00")
    (tmp_path / "m.csv").write_text("\n".join(rows) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vm.batch(task="diagnose", store=tmp_path / "s.db", manifest=tmp_path / "m.csv")
    st = vm.Store(tmp_path / "s.db")
    res = st.results("diagnose")
    assert len(res) == 13 and (res["gear_fm4"] - 3.0).abs().max() < 0.3
    assert st.assets()["gear"].tolist() == [32]
    row = vm.trend(st).set_index("metric").loc["gear_na4"]
    assert row["baseline_mean"] == pytest.approx(3.0, abs=0.3)
    if wear == 1.0:
        assert row["verdict"] == "ok" and row["last"] == pytest.approx(3.0, abs=0.3)
    else:
        assert row["verdict"] == "alarm" and row["last"] == pytest.approx(3.0 * wear ** 4, rel=0.15)


def test_the_manifests_gear_is_teeth_or_teeth_and_the_mating_gears(tmp_path):
    """``gear`` is the measured shaft's gear teeth (32) or with the mating gear's (32/71: the mating shaft
    turns at 32/71 of this one's speed, whose sidebands the gear test weighs against this shaft's);
    anything else is named as that row's error (the other rows are analysed)."""
    from vibmeasure.monitor.batch import _gear
    from vibmeasure.monitor.inputs import read_manifest
    m = tmp_path / "m.csv"
    m.write_text("file,asset,gear\na.h5,g,32\nb.h5,g,32/71\nc.h5,g,\n")
    rows = read_manifest(m)
    assert [r.get("gear") for r in rows][:2] == [32, "32/71"] and not rows[2].get("gear")
    assert _gear(rows[0]["gear"]) == vm.Gear(32)
    assert _gear(rows[1]["gear"]).mating_shaft_ratio == pytest.approx(32 / 71, rel=1e-15)
    for bad in ("3", "32/4", "32.5", "32/71/9", "teeth"):
        m.write_text(f"file,asset,gear\na.h5,g,{bad}\nb.h5,g,32\n")
        first, second = read_manifest(m)
        assert "row 2" in first["error"] and re.search(r"gear=.*teeth \(>= 5\)", first["error"]), first
        assert second["gear"] == 32 and "error" not in second


@pytest.mark.parametrize("worn, wheel", [("pinion", 0.1), ("wheel", 1.0)])
def test_na4_tells_which_of_two_meshing_gears_wears(tmp_path, worn, wheel):
    """A 32-tooth pinion meshing with a 71-tooth wheel (manifest ``gear`` 32/71), each with its own
    tooth-to-tooth pattern (the wheel's at ``wheel`` x the pinion's); from the eleventh measurement one
    of them wears (its pattern 2.5 x). Each gear's NA4 comes from its own shaft's synchronous average,
    at the speed of the mesh line refined between bins, with the other shaft's synchronous part taken
    out first: the worn gear's NA4 alarms, the other's stays ok. A quiet wheel beside a wearing pinion
    is the hard case: without the pinion's part taken out (over the wheel's 81 turns in 6 s, the
    pinion's orders near whole wheel orders do not average away) the wheel's NA4 read 12.4 against a
    baseline of 3.2, an alarm; with the mesh line's bin frequency for the speed, 9.1."""
    rows = ["file,asset,point,rpm,bearing,gear,time"]
    for i in range(13):
        w = 2.5 if i >= 10 else 1.0
        rec = _gearbox(w if worn == "pinion" else 1.0, seed=i, mating_wear=w * wheel if worn == "wheel" else wheel)
        path = vm.write(tmp_path / f"g{i:02d}.h5", rec)
        rows.append(f"{path.name},gearbox-1,input,1797,6205-2RS,32/71,2026-01-{i + 1:02d}T08:00")
    (tmp_path / "m.csv").write_text("\n".join(rows) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vm.batch(task="diagnose", store=tmp_path / "s.db", manifest=tmp_path / "m.csv")
    tr = vm.trend(tmp_path / "s.db").set_index("metric")
    bad, good = ("gear_na4", "gear_mating_na4") if worn == "pinion" else ("gear_mating_na4", "gear_na4")
    assert tr.loc[bad, "verdict"] == "alarm" and tr.loc[bad, "last"] > 10 * tr.loc[bad, "baseline_mean"]
    assert tr.loc[good, "verdict"] == "ok", tr.loc[good, "reason"]
