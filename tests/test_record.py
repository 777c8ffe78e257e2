import numpy as np
import pytest

import vibmeasure as vm


def test_from_array_and_shape():
    x = np.arange(10.0)
    r = vm.Record.from_array(x, fs=100.0, quantity="acceleration", unit="g", name="acc")
    assert r.data.shape == (1, 10)
    assert r.n_channels == 1 and r.n_samples == 10
    assert r.duration == pytest.approx(0.1)
    assert r.channels[0] == vm.Channel("acc", "acceleration", "g")
    assert r.history == ("from_array",)
    np.testing.assert_array_equal(r.time, np.arange(10) / 100.0)


def test_a_unit_names_its_quantity():
    # unit="g" alone is an acceleration (as vm.read and the CLI take it); a unit of another quantity given
    # with a quantity is still refused, and no unit leaves the quantity unknown
    assert vm.Record.from_array(np.ones(4), fs=1.0, unit="g").channels[0].quantity == "acceleration"
    assert vm.Channel("v", unit="mm/s").quantity == "velocity"
    assert vm.Record.from_array(np.ones(4), fs=1.0).channels[0].quantity == "unknown"
    with pytest.raises(vm.ParameterError, match="measures acceleration"):
        vm.Channel("x", "velocity", "g")


def test_immutable_and_copied():
    x = np.zeros(5)
    r = vm.Record.from_array(x, fs=1.0)
    x[0] = 1.0
    assert r.data[0, 0] == 0.0  # the record owns its samples
    with pytest.raises(ValueError):
        r.data[0, 0] = 2.0
    with pytest.raises(AttributeError):
        r.fs = 3.0


def test_multichannel_selection_and_history():
    d = np.vstack([np.ones(4), 2 * np.ones(4)])
    r = vm.Record(d, fs=10.0, channels=[vm.Channel("hammer", "force", "N"), vm.Channel("acc1", "acceleration", "m/s^2")])
    a = r["acc1"]
    assert a.names == ["acc1"]
    np.testing.assert_array_equal(a.data[0], 2.0)
    assert a.history[-1].startswith("select")
    assert r.index("hammer") == 0
    with pytest.raises(vm.ParameterError, match="'acc2' is not in this record"):
        r.select("acc2")


@pytest.mark.parametrize("fs", [0.0, -1.0, np.nan, np.inf, "fast"])
def test_bad_fs(fs):
    with pytest.raises(vm.ParameterError, match="fs="):
        vm.Record(np.zeros(3), fs=fs)


def test_bad_channels():
    with pytest.raises(vm.ParameterError, match="2 channels"):
        vm.Record(np.zeros((2, 3)), fs=1.0, channels=[vm.Channel("a")])
    with pytest.raises(vm.ParameterError, match="unique"):
        vm.Record(np.zeros((2, 3)), fs=1.0, channels=[vm.Channel("a"), vm.Channel("a")])
    with pytest.raises(vm.UnitError):
        vm.Channel("v", "velocity", "g")
    with pytest.raises(vm.ParameterError, match="real numbers"):
        vm.Record(np.zeros(3, complex), fs=1.0)


def test_to_unit_converts_and_records():
    r = vm.Record.from_array(np.array([1.0, -2.0]), fs=1.0, quantity="acceleration", unit="g")
    m = r.to_unit("m/s^2")
    np.testing.assert_allclose(m.data[0], [9.80665, -19.6133], rtol=1e-15)
    assert m.channels[0].unit == "m/s^2"
    assert "to_unit" in m.history[-1]
    with pytest.raises(vm.ParameterError, match="no channel of this record can be converted"):
        r.to_unit("mm/s")


def test_slice_time():
    r = vm.Record.from_array(np.arange(100.0), fs=10.0)
    s = r.slice_time(2.0, 3.0)
    assert s.t0 == pytest.approx(2.0)
    assert s.n_samples == 10 and s.data[0, 0] == 20.0
    with pytest.raises(vm.ParameterError, match="select no samples"):
        r.slice_time(20.0, 30.0)
