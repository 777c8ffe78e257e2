"""Every public function, class and method of ``vm`` (``vm.__all__``), ``vm.models``, ``vm.plot`` and
``vm.synth`` carries a numpydoc docstring: a Parameters section naming each parameter with its type,
Returns (functions), Raises, and Examples that run (doctest, from the repository's root, where
sample_data/ is). Like python-control's docstring test."""

import doctest
import inspect
import re
import warnings
from pathlib import Path

import pytest

import vibmeasure as vm

ROOT = Path(__file__).resolve().parents[1]


def public_objects() -> dict:
    import vibmeasure.models as models
    import vibmeasure.plot as plot
    import vibmeasure.synth as synth
    out = {}
    for mod, prefix in ((vm, "vm"), (models, "vm.models"), (plot, "vm.plot"), (synth, "vm.synth")):
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name)
            if inspect.ismodule(obj) or not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if inspect.isclass(obj) and issubclass(obj, (Exception, Warning)):
                continue   # errors are documented by their one-line docstring
            out[f"{prefix}.{name}"] = obj
            if inspect.isclass(obj):   # its own methods and those it inherits from vibmeasure's mixins
                for meth, f in inspect.getmembers(obj, inspect.isfunction):
                    if not meth.startswith("_") and f.__module__.startswith("vibmeasure"):
                        out[f"{prefix}.{name}.{meth}"] = f
    return out


def _parameters(obj) -> list:
    target = obj.__init__ if inspect.isclass(obj) else obj
    try:
        sig = inspect.signature(target)
    except (TypeError, ValueError):
        return []
    return [p.name for p in sig.parameters.values()
            if p.name not in ("self", "cls") and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def shortfalls(name: str, obj) -> list:
    """What the docstring of ``obj`` lacks: missing sections and undocumented parameters."""
    doc = inspect.getdoc(obj) or ""
    missing = []
    params = _parameters(obj)
    section = "Attributes" if inspect.isclass(obj) and "Attributes\n----------" in doc else "Parameters"
    if params and f"{section}\n----------" not in doc and "Parameters\n----------" not in doc:
        missing.append("Parameters")
    documented = set()
    for line in doc.splitlines():
        m = re.match(r"^([\w*]+(?:\s*,\s*[\w*]+)*)\s*:\s*\S", line)
        if m:
            documented |= {n.strip() for n in m.group(1).split(",")}
    missing += [f"parameter {p}" for p in params if p not in documented]
    if inspect.isfunction(obj) and "Returns\n-------" not in doc and "Yields\n------" not in doc:
        missing.append("Returns")
    if "Raises\n------" not in doc:
        missing.append("Raises")
    if "Examples\n--------" not in doc or ">>>" not in doc:
        missing.append("Examples")
    return missing


def test_every_public_docstring_is_numpydoc():
    objects = public_objects()
    assert len(objects) >= 190   # the audit sees the whole public surface (192 names today)
    short = {name: shortfalls(name, obj) for name, obj in objects.items() if shortfalls(name, obj)}
    assert not short, short


@pytest.mark.parametrize("name", sorted(public_objects()))
def test_the_examples_run(name, monkeypatch, tmp_path):
    obj = public_objects()[name]
    monkeypatch.chdir(ROOT)
    import tempfile
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))   # the examples' scratch files go with the test
    import matplotlib
    matplotlib.use("Agg")
    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for test in finder.find(obj, name, globs={}):
            runner.run(test)
    assert runner.failures == 0, f"{name}: {runner.failures} example(s) failed (run with -s to see them)"


def _module_names() -> list:
    import pkgutil
    return sorted(m.name for m in pkgutil.walk_packages(vm.__path__, "vibmeasure.")
                  if ".cli" not in m.name and not m.name.endswith("__main__"))


def _covered() -> set:
    """The dotted names of the objects whose examples ``test_the_examples_run`` runs already."""
    return {f"{o.__module__}.{o.__qualname__}" for o in public_objects().values()}


@pytest.mark.parametrize("module", _module_names())
def test_every_modules_examples_run(module, monkeypatch, tmp_path):
    """The examples of the functions inside the package (the steps of a pipeline, the bearing test, the
    readers) run too: an example that no longer runs misleads whoever reads the code to fix it."""
    import importlib
    import tempfile

    import matplotlib
    matplotlib.use("Agg")
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    covered = _covered()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for test in doctest.DocTestFinder().find(importlib.import_module(module), module):
            if test.examples and test.name not in covered:
                runner.run(test)
    assert runner.failures == 0, f"{module}: {runner.failures} example(s) failed (run with -s to see them)"
