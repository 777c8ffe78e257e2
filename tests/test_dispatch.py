"""One rule decides which analysis a record gets (core.dispatch.analysis_for): the report and the
batch's "auto" task both use it."""

import warnings

import pytest

import vibmeasure as vm
from vibmeasure.core.dispatch import analysis_for


def test_a_record_is_analysed_by_what_it_holds():
    decay = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=4.0, seed=1)
    machine = vm.synth.machine(rpm=1797, duration=1.0, seed=1)            # meta["rpm"]
    hammer = vm.synth.hammer_test(fn=[21.3], zeta=[0.01], shapes=[[1.0]], fs=1024.0, seed=1)
    assert analysis_for(decay) == "ringdown"
    assert analysis_for(decay, rpm=1500.0) == "diagnose"                  # a declared speed makes it a machine
    assert analysis_for(decay, tach="tach") == "diagnose"
    assert analysis_for(machine) == "diagnose"
    assert analysis_for(hammer) == "modes"                               # a force channel wins
    assert analysis_for(hammer, rpm=1500.0) == "modes"
    with pytest.raises(vm.ParameterError, match="rec must be a vm.Record"):
        analysis_for("pump.h5")


def test_batch_auto_runs_each_file_by_its_content(tmp_path):
    vm.write(tmp_path / "decay.h5", vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, snr_db=40,
                                                        seed=2))
    vm.write(tmp_path / "pump.h5", vm.synth.machine(fault="unbalance", rpm=1797, duration=2.0, seed=3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = vm.batch([tmp_path / "decay.h5", tmp_path / "pump.h5"], task="auto", store=tmp_path / "s.h5")
    assert set(rep["status"]) == {"done"}, rep
    st = vm.Store(tmp_path / "s.h5")
    assert st.results("ringdown")["fn1_hz"].iloc[0] == pytest.approx(12.0, rel=1e-3)   # 40 dB: well inside 0.1 %
    assert st.results("diagnose")["top"].iloc[0] == "unbalance"
    with pytest.raises(vm.ParameterError, match="'auto'"):
        vm.batch([tmp_path / "decay.h5"], task="everything", store=tmp_path / "t.h5")
