"""The user guide's examples run as written: every ```python block of docs/guide.md in order, in one
namespace, and every `vibmeasure ...` line of its ```bash blocks through the CLI, in a scratch folder
that sees sample_data/ and ../shared/ as the guide's reader does from the repository root."""

import contextlib
import io
import os
import re
import shlex
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
GUIDE = ROOT / "docs" / "guide.md"
BLOCK = re.compile(r"^```(python|bash)\n(.*?)^```", re.S | re.M)


def blocks(path):
    return [(m.group(1), m.group(2), path.read_text()[:m.start()].count("\n") + 1)
            for m in BLOCK.finditer(path.read_text())]


@pytest.fixture
def reader_folder(tmp_path, monkeypatch):
    work = tmp_path / "checkout"
    work.mkdir()
    (work / "sample_data").symlink_to(ROOT / "sample_data")
    (tmp_path / "shared").symlink_to(ROOT.parent / "shared")
    monkeypatch.chdir(work)
    return work


def test_the_guide_has_examples_of_every_job():
    kinds = [k for k, _, _ in blocks(GUIDE)]
    assert kinds.count("python") >= 20 and kinds.count("bash") >= 6
    text = GUIDE.read_text()
    for section in ("Ring-down", "FRFs and modes", "Models and comparison", "Machine diagnosis", "Fleet monitoring"):
        assert f"{section}" in text


def test_every_example_of_the_guide_runs(reader_folder):
    from vibmeasure.cli import main
    ns: dict = {"__name__": "guide"}
    for kind, code, line in blocks(GUIDE):
        if kind == "python":
            with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
                warnings.simplefilter("ignore")
                try:
                    exec(compile(code, f"{GUIDE.name}:{line}", "exec"), ns)
                except Exception as exc:  # name the block, not just the exec frame
                    raise AssertionError(f"docs/guide.md block at line {line} failed: {exc!r}") from exc
            continue
        for cmd in code.splitlines():
            cmd = cmd.split("#")[0].strip()
            if not cmd.startswith("vibmeasure "):
                continue
            out, err = io.StringIO(), io.StringIO()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                code_ = main(shlex.split(cmd)[1:], out=out, err=err)
            assert code_ == 0, f"docs/guide.md line {line}: {cmd!r} exited {code_}: {err.getvalue()[-500:]}"
    for picture in ("ringdown.png", "frf.png", "diagnosis.png", "trend.png", "srs.png"):
        assert (reader_folder / picture).stat().st_size > 10_000
    assert os.path.exists("beam-report.html")


def test_the_gallery_draws_every_plot_it_shows(tmp_path):
    # docs/make_gallery.py draws each picture of docs/gallery.md with the library's own plot calls
    import importlib.util
    spec = importlib.util.spec_from_file_location("make_gallery", ROOT / "docs" / "make_gallery.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        written = mod.draw(tmp_path)
    names = {p.name for p in written}
    assert names == set(mod.PICTURES)
    shown = set(re.findall(r"\]\(gallery/([\w.]+)\)", (ROOT / "docs" / "gallery.md").read_text()))
    assert shown == names
    for p in written:
        assert p.read_bytes()[:4] == b"\x89PNG" and p.stat().st_size > 8_000
    # the committed pictures are what the library draws now (RMS difference within 2 of 255 levels:
    # anti-aliasing noise passes, a moved label or a new colour bar does not)
    from matplotlib.testing.compare import compare_images
    from matplotlib.testing.exceptions import ImageComparisonFailure
    stale = []
    for p in written:
        try:
            if compare_images(str(ROOT / "docs" / "gallery" / p.name), str(p), tol=2) is not None:
                stale.append(p.name)
        except ImageComparisonFailure:   # another size
            stale.append(p.name)
    assert not stale, f"docs/gallery is stale: {stale}; run python docs/make_gallery.py"
    import vibmeasure.plot as P
    public = {n for n in dir(P) if n.startswith("plot_")}
    drawn = set(re.findall(r"\((plot_\w+)", " ".join(mod.PICTURES.values())))
    assert public <= drawn, f"plots missing from the gallery: {sorted(public - drawn)}"


README = ROOT / "README.md"


def test_every_example_of_the_readme_runs(reader_folder):
    """The README's tour runs as written (python blocks in one namespace, `vibmeasure ...` lines through
    the CLI), and the page stays a user's page: the two set-up commands first, at most 250 lines."""
    from vibmeasure.cli import main
    text = README.read_text()
    assert len(text.splitlines()) <= 250
    first = blocks(README)[0]
    assert first[0] == "bash" and first[1].splitlines() == [
        'python -m pip install -e . && vibmeasure demo', 'python -m pip install -e ".[test]" && python -m pytest']
    ns: dict = {"__name__": "readme"}
    for kind, code, line in blocks(README)[1:]:
        if kind == "python":
            with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
                warnings.simplefilter("ignore")
                try:
                    exec(compile(code, f"{README.name}:{line}", "exec"), ns)
                except Exception as exc:
                    raise AssertionError(f"README.md block at line {line} failed: {exc!r}") from exc
            continue
        for cmd in code.splitlines():
            cmd = cmd.split("#")[0].strip()
            if cmd.startswith("vibmeasure "):
                out, err = io.StringIO(), io.StringIO()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    rc = main(shlex.split(cmd)[1:], out=out, err=err)
                assert rc == 0, f"README.md line {line}: {cmd!r} exited {rc}: {err.getvalue()[-500:]}"
    assert ns["modes"].n_modes == 3 and ns["diag"].top == "bearing_outer_race"


def test_every_link_of_the_readme_and_docs_resolves():
    for page in [README, *sorted((ROOT / "docs").rglob("*.md")), ROOT / "CHANGELOG.md"]:
        for target in re.findall(r"\]\(([^)#:]+)\)", page.read_text()):
            if target.endswith(".png"):   # the gallery's pictures are drawn by docs/make_gallery.py
                continue
            assert (page.parent / target).exists(), f"{page.name}: link {target} does not resolve"
