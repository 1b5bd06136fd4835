"""The striker FMU: a rigid body whose motion under a held force is the
parabola x0 + v0 t + (g - F/m) t^2 / 2, standard-compliant, with the same
error handling and FMU state as the contact element (the same glue)."""

import math
import os
import pathlib
import shutil

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

from fmu_driver import Slave

ROOT = pathlib.Path(__file__).resolve().parent.parent
STRIKER = pathlib.Path(os.environ.get("STRIKER_FMU", ROOT / "build" / "striker.fmu"))


@pytest.fixture(scope="module")
def striker():
    md = read_model_description(str(STRIKER))
    folder = extract(str(STRIKER))
    made = []

    def make(start=True, **values):
        s = Slave(md, folder, start=start, **values)
        made.append(s)
        return s
    yield make
    for s in made:
        s.fmu.freeInstance()
    shutil.rmtree(folder, ignore_errors=True)


def test_striker_validates():
    assert validate_fmu(str(STRIKER)) == []


def test_motion_under_a_held_force_is_the_parabola(striker):
    m, g, x0, v0, F, H = 2.0, 9.81, -1e-3, 0.5, 3.0, 1e-4
    s = striker(m=m, g=g, x0=x0, v0=v0, F=F)
    a = g - F / m
    for n in range(1, 101):
        s.step(H)
        t = n * H
        # A sum of n exact parabola pieces: rounding only, at most n ulp of
        # the largest term (n eps/2 = 1.1e-14 of it at n = 100); measured
        # 2.3e-15 of it for x (x crosses 0 near t = 2 ms, so x's own size
        # is no scale) and 4.7e-15 for v.
        scale = max(abs(x0), abs(v0 * t), abs(0.5 * a * t * t))
        assert s.get("x") == pytest.approx(x0 + v0 * t + 0.5 * a * t * t, rel=0, abs=1e-14 * scale)
        assert s.get("v") == pytest.approx(v0 + a * t, rel=1e-14, abs=0)
    rates = s.fmu.getRealOutputDerivatives([6, 7], [1, 1])
    assert rates[0] == s.get("v") and rates[1] == a  # g - F/m: the same double expression


@pytest.mark.parametrize("name, value, says", [("m", 0.0, "m = 0"), ("m", -1.0, "m = -1"), ("F", math.nan, "F = nan"),
                                               ("g", math.inf, "g = inf"), ("v0", -math.inf, "v0 = -inf")])
def test_bad_values_are_refused(striker, name, value, says):
    s = striker(start=False)
    s.enter()
    with pytest.raises(FMICallException):
        s.set(**{name: value})
    assert says in s.last_error()
    s.fmu.exitInitializationMode()
    s.step(1e-5)
    assert math.isfinite(s.get("x"))


def test_striker_state_round_trip(striker):
    s = striker(F=100.0)
    s.step(1e-4)
    blob = s.fmu.serializeFMUstate(s.fmu.getFMUstate())
    s.step(1e-4)
    after = (s.get("x"), s.get("v"))
    s.fmu.setFMUstate(s.fmu.deSerializeFMUstate(blob))
    s.t -= 1e-4
    s.step(1e-4)
    assert (s.get("x"), s.get("v")) == after
