"""HTML reports and the demo: each input kind, bad inputs, and the demo report in a real browser
(headless Chromium from the system's package manager)."""

import os
import re
import shutil
import subprocess
import sys
import time
from html.parser import HTMLParser

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.reporting import demo


class _Page(HTMLParser):
    """Tags, attributes and text of a page; raises on nothing, records what a report must not hold."""

    def __init__(self):
        super().__init__()
        self.tags, self.text, self.external = [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        for k, v in attrs:
            if k in ("src", "href") and v and not v.startswith(("#", "data:")):
                self.external.append((tag, k, v))  # an <image href> in an SVG, a <link href>, a <script src>

    def handle_data(self, data):
        self.text.append(data)


def _parse(path):
    html = path.read_text(encoding="utf-8")
    page = _Page()
    page.feed(html)
    page.close()
    assert not page.external, f"the report loads from outside itself: {page.external[:3]}"
    assert "url(http" not in html and "@import" not in html
    return html, page, " ".join(page.text)


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("demo")
    t0 = time.perf_counter()
    res = demo(d)
    res["wall"] = time.perf_counter() - t0
    return d, res


def test_the_demo_report_holds_every_section_with_its_numbers(demo_dir):
    d, res = demo_dir
    assert res["wall"] < 60  # the budget on a 2-core machine
    html, page, text = _parse(d / "report.html")
    for title in ("Ring-down: ringdown_beam.h5", "FRF and modes: hammer_test.h5", "Machine diagnosis: pump_bearing.h5",
                  "Fleet trends: results.db", "Provenance"):
        assert title in text
    # the synthetic truths: beam 23.7 Hz / zeta 0.012; modes 31, 87, 165 Hz; outer-race fault; pump-3 alarm
    m = re.search(r"fn (\d+\.\d+) Hz, zeta (0\.\d+)", text)     # each to the digits its std supports
    assert abs(float(m[1]) - 23.7) < 0.005 and abs(float(m[2]) - 0.012) < 0.0005
    for f in ("31.0", "87.0", "165.0"):
        assert f in text.replace("30.99", "31.0").replace("86.99", "87.0")
    assert "bearing outer race" in text and "pump-3: alarm" in text
    assert page.tags.count("svg") >= 8  # ring-down, backbone, FRF, stabilisation, diagnosis, fleet trends
    assert vm.__version__ in text and len(re.findall(r"[0-9a-f]{64}", html)) >= 4  # input hashes


def test_a_report_of_each_kind_and_a_bad_file_listed(tmp_path):
    # fs / fn = 8.3 < 10: flagged resolution_limited, which the report must explain with what to do
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=100.0, duration=6.0, snr_db=40, seed=2)
    vm.write(tmp_path / "decay.csv", rec)
    (tmp_path / "broken.h5").write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 64)
    model = tmp_path / "m.toml"
    model.write_text('type = "sdof"\n[parameters]\nm = "1 kg"\nk = "5684.89 N/m"\nzeta = 0.02\n')  # fn = 12.0 Hz
    out = vm.report([tmp_path / "decay.csv", tmp_path / "broken.h5"], tmp_path / "r.html", model=model)
    html, page, text = _parse(out)
    assert "Ring-down: decay.csv" in text and "Comparison: decay.csv vs m.toml" in text
    assert "Not analysed:" in text and "broken.h5" in text  # listed with its error, the rest reported
    assert re.search(r"fn (12|12\.0\d*|11\.9\d*) Hz", text)  # 12.0 Hz to the 5 digits shown
    assert "resolution_limited" in text and "What to do:" in text and "record longer (finer lines) or sample faster" in text


SHARED = __import__("pathlib").Path(__file__).resolve().parents[2] / "shared" / "data"


def test_a_report_of_records_and_of_files_that_need_their_options(tmp_path):
    """The options a real file needs: the hammer test's force channel (--input) makes it FRFs and modes,
    not a ring-down; fs for a file without timing; channels chosen; a vm.Record reported as it is."""
    hammer = SHARED / "impact" / "case1.mat"
    assert hammer.is_file(), "../shared/data/impact/case1.mat is a development recording the tests read"
    out = vm.report([hammer], tmp_path / "h.html", input="Time_chan_1")
    _, _, text = _parse(out)
    assert "FRF and modes: case1.mat" in text and "Ring-down" not in text
    # a CSV of bare numbers (no time column) needs fs; a two-channel record reported on one channel
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=200.0, duration=6.0, snr_db=40, seed=2)
    np.savetxt(tmp_path / "bare.csv", rec.data[0])
    failures = []
    vm.report([tmp_path / "bare.csv"], tmp_path / "b.html", failures=failures)
    assert failures and "fs" in failures[0][1]                     # without fs: named as the missing option
    out = vm.report([tmp_path / "bare.csv"], tmp_path / "b.html", fs=200.0)
    assert re.search(r"fn (12|12\.0\d*|11\.9\d*) Hz", _parse(out)[2])
    two = vm.Record(np.vstack([rec.data[0], np.random.default_rng(1).normal(size=rec.n_samples)]), fs=200.0,
                    channels=["beam", "noise"], meta={"source": "beam test"})
    out = vm.report(two, tmp_path / "c.html", channels=["beam"])
    _, _, text = _parse(out)
    assert "Ring-down: beam test" in text and "channel beam" in text
    with pytest.raises(vm.ParameterError, match="fs= and unit= apply to files"):
        from vibmeasure.core.dispatch import load_input
        load_input(two, fs=100.0)
    failures = []
    vm.report([two], tmp_path / "d.html", input="hammer", failures=failures)
    assert "is not in this record" in failures[0][1]


