"""The command line, run in-process through main(argv) and once as the installed console script."""
import io
import json
import shutil
import subprocess
import sys

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.cli import main


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    code = main(argv, out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def test_text_report_on_sample(sample_dir):
    code, out, err = run(["ringdown", str(sample_dir / "ringdown_beam.csv")])
    assert code == 0
    assert "23.6" in out and "fn [Hz]" in out


def test_json_document_keys_and_values(sample_dir):
    code, out, _ = run(["ringdown", str(sample_dir / "ringdown_3modes.h5"), "--json"])
    assert code == 0
    doc = json.loads(out)
    assert doc["method"] == "ml" and doc["unit"] == "m" and doc["fs_hz"] == 2000.0
    modes = doc["modes"]
    assert [set(m) >= {"fn_hz", "zeta", "fn_std_hz", "zeta_std", "method", "flags"} for m in modes] == [True] * 3
    truth = ([21.3, 57.9, 110.4], [0.010, 0.020, 0.015])
    for m, f, z in zip(modes, *truth):
        # the sample is synthetic at 40 dB: within 5 reported std of the truth
        assert abs(m["fn_hz"] - f) < 5 * m["fn_std_hz"]
        assert abs(m["zeta"] - z) < 5 * m["zeta_std"]


@pytest.mark.parametrize("method", ["logdec", "hilbert", "halfpower"])
def test_classic_methods_from_cli(sample_dir, method):
    code, out, _ = run(["ringdown", str(sample_dir / "ringdown_beam.csv"), "--method", method, "--json"])
    assert code == 0
    m = json.loads(out)["modes"][0]
    assert m["method"] == method and m["fn_hz"] == pytest.approx(23.7, rel=2e-3)
    assert m["zeta"] == pytest.approx(0.012, rel=0.05)


def test_plot_written_atomically(sample_dir, tmp_path):
    png = tmp_path / "fit.png"
    code, _, err = run(["ringdown", str(sample_dir / "ringdown_beam.csv"), "--plot", str(png)])
    assert code == 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["fit.png"]


def test_errors_exit_2_and_write_nothing(tmp_path):
    bad = tmp_path / "bare.csv"
    bad.write_text("1\n2\n3\n" * 50)
    png = tmp_path / "out.png"
    code, out, err = run(["ringdown", str(bad), "--plot", str(png)])
    assert code == 2 and out == ""
    assert err.startswith("vibmeasure: error:") and "fs (sampling rate in Hz) is required" in err
    assert not png.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["bare.csv"]
    code, _, err = run(["ringdown", str(bad), "--fs", "100"])
    assert code == 2 and "vibmeasure: error:" in err  # a staircase is no decay
    code, _, err = run(["ringdown", str(tmp_path / "missing.h5")])
    assert code == 2 and "does not exist" in err


def test_wrong_channel_and_bad_modes(sample_dir):
    code, _, err = run(["ringdown", str(sample_dir / "ringdown_beam.csv"), "--channel", "nope"])
    assert code == 2 and "'nope' is not in this record" in err
    code, _, err = run(["ringdown", str(sample_dir / "ringdown_beam.csv"), "--modes", "many"])
    assert code == 2 and "--modes" in err
    with pytest.raises(SystemExit) as ex:
        run(["ringdown", str(sample_dir / "ringdown_beam.csv"), "--method", "magic"])
    assert ex.value.code == 2


def test_quality_warnings_go_to_stderr_and_json(sample_dir):
    code, out, err = run(["ringdown", str(sample_dir / "coulomb_decay.csv"), "--json"])
    assert code == 0
    doc = json.loads(out)
    assert doc["modes"][0]["zeta"] is None and "coulomb_friction" in doc["flags"]
    assert doc["extras"]["friction_decay_per_cycle"] == pytest.approx(4e-4, rel=0.01)
    assert "vibmeasure: warning:" in err and doc["warnings"]


def test_console_script_installed(sample_dir):
    exe = shutil.which("vibmeasure")
    cmd = [exe] if exe else [sys.executable, "-m", "vibmeasure.cli"]
    r = subprocess.run(cmd + ["ringdown", str(sample_dir / "ringdown_beam.csv"), "--json"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["modes"][0]["fn_hz"] == pytest.approx(23.7, rel=1e-3)


def test_force_channel_option_on_real_hammer_test(shared_data):
    code, out, err = run(["ringdown", str(shared_data("impact/case1.mat")), "--force", "Time_chan_1", "--json"])
    assert code == 0
    doc = json.loads(out)
    assert "start_detected" in doc["flags"] and doc["extras"]["channel"] == "Time_chan_2"
    fns = [m["fn_hz"] for m in doc["modes"]]
    assert min(abs(f - 34.06) for f in fns) < 0.01 and min(abs(f - 212.1) for f in fns) < 0.01
    code, _, err = run(["ringdown", str(shared_data("impact/case1.mat")), "--force", "hammer"])
    assert code == 2 and "'hammer' is not in this record" in err


# --- spectrum -----------------------------------------------------------------------------------
def test_spectrum_json_peaks_on_machine_sample(sample_dir):
    code, out, err = run(["spectrum", str(sample_dir / "machine.h5"), "--json", "--peaks", "6"])
    assert code == 0, err
    doc = json.loads(out)
    assert doc["kind"] == "amplitude" and doc["unit"] == "g" and doc["df_hz"] == pytest.approx(0.25)
    pk = doc["peaks"]["acc_de"]
    top = {round(p["freq_hz"], 2): p["amplitude"] for p in pk}
    # synthesised: 0.08 g at 29.95 Hz, 0.03 g at 2X, 0.05 g at 1200 Hz with 0.01 g sidebands (+-1X)
    assert top[29.95] == pytest.approx(0.08, rel=0.01) and top[1200.0] == pytest.approx(0.05, rel=0.01)
    assert {1170.05, 1229.95} <= set(top)


def test_spectrum_psd_csv_and_plot(sample_dir, tmp_path):
    csv, png = tmp_path / "psd.csv", tmp_path / "psd.png"
    code, out, err = run(["spectrum", str(sample_dir / "machine.h5"), "--kind", "psd", "--nperseg", "2048",
                          "--band", "10", "200", "--csv", str(csv), "--plot", str(png)])
    assert code == 0, err
    import pandas as pd
    tab = pd.read_csv(csv)
    assert list(tab.columns) == ["freq [Hz]", "acc_de [g^2/Hz]"]  # every header carries its unit
    assert tab["freq [Hz]"].min() >= 10 and tab["freq [Hz]"].max() <= 200
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_spectrum_envelope_needs_band(sample_dir):
    code, _, err = run(["spectrum", str(sample_dir / "machine.h5"), "--kind", "envelope"])
    assert code == 2 and "band=(lo, hi) is required" in err
    code, out, _ = run(["spectrum", str(sample_dir / "machine.h5"), "--kind", "envelope", "--band", "1000", "1400",
                        "--json", "--peaks", "1"])
    assert code == 0
    assert json.loads(out)["peaks"]["acc_de.env"][0]["freq_hz"] == pytest.approx(29.95, abs=0.05)


def test_spectrum_errors_and_progress(sample_dir, monkeypatch, tmp_path):
    code, _, err = run(["spectrum", str(sample_dir / "machine.h5"), "--kind", "psd", "--nperseg", "100000"])
    assert code == 2 and "exceeds the record length" in err
    from vibmeasure.cli._common import Progress
    monkeypatch.setattr(Progress.__init__, "__defaults__", (0.0,))  # show at once
    code, _, err = run(["spectrum", str(sample_dir / "machine.h5"), "--kind", "psd", "--nperseg", "256"])
    assert code == 0 and "psd [" in err and "100%" in err


# --- frf and modes ----------------------------------------------------------------------------
def _hammer_csv(tmp_path):
    from tests.test_frf import impact_record
    rec = impact_record()
    return vm.write(tmp_path / "hammer.csv", rec)


def test_frf_and_modes_from_hammer_csv(tmp_path):
    p = _hammer_csv(tmp_path)
    png = tmp_path / "bode.png"
    code, out, err = run(["frf", str(p), "--input", "hammer", "--impact", "--json", "--plot", str(png)])
    assert code == 0, err
    doc = json.loads(out)
    assert doc["outputs"] == ["a0", "a1", "a2"] and doc["n_averages"] == 3 and doc["form"] == "receptance"
    assert png.read_bytes()[:4] == b"\x89PNG"
    stab = tmp_path / "stab.png"
    code, out, err = run(["modes", str(p), "--input", "hammer", "--impact", "--band", "5", "150", "--json",
                          "--plot", str(stab)])
    assert code == 0, err
    modes = json.loads(out)["modes"]
    np.testing.assert_allclose([m["fn_hz"] for m in modes], [21.3, 57.9, 110.4], rtol=5e-4)
    np.testing.assert_allclose([m["zeta"] for m in modes], [0.010, 0.020, 0.015], rtol=0.01)
    assert stab.read_bytes()[:4] == b"\x89PNG"


def test_modes_from_uff_frf_file(tmp_path):
    pyuff = pytest.importorskip("pyuff")
    freq = np.arange(0, 150.25, 0.25)
    frf = vm.synth.modal_frf(freq, fn=[21.3, 57.9], zeta=[0.01, 0.02], shapes=[[0.5, 0.6], [0.7, -0.2]])
    path = tmp_path / "frf.uff"
    u = pyuff.UFF(str(path))
    for o in range(2):
        d = pyuff.prepare_58(func_type=4, rsp_node=o + 1, rsp_dir=3, ref_node=1, ref_dir=3, data=frf.h[o, 0],
                             x=freq, id1=f"frf {o}", rsp_ent_name=f"node{o + 1}", ref_ent_name="node1",
                             abscissa_spacing=1, abscissa_spec_data_type=18, ordinate_spec_data_type=8,
                             orddenom_spec_data_type=13, binary=0)
        u.write_sets(d, mode="add" if o else "overwrite")
    back = vm.read_frf(path)
    assert back.outputs == ("node1", "node2") and back.form == "receptance"
    np.testing.assert_allclose(back.h, frf.h, rtol=1e-5)  # ASCII UFF keeps ~6-7 digits
    code, out, err = run(["modes", str(path), "--band", "5", "100", "--json"])
    assert code == 0, err
    np.testing.assert_allclose([m["fn_hz"] for m in json.loads(out)["modes"]], [21.3, 57.9], rtol=1e-5)


def test_modes_errors(tmp_path):
    p = _hammer_csv(tmp_path)
    code, _, err = run(["modes", str(p), "--input", "nobody", "--band", "5", "150"])
    assert code == 2 and "'nobody' is not in the file" in err
    code, _, err = run(["modes", str(p), "--input", "hammer", "--impact", "--band", "200", "300"])
    assert code == 2 and "band=" in err


def test_every_option_of_every_command_has_help_text():
    import argparse
    from vibmeasure.cli.main import build_parser
    missing = []
    for a in build_parser()._actions:
        if isinstance(a, argparse._SubParsersAction):
            for name, sp in a.choices.items():
                missing += [(name, b.dest) for b in sp._actions
                            if b.help is None and not isinstance(b, argparse._HelpAction)]
    assert not missing, missing


def _bare_hammer_csv(tmp_path):
    # the same hammer test as a plain CSV with a time column: no quantities, no units
    import pandas as pd
    from tests.test_frf import impact_record
    rec = impact_record()
    df = pd.DataFrame(rec.data.T, columns=list(rec.names))
    df.insert(0, "time", rec.time)
    p = tmp_path / "bare_hammer.csv"
    df.to_csv(p, index=False)
    return p


def test_frf_and_modes_take_quantity_and_unit_per_channel_and_write_csv_with_units(tmp_path):
    import pandas as pd
    p = _bare_hammer_csv(tmp_path)
    csv = tmp_path / "frf.csv"
    code, out, err = run(["frf", str(p), "--input", "hammer", "--impact", "--unit", "mm", "--unit", "hammer=N",
                          "--json", "--csv", str(csv)])
    assert code == 0, err
    doc = json.loads(out)
    assert doc["form"] == "receptance"  # --unit mm says displacement
    tab = pd.read_csv(csv)
    assert list(tab.columns)[:7] == ["freq [Hz]", "output", "input", "re [mm/N]", "im [mm/N]", "magnitude [mm/N]",
                                     "phase [deg]"]
    assert set(tab["output"]) == {"a0", "a1", "a2"} and len(tab) == 3 * tab["freq [Hz]"].nunique()
    # velocity data named so: the FRF is a mobility
    code, out, err = run(["frf", str(p), "--input", "hammer", "--impact", "--quantity", "velocity", "--json"])
    assert code == 0 and json.loads(out)["form"] == "mobility", err
    modes_csv = tmp_path / "modes.csv"
    code, out, err = run(["modes", str(p), "--input", "hammer", "--impact", "--band", "5", "150",
                          "--quantity", "displacement", "--csv", str(modes_csv)])
    assert code == 0, err
    m = pd.read_csv(modes_csv)
    assert list(m.columns)[:5] == ["mode", "fn [Hz]", "fn_std [Hz]", "zeta [-]", "zeta_std [-]"]
    np.testing.assert_allclose(m["fn [Hz]"], [21.3, 57.9, 110.4], rtol=5e-4)  # the synthetic system's modes
    # bad per-channel settings are named errors, and nothing is written
    bad = tmp_path / "bad.csv"
    code, _, err = run(["frf", str(p), "--input", "hammer", "--impact", "--quantity", "a9=velocity", "--csv", str(bad)])
    assert code == 2 and "'a9' is not in the file" in err and not bad.exists()
    code, _, err = run(["frf", str(p), "--input", "hammer", "--impact", "--quantity", "a0=velocity", "--unit", "a0=g"])
    assert code == 2 and "'a0'" in err and "velocity" in err
    code, _, err = run(["frf", str(p), "--input", "hammer", "--impact", "--quantity", "speed"])
    assert code == 2 and "must be displacement, velocity, acceleration or force" in err


def test_model_help_documents_the_toml_format(capsys):
    from vibmeasure.cli import main
    with pytest.raises(SystemExit):
        main(["model", "--help"])
    text = capsys.readouterr().out
    for must in ('type = "sdof"', 'k = "40 N/mm"', "modal_zeta", "bc", "units:"):
        assert must in text


@pytest.mark.parametrize("argv", [["ringdown", "missing.csv", "--json"], ["spectrum", "missing.wav", "--json"]])
def test_json_errors_are_one_json_document(argv, tmp_path):
    """With --json, stdout is always one JSON document: on an error {"error", "exit_code"} (issue 49)."""
    import json
    code, out, err = run([argv[0], str(tmp_path / argv[1])] + argv[2:])
    assert code == 2 and "does not exist" in err
    doc = json.loads(out)
    assert doc["exit_code"] == 2 and "does not exist" in doc["error"]


def test_report_exits_1_when_an_input_was_not_analysed(tmp_path):
    """Issue 49: the report is written with the failed input's section, and the exit code says so."""
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n")
    code, _, err = run(["report", str(bad), "-o", str(tmp_path / "r.html")])
    assert code == 1 and "1 of 1 input(s) not analysed" in err and (tmp_path / "r.html").is_file()


def test_spectrum_leaves_out_a_time_column_as_ringdown_does(tmp_path):
    """Issue 49: a headerless two-column file (time, signal): `spectrum` analysed the time column too."""
    t = np.arange(4096) / 1000.0
    p = tmp_path / "two.csv"
    np.savetxt(p, np.c_[t, np.sin(2 * np.pi * 50 * t)], delimiter=",")
    import json
    for extra in ([], ["--fs", "1000"]):   # the reader takes the rising first column as the time base
        code, out, err = run(["spectrum", str(p), *extra, "--peaks", "1", "--json"])
        doc = json.loads(out)
        assert code == 0 and doc["channels"] == ["ch1"] and doc["peaks"]["ch1"][0]["freq_hz"] == pytest.approx(50, abs=0.3)
    code, out, err = run(["spectrum", str(p), "--fs", "500", "--json"])   # a rate the time column contradicts
    assert code == 2 and "contradicts" in json.loads(out)["error"]


def test_several_files_per_command_one_result_each(sample_dir, tmp_path):
    """Several files (or a quoted glob) on one command: with --json one array, a document per file in the
    order given (an error's document in its place), the worst exit code; each picture named after its file."""
    beam, three = sample_dir / "ringdown_beam.csv", sample_dir / "ringdown_3modes.h5"
    code, out, err = run(["ringdown", str(beam), str(tmp_path / "missing.csv"), str(three), "--json"])
    docs = json.loads(out)
    assert code == 2 and [d["file"] for d in docs] == [str(beam), str(tmp_path / "missing.csv"), str(three)]
    assert docs[1]["exit_code"] == 2 and "does not exist" in docs[1]["error"]
    single = json.loads(run(["ringdown", str(beam), "--json"])[1])
    assert docs[0]["modes"] == single["modes"]   # the same result as run alone
    for f in (beam, three):
        shutil.copy(f, tmp_path / f.name)
    code, out, err = run(["ringdown", str(tmp_path / "ringdown_*"), "--plot", str(tmp_path / "fit.png")])
    assert code == 0 and out.count("== ") == 2
    assert (tmp_path / "fit-ringdown_beam.png").is_file() and (tmp_path / "fit-ringdown_3modes.png").is_file()
    code, _, err = run(["ringdown", str(tmp_path / "nothing_*.csv")])
    assert code == 2 and "does not exist" in err
