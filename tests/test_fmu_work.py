"""A communication step whose internal steps are known to exceed the FMU's
limit (1e9, about a minute of CPU) before the first of them is refused at
once, in both FMI versions, naming dt_max, its value and the rule, rather
than after running its 1e9 internal steps; the instance stays usable. The
FMUs run in a child process under a timeout, so that a step that takes the
long way fails the test instead of hanging it. A step of 1000 s whose free
flight is one exact step is no such step: it runs in about a millisecond."""

import json
import os
import pathlib
import time

import pytest

import fraccontact
from child_process import child_results
from conftest import FMU

FMU3 = pathlib.Path(os.environ.get("FRACCONTACT_FMU3", FMU.parent / "fraccontact-fmi3.fmu"))
V0 = 0.626418  # the default impact velocity
OUTPUTS = ["F", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps"]
LIMIT = "more than 1e+09"

# (name, parameters, the steps of H_lead before the refused one, its H, how the instance is used after it:
# "reset" and run again with dt_max = 0, or "step" on, as if the refused step had not been asked for).
# Every method whose internal steps in contact are bounded by dt_max: the G1 law's fixed steps from the
# start (gap0 = 0) and after a free flight (the step that holds the onset), the Hertz law's
# error-controlled steps capped by dt_max, the compressed springpot (whose kernel takes no dt_max below
# about 1e-16 s), a prescribed rate from its onset and in the middle of its contact; and the full G1
# history, whose steps sum over all before them (1e6 steps from the start: the work of 1.6e10).
CASES = [
    ("g1", dict(dt_max=1e-300), 0, 0.0, 1e-5, "reset"),
    ("g1-after-flight", dict(dt_max=1e-300, gap0=1e-3), 15, 1e-4, 1e-4, "reset"),
    ("hertz-tolerance", dict(dt_max=1e-300, law=2, tolerance=1e-6), 0, 0.0, 1e-5, "reset"),
    ("springpot", dict(dt_max=1e-16, damper=2), 0, 0.0, 1e-5, "reset"),
    ("driven", dict(dt_max=1e-300, scene=2, m=0.0, v=0.1), 0, 0.0, 1e-5, "reset"),
    ("driven-in-contact", dict(dt_max=1e-9, scene=2, m=0.0, v=0.1), 1, 1e-5, 10.0, "step"),
    ("g1-history", dict(dt_max=1e-7, damper=2, memory=1), 0, 0.0, 0.1, "step"),
]
NAMED = {"g1-history": "memory = 1 (the full G1 history) is invalid"}


class Instance:
    """The contact FMU of one FMI version through fmpy, by name, its error messages collected."""

    def __init__(self, fmi, start_time=0.0, **values):
        from fmpy import extract, read_model_description
        path = str(FMU if fmi == 2 else FMU3)
        md = read_model_description(path)
        self.fmi, self.values, self.start_time = fmi, values, start_time
        self.vars = {v.name: v for v in md.modelVariables}
        self.errors = []
        folder = extract(path)
        if fmi == 2:
            from fmpy import calloc, free
            from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                                   fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
            self.callbacks = fmi2CallbackFunctions()
            self.callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, cat, msg: self._log(status, msg))
            self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier="fraccontact")
            self.fmu.instantiate(callbacks=self.callbacks)
        else:
            from fmpy.fmi3 import FMU3Slave
            self.fmu = FMU3Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier="fraccontact")
            self.fmu.instantiate(logMessage=lambda env, status, cat, msg: self._log(status, msg))
        self.start(**values)

    def _log(self, status, message):
        if status >= 3:
            self.errors.append(message.decode())

    def start(self, **values):
        if self.fmi == 2:
            self.fmu.setupExperiment(startTime=self.start_time)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=self.start_time)
        for name, value in values.items():
            vr = [self.vars[name].valueReference]
            if self.vars[name].type in ("Real", "Float64"):
                (self.fmu.setReal if self.fmi == 2 else self.fmu.setFloat64)(vr, [float(value)])
            else:
                (self.fmu.setInteger if self.fmi == 2 else self.fmu.setInt32)(vr, [int(value)])
        self.fmu.exitInitializationMode()

    def get(self, name):
        vr = [self.vars[name].valueReference]
        return (self.fmu.getReal if self.fmi == 2 else self.fmu.getFloat64)(vr)[0]

    def step(self, t, H):
        """True if the step was taken, False if refused."""
        try:
            self.fmu.doStep(t, H)
            return True
        except Exception:  # fmpy's FMICallException on fmi2Error/fmi3Error
            return False