def test_an_empty_store_and_bad_output_paths(tmp_path):
    with vm.Store(tmp_path / "s.h5", writable=True) as st:
        st.add_asset("a")
    out = vm.report([], tmp_path / "r.html", store=tmp_path / "s.h5")
    _, _, text = _parse(out)
    assert "no trend yet" in text and "fewer measurements than the baseline needs" in text
    with pytest.raises(vm.ParameterError, match="folder .* does not exist"):
        vm.report([], tmp_path / "missing" / "r.html", store=tmp_path / "s.h5")
    with pytest.raises(vm.ParameterError, match="nothing to report"):
        vm.report([], tmp_path / "r2.html")
    assert not (tmp_path / "r2.html").exists()


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        p = shutil.which(name)
        if p:
            return p
    if os.environ.get("VIBMEASURE_CI"):
        pytest.fail("CI must have Debian's chromium (.ci/run installs it with apt-get)")
    pytest.skip("no Chromium on this machine (outside CI): the browser test needs Debian's chromium package")


def _dom(browser, url, width, height):
    common = [browser, "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
              f"--window-size={width},{height}", "--virtual-time-budget=5000", "--enable-logging=stderr", "--v=0"]
    dom = subprocess.run(common + ["--dump-dom", url], capture_output=True, text=True, timeout=120)
    assert dom.returncode == 0, dom.stderr[-2000:]
    return common, dom


def _attr(html, name):
    return re.search(rf'{name}="([^"]*)"', html).group(1)


