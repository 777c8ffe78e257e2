"""The public contract: names, keyword-only options, docstrings, no printing, no matplotlib on import."""
import inspect
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import vibmeasure as vm

PUBLIC_FUNCS = [vm.read, vm.write, vm.ringdown, vm.ringdown_crb, vm.log_decrement, vm.hilbert_decay,
                vm.half_power, vm.synth.free_decay, vm.synth.coulomb_decay, vm.diagnose, vm.prewhiten,
                vm.remove_synchronous, vm.kurtogram, vm.band_ses]


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
        if p.parent.name == "cli":   # the command line's own package writes to the terminal
            continue
        for i, line in enumerate(p.read_text().splitlines(), 1):
            if re.match(r"\s*print\(", line):
                offenders.append(f"{p.name}:{i}")
    assert offenders == []


def _bad_input_cases():
    import numpy as np
    rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=1000.0, duration=3.0)
    frf = vm.synth.modal_frf(np.linspace(1, 50, 200), fn=[10.0], zeta=[0.02], shapes=[[1.0]])
    spec = vm.amplitude_spectrum(rec)
    return {
        "FRF.select index": (lambda: frf.select(outputs=5), "out of range"),
        "harmonic_family channel": (lambda: vm.harmonic_family(spec, 10.0, channel="nope"), "channel='nope'"),
        "sideband_family channel": (lambda: vm.sideband_family(spec, 10.0, 1.0, channel=7), "channel=7"),
        "fit_modes input": (lambda: vm.fit_modes(frf, band=(2, 40), input="zz"), "input='zz'"),
        "half_power output": (lambda: vm.half_power(frf, channel=3), "output=3"),
        "modal_crb residues": (lambda: vm.modal_crb(np.linspace(1, 50, 100), fn=[10.0], zeta=[0.02],
                                                    residues=np.ones((1, 2)), noise_std=[0.1]), "residues must be"),
        "update_sdof mode": (lambda: vm.models.update_sdof(vm.ringdown(rec), m=1.0, mode=5), "mode=5"),
        "read_spectrum missing": (lambda: vm.read_spectrum("no/such/file.lvm"), "does not exist"),
        "envelope order": (lambda: vm.envelope(rec, band=(100, 200), order=0), "order=0"),
        "Spectrum.channel": (lambda: spec.channel("nope"), "channel='nope'"),
    }


@pytest.mark.parametrize("name", sorted(_bad_input_cases()))
def test_bad_input_is_a_parameter_error_naming_the_argument(name):
    call, match = _bad_input_cases()[name]
    with pytest.raises(vm.ParameterError, match=match):
        call()


def test_new_public_functions_of_session_4_name_their_bad_arguments():
    # each refusal names the argument and its rule: no numpy/matplotlib error from deep inside
    import matplotlib
    matplotlib.use("Agg")
    from vibmeasure import plot as P
    from vibmeasure.signal.preprocess import extend
    H = dict(fn=[20.0], zeta=[0.01], shapes=[[1.0]], fs=1024.0)
    for kw, word in ((dict(peak_force=float("nan")), "peak_force"), (dict(peak_force="a"), "peak_force"),
                     (dict(noise=-1.0), "noise"), (dict(duration=0.1), "duration"), (dict(double_at="x"), "double_at"),
                     (dict(double_at=9.0), "double_at"), (dict(hits=[]), "hits"), (dict(quantity="jerk"), "quantity")):
        with pytest.raises(vm.ParameterError, match=word):
            vm.synth.hammer_test(**H, **kw)
    with pytest.raises(vm.ParameterError, match="finite"):
        extend(np.array([1.0, np.nan, 2.0, 3.0, 4.0]), 10)
    with pytest.raises(vm.ParameterError, match="n_ext"):
        extend(np.arange(10.0), 2.5)
    freq = np.arange(0, 50.0625, 0.0625)
    est = vm.fit_modes(vm.synth.modal_frf(freq, fn=[10.0, 30.0], zeta=[0.02, 0.02], shapes=[[1.0, 0.7]]), band=(2, 45))
    with pytest.raises(vm.ParameterError, match="freq must be a 1-D array of finite"):
        vm.synthesize_frf(est, [np.nan], residuals=True)
    with pytest.raises(vm.ParameterError, match="freq must be > 0"):
        vm.synthesize_frf(est, freq, residuals=True)
    spec = vm.psd(vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, snr_db=40, seed=2))
    with pytest.raises(vm.ParameterError, match="fmax"):
        P.plot_spectrum(spec, fmax="x")
    with pytest.raises(vm.ParameterError, match="db="):
        P.plot_spectrum(spec, db="yes")
    rec = vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, snr_db=40, seed=2)
    cmp = vm.compare(vm.ringdown(rec), vm.models.SDOF(m=1.0, k=(2 * np.pi * 12.0) ** 2, zeta=0.02))
    for bad in ("x", -1.0):
        with pytest.raises(vm.ParameterError, match="rtol_zeta"):
            P.plot_comparison(cmp, rtol_zeta=bad)
    import matplotlib.pyplot as plt
    plt.close("all")
