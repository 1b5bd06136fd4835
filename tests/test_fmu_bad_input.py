"""Bad input through fmpy: an error status and a log message that names the
variable and the value; the instance stays usable; no NaN reaches an output."""

import math

import pytest
from fmpy.fmi1 import FMICallException

REALS = ["v", "m", "R", "E_i", "nu_i", "E_s", "nu_s", "k", "c", "dt_max", "g", "gap0"]
OUTPUTS = ["F", "F_avg", "F_avg_next", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps", "semi_integral"]


def rejected(s, name, value, shown):
    """Setting name = value fails, says why, and keeps the old value."""
    before = s.get(name)
    with pytest.raises(FMICallException):
        s.set(**{name: value})
    message = s.last_error()
    assert name in message and shown in message, message
    assert s.get(name) == before


def assert_usable(s):
    """The instance still runs an impact and its outputs are finite."""
    s.fmu.exitInitializationMode()
    for _ in range(200):
        s.step(1e-5)
        for name in OUTPUTS:
            assert math.isfinite(s.get(name)), name
    assert s.get("eps") > 0.0


@pytest.mark.parametrize("name", REALS)
@pytest.mark.parametrize("value, shown", [(math.nan, "nan"), (math.inf, "inf"), (-math.inf, "-inf")])
def test_non_finite_reals_are_rejected(slave, name, value, shown):
    s = slave(start=False)
    s.enter()
    rejected(s, name, value, shown)
    assert_usable(s)


@pytest.mark.parametrize("name, value", [
    ("c", 0.0), ("c", -6080.0), ("k", -1.0), ("R", 0.0), ("R", -1e-3), ("dt_max", -1e-7),
    ("dt_max", -1e-7), ("m", -0.7437), ("E_i", 0.0), ("E_s", -1.0), ("nu_i", 0.7), ("nu_s", -1.5),
    ("gap0", -1e-3), ("law", 0), ("law", 4), ("scene", 0), ("scene", 3), ("g1_nodes", -5)])
def test_out_of_range_values_are_rejected(slave, name, value):
    s = slave(start=False)
    s.enter()
    rejected(s, name, value, f"{name} = {value:g}")
    assert_usable(s)


def test_drop_test_without_mass_is_refused_at_initialization(slave):
    s = slave(start=False, m=0.0)
    s.fmu.enterInitializationMode()
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    assert "m = 0" in s.last_error() and "drop test" in s.last_error()
    # Still in initialization mode: the master corrects the mass and goes on.
    s.set(m=0.5)
    s.fmu.exitInitializationMode()
    s.step(2e-3)
    assert s.get("eps") > 0.0


def test_driven_scene_takes_zero_mass(slave):
    s = slave(scene=2, m=0.0, v=0.1)
    s.step(1e-4)
    assert s.get("F") > 0.0


def test_input_nan_during_simulation_is_rejected(slave):
    s = slave(scene=2, m=0.0, v=0.1)
    s.step(1e-4)
    rejected(s, "v", math.nan, "nan")
    s.step(1e-4)
    assert math.isfinite(s.get("F")) and s.get("F") > 0.0


def test_unknown_value_references_are_errors(slave):
    s = slave()
    for call, args in [(s.fmu.getReal, ([999],)), (s.fmu.setReal, ([999], [1.0])),
                       (s.fmu.getInteger, ([13],)), (s.fmu.getBoolean, ([1],)),
                       (s.fmu.getString, ([1],))]:
        with pytest.raises(FMICallException):
            call(*args)
        assert "is not a" in s.last_error(), s.last_error()


def test_wrong_call_order_is_an_error_not_a_crash(slave):
    s = slave(start=False)
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-5)
    assert "illegal call sequence" in s.last_error()
    s.start()
    with pytest.raises(FMICallException):
        s.set(c=1000.0)  # a fixed parameter after initialization
    assert "c is a fixed parameter" in s.last_error()
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=1.0, communicationStepSize=1e-5)
    assert "does not match" in s.last_error()
    s.step(1e-5)  # still usable
    assert s.get("F") > 0.0


MATERIALS = {"R": 1e-2, "E_i": 70e9, "nu_i": 0.25, "E_s": 1.2e9, "nu_s": 0.35}


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_a_material_without_effect_warns_at_the_end_of_initialization(slave, name):
    """With k != 0, k wins: a material set away from its default changes
    nothing, so fmi2ExitInitializationMode says so (fmi2Warning, naming it
    and its value) and the simulation goes on with the given k."""
    s = slave(start=False, **{name: MATERIALS[name]})
    s.enter()
    assert s.fmu.exitInitializationMode() == 1  # fmi2Warning
    warnings = [m for status, category, m in s.log if status == 1]
    assert len(warnings) == 1 and f"{name} = {MATERIALS[name]:g}" in warnings[0], s.log
    assert "k = 3.299e+08" in warnings[0] and "no effect" in warnings[0]
    assert_stepping_matches_the_default(s)


def assert_stepping_matches_the_default(s):
    for _ in range(200):
        s.step(1e-5)
    assert s.get("eps") == pytest.approx(0.58606378, rel=1e-7, abs=0)  # the h20 default (README, "Two commands")


# A damper's parameter set while the other damper is selected, and what
# the warning must say: the value has no effect, and why.
UNUSED_DAMPER_VALUES = [
    ({"damper_order": 0.3}, "damper_order = 0.3", "damper = 1"),
    ({"c_alpha": 1e5}, "c_alpha = 100000", "damper = 1"),
    ({"memory": 1}, "memory = 1", "damper = 1"),
    ({"memory_tolerance": 1e-8}, "memory_tolerance = 1e-08", "damper = 1"),
    ({"damper": 2, "c": 5000.0}, "c = 5000", "damper = 2"),
    ({"damper": 2, "memory": 1, "memory_tolerance": 1e-8}, "memory_tolerance = 1e-08", "memory = 1"),
]


@pytest.mark.parametrize("values, named, because", UNUSED_DAMPER_VALUES)
def test_a_damper_value_without_effect_warns(slave, values, named, because):
    s = slave(start=False, **values)
    s.enter()
    assert s.fmu.exitInitializationMode() == 1  # fmi2Warning
    warnings = [m for status, category, m in s.log if status == 1]
    assert len(warnings) == 1 and named in warnings[0] and because in warnings[0], s.log
    assert "no effect" in warnings[0]


def test_no_warning_for_the_selected_dampers_own_values(slave):
    for values in ({"c": 5000.0}, {"damper": 2, "damper_order": 0.3, "c_alpha": 1e5, "memory_tolerance": 1e-8},
                   {"damper": 2, "memory": 1, "damper_order": 0.7}):
        s = slave(start=False, **values)
        s.enter()
        assert s.fmu.exitInitializationMode() == 0, values
        assert not [m for status, category, m in s.log if status == 1], s.log


def test_no_warning_with_k_0_or_default_materials(slave):
    for values in ({}, {"k": 0.0, "E_s": 1.2e9}):
        s = slave(start=False, **values)
        s.enter()
        assert s.fmu.exitInitializationMode() == 0
        assert not [m for status, category, m in s.log if status == 1], s.log
