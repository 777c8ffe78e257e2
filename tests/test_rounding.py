"""Numbers for people: one rounding rule (the std to two significant digits, the value to the std's
last decimal, JCGM 100:2008 7.2.6), used alike by the report, the command line and the results' repr."""

import io
import re

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.core.rounding import band, plain, with_std


@pytest.mark.parametrize("value, std, expected", [
    (0.0123456, 1.234e-5, ("0.012346", "0.000012")),     # the "0.012 +- 1e-05" case, written out
    (24.000123, 0.00029, ("24.00012", "0.00029")),       # never "24 +- 0.00029"
    (23.70123, 0.0045, ("23.7012", "0.0045")),
    (1234.5, 56.0, ("1235", "56")),                      # half away from zero, not to even
    (-1234.5, 56.0, ("-1235", "56")),
    (123456.0, 5600.0, ("123500", "5600")),
    (-1e-5, 0.01, ("0.000", "0.010")),                    # no "-0"
    (0.0005, 0.002, ("0.0005", "0.0020")),               # a std larger than the value keeps both visible
    (2.5e-7, 3.1e-9, ("2.500e-07", "0.031e-07")),        # tiny: one shared power of ten
    (3.0e8, 2.0e3, ("3.000000e+08", "0.000020e+08")),
])
def test_a_value_is_rounded_to_its_std(value, std, expected):
    assert with_std(value, std) == expected


def test_a_value_without_a_usable_std_keeps_its_digits():
    assert with_std(23.70123456, float("nan")) == ("23.7012", "n/a")
    assert with_std(23.70123456, 0.0) == ("23.7012", "n/a")
    assert with_std(float("inf"), 0.1) == ("n/a", "0.1")
    assert plain(-0.0) == "0" and plain(None) == "n/a" and plain(1.0e-20, 3) == "1e-20"
    assert band(1.01111, 819.2) == "1.011-819.2"


def test_repr_report_and_command_line_round_alike(tmp_path):
    """The same estimate reads the same everywhere: ModalEstimate's repr, the CLI table and the report."""
    est = vm.ModalEstimate(fn=[23.699487], zeta=[0.01200613], fn_std=[0.000342], zeta_std=[1.43e-5])
    text = repr(est)
    assert "fn=23.69949±0.00034 Hz" in text and "zeta=0.012006±0.000014" in text
    from vibmeasure.cli._common import mode_row
    row = mode_row(0, 23.699487, 0.000342, 0.01200613, 1.43e-5, ("few_cycles",))
    assert re.split(r"\s+", row.strip()) == ["1", "23.69949", "0.00034", "0.012006", "0.000014", "few_cycles"]
    rec = vm.synth.free_decay(fn=23.7, zeta=0.012, fs=1000.0, duration=8.0, snr_db=40, seed=3)
    fit = vm.ringdown(rec)
    out = vm.report([rec], tmp_path / "r.html")
    html = out.read_text()
    fn_s, fn_std_s = with_std(fit.fn[0], fit.fn_std[0])
    assert f">{fn_s}</td>" in html and f">{fn_std_s}</td>" in html
    from vibmeasure.cli import main
    rec_path = tmp_path / "d.csv"
    vm.write(rec_path, rec)
    buf = io.StringIO()
    assert main(["ringdown", str(rec_path)], out=buf, err=io.StringIO()) == 0
    assert fn_s in buf.getvalue() and fn_std_s in buf.getvalue()
    assert np.isfinite(fit.fn_std[0])
