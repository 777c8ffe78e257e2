import pytest
from hypothesis import given, strategies as st

import vibmeasure as vm
from vibmeasure.core import units


def test_g_is_standard_gravity():
    assert units.convert(1.0, "g", "m/s^2") == pytest.approx(9.80665, rel=0, abs=0)


def test_imperial_velocity_and_displacement():
    assert units.convert(1.0, "in/s", "mm/s") == pytest.approx(25.4, rel=1e-15)
    assert units.convert(1.0, "mil", "um") == pytest.approx(25.4, rel=1e-15)


@given(st.floats(-1e6, 1e6, allow_nan=False), st.sampled_from(["g", "mm/s^2", "in/s^2"]))
def test_round_trip(v, u):
    # a factor and its inverse: round-off only (2 ulp)
    back = units.convert(units.convert(v, u, "m/s^2"), "m/s^2", u)
    assert back == pytest.approx(v, rel=4e-16, abs=1e-300)


def test_aliases_normalise():
    assert units.normalize_unit("m/s2") == "m/s^2"
    assert units.quantity_of("ips") == "velocity"


def test_wrong_quantity_raises_unit_error():
    with pytest.raises(vm.UnitError, match="different quantities"):
        units.convert(1.0, "g", "mm/s")
    with pytest.raises(vm.UnitError, match="measures acceleration"):
        units.check_unit("velocity", "g")
    with pytest.raises(vm.UnitError, match="not known"):
        units.normalize_unit("furlong")


def test_integral_and_derivative_quantities():
    assert units.integral_quantity("acceleration") == "velocity"
    assert units.derivative_quantity("displacement") == "velocity"
    with pytest.raises(vm.ParameterError, match="cannot be integrated"):
        units.integral_quantity("displacement")
