"""A dashpot far softer than the spring (c -> 0) lets x2 follow the striker:
the force tends to c v and x1 to (c v / k)^(1/n), after a transient of the
relaxation time c / k'. The error-controlled steps (ESDIRK 5(4), L-stable)
take long steps once it is over; they collapsed to about x1 / v instead (the
error of x2, of the order of the force's relative error times x2's travel,
was set against the tiny indentation), and `fraccontact-solve --c 1e-300
--law 2 --tolerance 1e-5` ran for hours. Where the spring could carry c v only
as a denormal x1^n = c v / k (the fuzzers' FMU input, c = 5.8e-308:
tests/fuzz_regressions/slow-soft-dashpot.bin) the force has few digits, and
the input is refused up front, naming c, its value and the rule, in the
library and in both FMUs, the instance staying usable. Every case runs in a
child process under a timeout, so that a case that takes the long way fails
instead of hanging the suite."""

import json
import pathlib
import re
import subprocess
import sys

import pytest

TESTS = pathlib.Path(__file__).resolve().parent
CONTROLLED = dict(law=2, tolerance=1e-5)
V, K = 0.626418, 329900000.0  # the h20 defaults: v and the spring's k (n = 1.5)
# Soft dashpots whose c v / k is a normal double, down to near the limit (c v / k = DBL_MIN at c = 1.17e-299).
SOFT = [1e-60, 1e-200, 1.2e-299]
# c v / k below the normal doubles: the reported solver input and the fuzzers' FMU input.
TOO_SOFT = [1e-300, 5.8e-308]
RULE = "below the smallest normal double"
T_END = 1e-3
# At most this many internal steps for 1 ms of contact: the measured runs take 77 to 311 (the
# controller grows the steps 5-fold from the onset's, about 1e-47 to 1e-200 s, to the 1e-3 s
# left); the collapsed steps of about x1 / v took more than 1e30.
MAX_STEPS = 1000


def library_child():
    import fraccontact
    out = {"soft": [], "too_soft": []}
    for c in SOFT:
        r = fraccontact.impact(c=c, t_end=T_END, **CONTROLLED)
        out["soft"].append(dict(steps=r.steps, x1=r.end.x1, F=r.end.F_peak, x=r.end.x))
    for c in TOO_SOFT:
        try:
            fraccontact.impact(c=c, t_end=T_END, **CONTROLLED)
            out["too_soft"].append("")
        except ValueError as e:
            out["too_soft"].append(str(e))
    return out


def fmu_child(fmi):
    from test_fmu_work import Instance
    out = {"soft": [], "too_soft": [], "usable": []}
    s = Instance(fmi, **CONTROLLED)
    for c in SOFT:
        s.fmu.reset()
        s.start(c=c, **CONTROLLED)
        taken = s.step(0.0, T_END)
        out["soft"].append(dict(taken=taken, x1=s.get("x1"), F=s.get("F")))
    for c in TOO_SOFT:  # refused at exitInitializationMode, where the FMU checks its inputs
        s.fmu.reset()
        try:
            s.start(c=c, **CONTROLLED)
            out["too_soft"].append("")
        except Exception:  # fmpy's FMICallException on fmi2Error/fmi3Error
            out["too_soft"].append(s.errors[-1])
        s.fmu.reset()
        s.start(**CONTROLLED)
        out["usable"].append(s.step(0.0, 1e-5))
    return out


def run_child(which):
    """The child's results; 30 s for cases that take milliseconds: steps collapsed to x1 / v
    run for hours."""
    code = (f"import sys; sys.path.insert(0, {str(TESTS)!r}); import test_soft_dashpot; "
            f"test_soft_dashpot.child({which!r})")
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{which}: a soft dashpot's run did not finish within 30 s")
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def child(which):
    print(json.dumps(library_child() if which == "library" else fmu_child(int(which))))


@pytest.fixture(scope="module")
def library():
    return run_child("library")


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def fmu(request):
    return run_child(str(request.param))


def quasi_static(c):
    """The relaxed contact of a dashpot c at the striker's speed: force c v at x1 = (c v / k)^(2/3)."""
    return c * V, (c * V / K) ** (2.0 / 3.0)


def named(c, message):
    """Whether the message names c with its value (shortest round-trip: the same double) and the rule."""
    found = re.match(r"c = (\S+) is invalid", message)
    return bool(found) and float(found[1]) == c and RULE in message


def test_a_soft_dashpot_takes_long_steps_to_its_closed_form(library):
    for c, r in zip(SOFT, library["soft"]):
        F, x1 = quasi_static(c)
        assert r["steps"] < MAX_STEPS, (c, r)
        # The striker's speed changes by c v t / m, below rounding: F and x are c v and v t to
        # rounding (measured 7e-16); x1 is the stiff stage's root to rounding through the 2/3
        # power (measured 2.6e-14), rel 1e-13 its bound.
        assert r["F"] == pytest.approx(F, rel=1e-14, abs=0), c
        assert r["x"] == pytest.approx(V * T_END, rel=1e-14, abs=0), c
        assert r["x1"] == pytest.approx(x1, rel=1e-13, abs=0), c


def test_the_library_refuses_a_dashpot_the_spring_carries_only_as_a_denormal(library):
    for c, message in zip(TOO_SOFT, library["too_soft"]):
        assert named(c, message), message


def test_the_fmus_step_a_soft_dashpot_to_its_closed_form(fmu):
    for c, r in zip(SOFT, fmu["soft"]):
        F, x1 = quasi_static(c)
        assert r["taken"], (c, r)
        # as in the library's test above: F to rounding, x1 the stage root through the 2/3 power
        assert r["F"] == pytest.approx(F, rel=1e-14, abs=0), c
        assert r["x1"] == pytest.approx(x1, rel=1e-13, abs=0), c


def test_the_fmus_refuse_a_dashpot_the_spring_carries_only_as_a_denormal(fmu):
    for c, message in zip(TOO_SOFT, fmu["too_soft"]):
        assert named(c, message), message
    assert fmu["usable"] == [True, True]
