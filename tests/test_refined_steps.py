"""A striker so light that the fixed steps are refined in contact (4000 in
the time the spring stops it, docs/model.md) is refused where those steps
cannot stop it, at once and naming m, v, their values and the rule, in the
library and in both FMUs, the instance staying usable. Two such inputs the
fuzzers found (tests/fuzz_regressions/slow-refined-*): a first indentation
v h that underflows to 0, so that the spring never acts and the contact
never ends (the steps ran to the 1e9-step limit, minutes of CPU); and
steps shorter than the clock's resolution at t = 6080 s. Every case runs in a
child process under a timeout, so that a case that takes the long way fails
instead of hanging the suite."""

import json
import re

import pytest

from child_process import child_results

# The fuzzers' two inputs: a driven proxy striker (fuzz-timeout-1) and a drop test (fuzz-timeout-2).
TINY = [dict(scene=2, m=7.32138302413571e-304, v=1.0674309471292458e-255),
        dict(scene=1, m=8.303894128978216e-275, v=8.4962870852480123e-314)]
UNDERFLOW = "below the normal doubles: never stopping it; raise m or v"
# m = 1e-14 kg at the default v: stopped in about 1.2e-9 s, refined steps of about 3e-13 s, shorter
# than four ulp of t = 6080 s (5.4e-12 s) but representable at t = 0.
LIGHT = dict(scene=2, m=1e-14)
CLOCK = "which do not advance the clock at t = 6080.0000000"  # in the contact that begins at 6080 s


def library_child():
    import fraccontact
    out = []
    for values in TINY:
        try:
            fraccontact.impact(t_end=1e-4, **values)
            out.append("")
        except ValueError as e:
            out.append(str(e))
    return out


def fmu_child(fmi):
    from test_fmu_work import Instance
    out = {"tiny": [], "usable": []}
    s = Instance(fmi)
    for values in TINY:  # refused at exitInitializationMode, where the FMU checks its inputs
        s.fmu.reset()
        try:
            s.start(**values)
            out["tiny"].append("")
        except Exception:  # fmpy's FMICallException on fmi2Error/fmi3Error
            out["tiny"].append(s.errors[-1])
        s.fmu.reset()
        s.start(scene=values["scene"])
        out["usable"].append(s.step(0.0, 1e-5))
    s = Instance(fmi, start_time=6080.0, **LIGHT)
    out["clock_taken"] = s.step(6080.0, 1e-4)
    out["clock_message"] = s.errors[-1] if s.errors else ""
    vr = [s.vars["m"].valueReference]
    (s.fmu.setReal if fmi == 2 else s.fmu.setFloat64)(vr, [0.7437])
    out["after"] = s.step(6080.0, 1e-4)
    return out


def run_child(which):
    """The child's results; 60 s for cases that take milliseconds: one that runs its
    steps to the 1e9-step limit (minutes) runs past that."""
    return child_results("test_refined_steps", which, 60,
                         f"{which}: a striker whose refined steps cannot stop it was not refused within 60 s")


def child(which):
    print(json.dumps(library_child() if which == "library" else fmu_child(int(which))))


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def fmu(request):
    return run_child(str(request.param))


def named(values, message):
    """Whether the message names m and v with their values (shortest round-trip: the same doubles)."""
    found = re.match(r"m = (\S+), v = (\S+) are invalid", message)
    return bool(found) and float(found[1]) == values["m"] and float(found[2]) == values["v"]


def test_the_library_refuses_a_first_indentation_that_underflows():
    for values, message in zip(TINY, run_child("library")):
        assert named(values, message) and UNDERFLOW in message, message


def test_the_fmus_refuse_a_first_indentation_that_underflows(fmu):
    for values, message in zip(TINY, fmu["tiny"]):
        assert named(values, message) and UNDERFLOW in message, message
    assert fmu["usable"] == [True, True]


def test_the_fmus_refuse_refined_steps_shorter_than_the_clock_resolves(fmu):
    assert not fmu["clock_taken"] and "m = 1e-14" in fmu["clock_message"] and CLOCK in fmu["clock_message"], fmu
    assert fmu["after"]  # the instance stays usable: a heavier striker steps on