def outputs_after(instance, t, steps, H=1e-5):
    for n in range(steps):
        assert instance.step(t + n * H, H)
    return [instance.get(name) for name in OUTPUTS]


def child(fmi):
    """Each case's refusal, its time, and the instance's use after it; JSON on stdout."""
    results = {}
    for name, values, lead, H_lead, H, then in CASES:
        s = Instance(fmi, **values)
        t = 0.0
        for n in range(lead):
            assert s.step(t, H_lead), s.errors
            t += H_lead
        begin = time.process_time()
        taken = s.step(t, H)
        seconds = time.process_time() - begin
        result = dict(taken=taken, seconds=seconds, message=s.errors[-1] if s.errors else "", t=t)
        if then == "reset":  # a sane dt_max, and the run is a fresh instance's
            s.fmu.reset()
            s.start(**{**values, "dt_max": 0.0})
            fresh = Instance(fmi, **{**values, "dt_max": 0.0})
            result.update(after=outputs_after(s, 0.0, 300), fresh=outputs_after(fresh, 0.0, 300))
        else:  # the refused step changed nothing: the next is the fresh instance's
            fresh = Instance(fmi, **values)
            outputs_after(fresh, 0.0, lead, H_lead)
            result.update(after=outputs_after(s, t, 1), fresh=outputs_after(fresh, t, 1))
        results[name] = result
    print(json.dumps(results))


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def refusals(request):
    """The child's results; it is given 60 s for all the cases, which take seconds: any
    step that takes the long way (1e9 internal steps) runs past that."""
    return child_results("test_fmu_work", request.param, 60,
                         f"FMI {request.param}: a refused configuration's step did not return within 60 s")


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_a_step_beyond_the_step_limit_is_refused_at_once(refusals, case):
    name, values = case[:2]
    r = refusals[name]
    assert not r["taken"], r
    named = NAMED.get(name, f"dt_max = {values['dt_max']:g} is invalid")
    assert named in r["message"] and LIMIT in r["message"], r["message"]
    assert r["seconds"] < 0.05  # before any internal step: microseconds (the child's CPU time, whatever the load)
    assert r["after"] == r["fresh"]


def test_the_refused_step_after_a_flight_holds_the_onset(refusals):
    """gap0 = 1e-3 at v: the flight's steps are taken (one exact step each, and
    the prediction of the next is dropped, not computed), the one that
    holds the onset at gap0 / v is refused."""
    r = refusals["g1-after-flight"]
    assert r["t"] <= 1e-3 / V0 < r["t"] + 1e-4


# ---------------------------- a communication step of 1000 s (docs/numerics.md)

@pytest.mark.parametrize("v", [V0, -1.0])
def test_a_communication_step_of_1000_s(slave, v):
    """docs/numerics.md ("Sub-stepping"): free flight is one exact step, so a step of
    1000 s costs about a millisecond: the h20 impact's 13 161 contact steps
    and one flight step (the library's impact, to the bit), or with v = -1
    one flight step. It was refused (more than 1e9 steps of dt_max)."""
    s = slave(v=v)
    t0 = time.process_time()
    s.step(1000.0)
    cpu = time.process_time() - t0
    assert s.get("x") == pytest.approx(v * 1000.0, rel=1e-3, abs=0) if v < 0 else s.get("eps") > 0.5
    if v > 0:
        library = fraccontact.impact()
        assert s.get("eps") == library.eps and s.get("F_peak") == library.F_peak
    assert cpu < 5e-3  # about a millisecond (0.7 ms measured), with room for a loaded machine
