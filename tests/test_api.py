"""The public contract: names, keyword-only options, docstrings, no printing, no matplotlib on import."""
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

import vibmeasure as vm

PUBLIC_FUNCS = [vm.read, vm.write, vm.ringdown, vm.ringdown_crb, vm.log_decrement, vm.hilbert_decay,
                vm.half_power, vm.synth.free_decay, vm.synth.coulomb_decay]


def test_contract_names_exist():
    for name in ["read", "write", "Record", "Channel", "ModalEstimate", "ringdown", "log_decrement",
                 "ParameterError", "FitError", "QualityWarning", "UnitError", "VibMeasureError"]:
        assert hasattr(vm, name), name
    assert issubclass(vm.ParameterError, ValueError) and issubclass(vm.FitError, RuntimeError)


@pytest.mark.parametrize("fn", PUBLIC_FUNCS, ids=lambda f: f.__name__)
def test_options_after_data_are_keyword_only_and_documented(fn):
    params = list(inspect.signature(fn).parameters.values())
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    assert len(positional) <= 2  # the data (and for write, the path)
    assert not any(p.kind == p.VAR_KEYWORD for p in params)  # no **kwargs sinks
    assert fn.__doc__ and len(fn.__doc__.strip()) > 40


def test_import_does_not_load_matplotlib():
    code = "import sys, vibmeasure; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_library_never_prints():
    root = Path(vm.__file__).parent
    offenders = []
    for p in root.rglob("*.py"):
        if p.name == "cli.py":
            continue
        for i, line in enumerate(p.read_text().splitlines(), 1):
            if re.match(r"\s*print\(", line):
                offenders.append(f"{p.name}:{i}")
    assert offenders == []