def test_the_demo_report_renders_in_a_real_browser(demo_dir, tmp_path):
    """The demo and a report of real recordings (a CWRU diagnosis, a hammer test) in headless Chromium at a
    desktop (1280 px) and a phone (390 px) width: every picture rendered, no console error, and no table,
    figure or paragraph wider than the page (the page measures itself: getBoundingClientRect against the
    body's content box, scrollWidth against clientWidth)."""
    d, _ = demo_dir
    browser = _chromium()
    real = vm.report([SHARED / "cwru" / "IR007_0.mat", SHARED / "impact" / "case1.mat"], tmp_path / "real.html")
    hammer = vm.report([SHARED / "impact" / "case1.mat"], tmp_path / "hammer.html", input="Time_chan_1")
    doms = {}
    for page, min_fig in ((d / "report.html", 8), (real, 2), (hammer, 2)):
        url = page.resolve().as_uri()
        for width, height in ((1280, 900), (390, 844)):
            common, dom = doms[page, width] = _dom(browser, url, width, height)
            n_fig, n_ok = int(_attr(dom.stdout, "data-figures")), int(_attr(dom.stdout, "data-figures-rendered"))
            assert n_fig >= min_fig and n_ok == n_fig, (page.name, width)   # every picture has a size
            assert _attr(dom.stdout, "data-overflow") == "0", (page.name, width, _attr(dom.stdout, "data-overflow-what"))
            console = [l for l in dom.stderr.splitlines() if "CONSOLE" in l or "Uncaught" in l]
            assert not console, console  # no console errors (a script error, a resource refused)
    common, dom = doms[d / "report.html", 390]
    assert re.search(r"fn 23\.(7|69\d*)", dom.stdout) and "bearing outer race" in dom.stdout
    shot = tmp_path / "report.png"
    r = subprocess.run(common + [f"--screenshot={shot}", (d / "report.html").resolve().as_uri()],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and shot.stat().st_size > 20_000


def test_vibmeasure_demo_command(tmp_path, demo_dir):
    # the command in a folder a first demo filled (the module's demo, copied): its inputs are reused and
    # its stored results skipped, and the report is written again. The README's first command, run by
    # .ci/run on a fresh clone, is the command in an empty folder
    shutil.copytree(demo_dir[0], tmp_path / "d")
    (tmp_path / "d" / "report.html").unlink()
    r = subprocess.run([sys.executable, "-m", "vibmeasure.cli", "demo", "--out", str(tmp_path / "d")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-1500:]
    assert "report:" in r.stdout and (tmp_path / "d" / "report.html").stat().st_size > 100_000
    assert (tmp_path / "d" / "results.db").exists() and "synthesising" not in r.stderr
    assert np.isfinite(float(re.search(r"done in (\d+) s", r.stdout).group(1)))


def test_results_computed_already_are_reported_as_they_are(tmp_path):
    """vm.report takes results (issue 49): an estimate alone gives its tables; paired with its source it
    also gets the figures that need the data; nothing is analysed again (the numbers are the result's)."""
    import warnings
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=100.0, duration=6.0, snr_db=40, seed=2)
    rec = vm.Record(rec.data, rec.fs, channels=rec.channels, meta={"source": "beam"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.ringdown(rec)
    freq = np.arange(0, 50.0625, 0.0625)
    frf = vm.synth.modal_frf(freq, fn=[10.0, 30.0], zeta=[0.02, 0.02], shapes=[[1.0, 0.7]])
    modes = vm.fit_modes(frf, band=(2, 45))
    cmp = vm.compare(est, vm.models.SDOF(m=1.0, k=5684.89, zeta=0.02))
    failures = []
    out = vm.report([(rec, est), est, (frf, modes), cmp, (frf, est)], tmp_path / "given.html", failures=failures)
    html, page, text = _parse(out)
    titles = re.findall(r"<h2>(.*?)</h2>", html)
    assert titles[:4] == ["Ring-down: beam", "Ring-down: ModalEstimate (input 2)", "FRF and modes: FRF dof0/dof0",
                          "Comparison: Comparison (input 4)"]
    assert "an FRF pairs with a fit_modes estimate" in failures[0][1]   # a pair that cannot belong together
    # the record's figure only with the record (ring-down and residual), the FRF's only with the FRF
    assert html.count("record, fitted decay and envelope") == 1 and html.count("FRF magnitude, phase") == 1
    assert html.count("damping and frequency versus amplitude") == 2    # the backbone needs the estimate only
    assert html.count("<svg") == 2 + 1 + 2 + 1
    shown = re.search(r"fn ([\d.]+) Hz, zeta ([\d.]+)", text)
    assert float(shown[1]) == pytest.approx(est.fn[0], rel=1e-4)        # the result's own number, rounded
    assert "given as a result (ml)" in text and "given as a result (fit_modes)" in text


def test_a_ringdown_plot_and_its_report_show_the_same_flags(tmp_path):
    """The flags in the picture's title are the report's flag list: the record's and each mode's, once
    each, the informational noise_floor in neither (issue 49)."""
    import warnings
    import matplotlib.pyplot as plt
    from vibmeasure.core.results._common import shown_flags
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=100.0, duration=6.0, snr_db=40, seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vm.QualityWarning)
        est = vm.ringdown(rec)
    flags = shown_flags(est.flags, est.mode_flags)
    assert "resolution_limited" in flags and "noise_floor" not in flags   # fs/fn = 8.3: flagged
    title = vm.plot.plot_ringdown(rec, est).panels[0].get_title()
    plt.close("all")
    assert title.split("flags: ")[1].split(", ") == flags
    html = vm.report([(rec, est)], tmp_path / "f.html").read_text(encoding="utf-8")
    assert re.findall(r'<div class="flag"><strong>(\w+)</strong>', html) == flags


def test_a_backbone_model_that_does_not_fit_prints_no_parameter():
    # a model that fails its goodness-of-fit test has NaN parameters: the report says so and why, and
    # prints no number from it; a model that fits lists each parameter with its std
    from vibmeasure.reporting.sections import _backbone_model_table
    t = _backbone_model_table({"fits": False, "reason": "damping chi-square 240 (limit 9.2)"})
    assert t["rows"] == [] and "damping chi-square 240" in t["caption"] and "No weakly nonlinear model" in t["caption"]
    ok = {"fits": True, "fn0_hz": 10.0, "fn0_std_hz": 0.0012, "k3_over_k": 0.05, "k3_over_k_std": 0.0031,
          "zeta_viscous": 0.0104, "zeta_viscous_std": 0.00021, "friction_term": 1e-5, "friction_term_std": 2e-5,
          "quadratic_term": 0.0, "quadratic_term_std": 1e-3}
    rows = _backbone_model_table(ok, "mm")["rows"]
    assert rows[0][1:] == ["10.0000", "0.0012"] and rows[2][1:] == ["0.01040", "0.00021"]
    assert rows[1][0] == "cubic stiffness k3/k [1/mm^2]" and rows[3][0] == "friction term [mm]"
