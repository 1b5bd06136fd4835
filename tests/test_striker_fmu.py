"""The striker FMU: a rigid body whose motion under a held force is the
parabola x0 + v0 t + (g - F/m) t^2 / 2 (with its spring k_s a harmonic
oscillation), standard-compliant, with the same error handling and FMU state
as the contact element (the same glue)."""

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


def test_motion_on_its_spring_is_the_oscillation(striker):
    m, g, x0, v0, F, k_s, H = 2.0, 9.81, -1e-3, 0.5, 3.0, 5e4, 1e-4
    s = striker(m=m, g=g, x0=x0, v0=v0, F=F, k_s=k_s)
    w, a = math.sqrt(k_s / m), g - F / m
    rest = x0 + a / w ** 2  # where gravity, the held force and the spring balance
    amplitude = math.hypot(x0 - rest, v0 / w)
    for n in range(1, 201):  # 20 ms: three periods (2 pi / w = 6.3 ms)
        s.step(H)
        t = n * H
        # n exact pieces of the oscillation, each rounding to a few ulp of
        # the amplitude (w H = 0.016: the pieces' sin and cos are exact to
        # an ulp): 200 steps give at most about 1e-13 of it.
        assert s.get("x") == pytest.approx(rest + (x0 - rest) * math.cos(w * t) + v0 / w * math.sin(w * t),
                                           rel=0, abs=1e-13 * amplitude)
        assert s.get("v") == pytest.approx(-(x0 - rest) * w * math.sin(w * t) + v0 * math.cos(w * t),
                                           rel=0, abs=1e-13 * amplitude * w)
    rates = s.fmu.getRealOutputDerivatives([6, 7], [1, 1])
    assert rates[1] == pytest.approx(-w ** 2 * (s.get("x") - rest), rel=1e-12, abs=1e-12 * amplitude * w ** 2)


@pytest.mark.parametrize("name, value, says", [("k_s", -1.0, "k_s = -1"), ("k_s", math.nan, "k_s = nan"),
                                               ("m", 0.0, "m = 0"), ("m", -1.0, "m = -1"), ("F", math.nan, "F = nan"),
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


@pytest.mark.parametrize("k_s", [0.0, 5e4])
def test_striker_state_round_trip(striker, k_s):
    s = striker(F=100.0, k_s=k_s)
    s.step(1e-4)
    blob = s.fmu.serializeFMUstate(s.fmu.getFMUstate())
    s.step(1e-4)
    after = (s.get("x"), s.get("v"))
    s.fmu.setFMUstate(s.fmu.deSerializeFMUstate(blob))
    s.t -= 1e-4
    s.step(1e-4)
    assert (s.get("x"), s.get("v")) == after
