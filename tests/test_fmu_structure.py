"""modelDescription.xml tells the truth: the ModelStructure's outputs and
initial unknowns with their dependencies, checked by perturbing every known
and watching what moves, and the capability flags, checked by using them."""

import pytest
from fmpy.fmi1 import FMICallException


def structure(md):
    index = {i + 1: v for i, v in enumerate(md.modelVariables)}
    deps = lambda unknowns: {u.variable.name: {d.name for d in (u.dependencies or [])} for u in unknowns}
    return index, deps(md.outputs), deps(md.initialUnknowns)


def knowns(md):
    return [v for v in md.modelVariables if v.causality in ("input", "parameter")]


def perturbed(v):
    """A different valid value for the known."""
    if v.type == "Integer":
        return {"law": 2, "g1_nodes": 5, "scene": 2, "damper": 2, "memory": 1, "coupling": 2}[v.name]
    start = float(v.start)
    if v.name == "memory_tolerance":
        return start * 10.0
    if v.name == "tolerance":
        return 1e-6
    return start * 1.5 + 0.1 if v.name not in ("nu_i", "nu_s") else start * 0.5


def test_outputs_and_initial_unknowns_are_every_output(model_description):
    """... and the initial unknowns Model Exchange's state derivatives too."""
    outputs = {v.name for v in model_description.modelVariables if v.causality == "output"}
    derivatives = {v.name for v in model_description.modelVariables if v.derivative is not None}
    _, out_deps, init_deps = structure(model_description)
    assert set(out_deps) == outputs and set(init_deps) == outputs | derivatives
    assert {u.variable.name for u in model_description.derivatives} == derivatives


def test_initial_unknowns_depend_on_exactly_the_declared_knowns(slave, model_description):
    _, _, declared = structure(model_description)
    outputs = sorted(declared)
    base = slave(start=False)
    base.enter()
    before = {name: base.get(name) for name in outputs}
    found = {name: set() for name in outputs}
    for known in knowns(model_description):
        s = slave(start=False)
        s.enter()
        s.set(**{known.name: perturbed(known)})
        for name in outputs:
            if s.get(name) != before[name]:
                found[name].add(known.name)
    assert found == declared


def test_outputs_have_no_direct_feedthrough(slave, model_description):
    """No output declares an input (Model Exchange's outputs declare the states they read, which
    are no knowns of co-simulation), and after a step, setting the inputs changes no output until
    the next step."""
    _, declared, _ = structure(model_description)
    inputs = {v.name for v in model_description.modelVariables if v.causality == "input"}
    assert inputs and all(not d & inputs for d in declared.values())
    s = slave(scene=2, m=0.0, v=0.5)
    s.step(1e-4)
    before = {name: s.get(name) for name in declared}
    s.set(v=0.9, m=0.3)
    assert {name: s.get(name) for name in declared} == before


def test_capability_flags_match_the_code(slave, model_description):
    cs = model_description.coSimulation
    s = slave(scene=2, m=0.0, v=0.3)
    assert cs.canHandleVariableCommunicationStepSize
    for H in (1e-6, 3.7e-5, 1e-4, 2.2e-7):             # any step size, no error
        s.step(H)
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    s.fmu.deSerializeFMUstate(s.fmu.serializeFMUstate(s.fmu.getFMUstate()))
    assert cs.canInterpolateInputs
    s.fmu.setRealInputDerivatives([1], [1], [10.0])
    assert cs.maxOutputDerivativeOrder == 1
    s.fmu.getRealOutputDerivatives([13], [1])
    with pytest.raises(FMICallException):
        s.fmu.getRealOutputDerivatives([13], [2])
    assert not cs.providesDirectionalDerivative
    with pytest.raises(FMICallException):
        s.fmu.getDirectionalDerivative([13], [1], [1.0])
    assert not cs.canRunAsynchronuously
    with pytest.raises(FMICallException):
        s.fmu.cancelStep()
    assert not cs.canBeInstantiatedOnlyOncePerProcess  # many instances: tests/test_fmi2.c


def test_last_successful_time_and_terminated_status(slave):
    from fmpy.fmi2 import fmi2LastSuccessfulTime, fmi2Terminated
    s = slave()
    s.step(1e-5)
    s.step(2e-5)
    # fmi2DoStep lands exactly on the communication point, t + H as the
    # master adds it (1e-5 + 2e-5 = 3.0000000000000004e-05 in doubles)
    assert s.fmu.getRealStatus(fmi2LastSuccessfulTime) == 1e-5 + 2e-5
    assert s.fmu.getBooleanStatus(fmi2Terminated) == 0


def test_log_messages_carry_the_instance_name(slave):
    s = slave(start=False)
    s.enter()
    with pytest.raises(FMICallException):
        s.set(c=-1.0)
    assert s.log[-1][1] == "logStatusError" and "c = -1" in s.log[-1][2]
    assert s.log_names == ["test"] * len(s.log_names) and s.log_names
