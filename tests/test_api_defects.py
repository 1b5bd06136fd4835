"""Issue 35, the API's items, each held against a closed form or a second
implementation, not the code's own earlier output:

 5  a striker that never reaches the specimen: one documented answer (no
    impact, a warning naming v, g and gap0) in the library, the solver, the
    package and the FMU; one that arrives later (gravity) is no such case
 18 the library's two-body parameters v2 and m2 (the approach speed v - v2,
    the reduced mass m m2/(m + m2)) in one call; a, a2 and coupling refused
    with the reason
 18 docs/python.md: the scene command, the scenes' and crash figures' API and
    the files the package ships
 20 impacts() of an empty batch keeps method's text type; impacts()'s
    per_impact is None, as docs/python.md says"""

import json
import math
import os
import pathlib
import re
import subprocess
import warnings

import numpy as np
import pytest

import fraccontact
from closed_forms import HERTZ_TC, SCHEME_RTOL
from doc_pages import section, text
from fraccontact import cli, crash
from fraccontact.scenes import bumper, headform, masters
from test_two_bodies import M1, M2, V, two_bodies

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
EPS = 2.220446049250313e-16
NEVER = "the striker never reaches the specimen"


def warned(run):
    """What run returns and the messages of the warnings it gives."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = run()
    return result, [str(w.message) for w in caught if issubclass(w.category, fraccontact.ParameterWarning)]


# ------------------------------------------------ item 5: no impact, said so

# (v, g, gap0): the flight -gap0 + v t + g t^2 / 2 never reaches 0, and why
NEVER_ARRIVES = [(-1.0, 0.0, 0.0),      # moving away
                 (0.0, 0.0, 0.0),       # at rest on the surface, nothing pushes it
                 (0.0, 0.0, 1e-3),      # at rest in the gap
                 (0.1, -9.81, 1e-3)]    # towards it, but turned back in the gap: v^2 = 0.01 < 2 |g| gap0 = 0.0196
# The same striker where it does arrive: gravity brings one moving away back,
# and a faster one crosses the gap against a deceleration (0.04 > 0.0196).
ARRIVES = [(-0.5, 9.81, 1e-3), (0.0, 9.81, 1e-3), (0.2, -9.81, 1e-3)]


def onset(v, g, gap0):
    """The first root t > 0 of -gap0 + v t + g t^2 / 2, and the speed there."""
    speed = math.sqrt(v * v + 2 * g * gap0)
    return (speed - v) / g, speed


@pytest.mark.parametrize("v, g, gap0", NEVER_ARRIVES)
def test_a_striker_that_never_arrives_warns_and_has_no_impact(v, g, gap0):
    """The documented answer (docs/model.md §9): a warning naming v, g and
    gap0; the run stops at once (receding) with no impact; the first
    impact's figures NaN; the FMU's outputs F_peak, eps, t_contact, E_diss 0."""
    r, messages = warned(lambda: fraccontact.impact(v=v, g=g, gap0=gap0))
    assert len(messages) == 1 and messages[0].startswith(f"v = {v:g} with g = {g:g} and gap0 = {gap0:g}: {NEVER}")
    assert messages[0] == fraccontact.warning(v=v, g=g, gap0=gap0)
    assert (r.stopped, r.impacts, r.steps, r.per_impact) == ("receding", 0, 0, [])
    assert all(math.isnan(r[name]) for name in fraccontact.model.IMPACT_FIGURES)
    assert (r.end.F_peak, r.end.eps, r.end.t_contact, r.end.E_diss, r.end.v) == (0.0, 0.0, 0.0, 0.0, v)


@pytest.mark.parametrize("v, g, gap0", ARRIVES)
def test_a_striker_that_arrives_later_does_not_warn(v, g, gap0):
    """Its onset is the flight's root (the model's exact parabola: to a few
    roundings, 4 ulp) and it has its impact."""
    r, messages = warned(lambda: fraccontact.impact(v=v, g=g, gap0=gap0))
    t, speed = onset(v, g, gap0)
    assert messages == [] and r.impacts == 1 and r.F_peak > 0
    assert r.t_onset == pytest.approx(t, rel=4 * EPS, abs=0)
    assert r.v_onset == pytest.approx(speed, rel=4 * EPS, abs=0)


def test_a_batch_with_strikers_that_never_arrive_warns_once_and_runs_the_others():
    a, messages = warned(lambda: fraccontact.impacts(v=np.array([0.5, -1.0, 0.0])))
    assert messages == [f"case (1,): {fraccontact.warning(v=-1.0)} (2 of 3 cases have a value without effect)"]
    assert list(a.impacts) == [1, 0, 0] and list(a.stopped) == ["impacts", "receding", "receding"]
    assert a.F_peak[0] > 0 and np.isnan(a.F_peak[1:]).all() and (a.end.F_peak[1:] == 0).all()


def test_the_solver_warns_and_reports_no_impact():
    """Exit 0, the library's warning on stderr, the JSON's figures null and
    its end the FMU's outputs."""
    done = subprocess.run([SOLVE, "--v", "-1", "--json"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stderr == f"fraccontact-solve: warning: {fraccontact.warning(v=-1.0)}\n"
    r = json.loads(done.stdout)
    assert all(r[name] is None for name in fraccontact.model.IMPACT_FIGURES)
    assert (r["stopped"], r["impacts"], r["per_impact"]) == ("receding", 0, [])
    assert (r["end"]["F_peak"], r["end"]["eps"], r["end"]["E_diss"]) == (0, 0, 0)


def test_the_solver_says_nothing_of_a_striker_gravity_brings_back():
    done = subprocess.run([SOLVE, "--v", "-0.5", "--g", "9.81", "--gap0", "1e-3", "--json"], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert json.loads(done.stdout)["impacts"] == 1


def test_the_fmu_warns_at_initialization_and_outputs_no_impact(slave):
    """The drop test's FMU: the same sentence as fmi2Warning when it leaves
    initialization; then its flight, F_peak and eps staying 0."""
    s = slave(v=-1.0)
    assert [(status, message) for status, _, message in s.log if NEVER in message] == \
        [(1, fraccontact.warning(v=-1.0))]  # fmi2Warning
    for _ in range(10):
        s.step(1e-4)
    assert (s.get("F_peak"), s.get("eps"), s.get("E_diss"), s.get("F")) == (0.0, 0.0, 0.0, 0.0)
    assert s.get("x") == pytest.approx(-1e-3, rel=4 * EPS, abs=0)  # x = v t, exact flight over 1 ms


def test_the_fmu_says_nothing_where_gravity_brings_the_striker_back(slave):
    s = slave(v=-0.5, g=9.81, gap0=1e-3)
    assert not [message for _, _, message in s.log if NEVER in message]
    for _ in range(130):  # the onset at 0.104 s (onset()), the impact over by 0.13 s
        s.step(1e-3)
    assert s.get("F_peak") > 0 and s.get("eps") > 0


def test_the_driven_scene_does_not_warn(slave):
    """The caller owns its striker there: v may change at any step."""
    s = slave(scene=2, m=0.0, v=-1.0)
    assert not [message for _, _, message in s.log if NEVER in message]


# ------------------------------------------------ item 18: two bodies in one call

K, MR = 3.299e8, M1 * M2 / (M1 + M2)


def test_the_two_body_impact_is_one_call_and_the_elastic_closed_form():
    """4.5 kg at 3 m/s on a 2 kg body at 1 m/s, no damping to speak of
    (c = 1e300): Hertz's closed form (docs/model.md §2) at the approach speed
    2 m/s with the reduced mass 18/13 kg. Tolerances: the scheme's
    (closed_forms.SCHEME_RTOL, 3x what it measures; here F_peak 1.0e-9,
    t_contact 3.2e-9, eps 1.6e-11)."""
    r = fraccontact.impact(law="hertz", c=1e300, v=3.0, m=M1, v2=1.0, m2=M2)
    u = 3.0 - 1.0
    x_max = (5 * MR * u * u / (4 * K)) ** 0.4
    assert r.F_peak == pytest.approx(K * x_max ** 1.5, rel=SCHEME_RTOL["F_peak"], abs=0)
    assert r.t_contact == pytest.approx(HERTZ_TC * x_max / u, rel=SCHEME_RTOL["t_contact"], abs=0)
    assert r.eps == pytest.approx(1.0, rel=SCHEME_RTOL["eps"], abs=0)
    assert r.v_onset == u


def test_the_solvers_reference_takes_the_two_bodies_too():
    """--reference (GSL at --rtol 1e-12) with --v2 and --m2: the same closed
    form, within 1e-10 (100x the reference's tolerance; it measures 1e-14)."""
    done = subprocess.run([SOLVE, "--reference", "--law", "hertz", "--c", "1e300", "--v", "3", "--m", str(M1),
                           "--v2", "1", "--m2", str(M2), "--json"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    r = json.loads(done.stdout)
    x_max = (5 * MR * 2.0 ** 2 / (4 * K)) ** 0.4
    assert r["F_peak"] == pytest.approx(K * x_max ** 1.5, rel=1e-10, abs=0)
    assert r["t_contact"] == pytest.approx(HERTZ_TC * x_max / 2.0, rel=1e-10, abs=0)
    assert r["end"]["v"] == pytest.approx(-2.0, rel=1e-10, abs=0)  # the approach speed, reversed


def test_the_two_body_impact_is_the_two_free_bodies_co_simulation():
    """Against the two bodies each integrated by the master and exchanging
    -F and +F (tests/test_two_bodies.py): their F_peak, and eps from the
    bodies' own final velocities, to the rounding of the same internal
    steps taken in another order (ROUNDING there, 1e-12)."""
    r = fraccontact.impact(law="hertz", v=V, m=M1, v2=0.0, m2=M2)
    bodies = two_bodies(2, 1, 1e-5)
    assert r.F_peak == pytest.approx(bodies["F_peak"], rel=1e-12, abs=0)
    assert r.eps == pytest.approx(bodies["eps"], rel=1e-12, abs=0)


def test_the_second_bodys_values_are_refused_by_name():
    for params, says in ((dict(m2=-1.0), "m2 = -1 is invalid: the second body's mass"),
                         (dict(v2=math.inf), "v2 = inf is invalid: the second body's velocity must be finite"),
                         (dict(v=1.5e154, m=1.0, v2=-1.5e154, m2=1.0), "the relative motion of the two bodies")):
        with pytest.raises(ValueError, match="^" + says.replace("(", r"\(")):
            fraccontact.impact(**params)
        option = "--" + next(iter(params))
        done = subprocess.run([SOLVE, *(str(x) for k, v in params.items() for x in (f"--{k}", v))], capture_output=True, text=True,
                              timeout=60)
        assert done.returncode == 2 and says in done.stderr and done.stdout == "", (option, done.stderr)


@pytest.mark.parametrize("name", ["a", "a2", "coupling"])
def test_the_co_simulation_inputs_are_refused_with_the_reason(name):
    """The FMU's variables that are no parameter of a run: TypeError saying
    why, as docs/python.md states."""
    with pytest.raises(TypeError, match=f"^{name}: no parameter of a run; .*a library run has no master"):
        fraccontact.impact(**{name: 1})
    prose = " ".join(section("In Python: the `fraccontact` package").split())
    assert "The FMU's inputs `a`, `a2` and `coupling` are no parameters of a run" in prose


# ------------------------------------------------ item 20: the batch's result


def test_an_empty_batch_keeps_methods_type():
    assert fraccontact.impacts(c=np.array([])).method.dtype.kind == fraccontact.impacts(c=np.array([5e3])).method.dtype.kind == "U"


def test_the_batchs_per_impact_is_none_as_the_docs_say():
    assert fraccontact.impacts(c=np.array([5e3])).per_impact is None
    prose = " ".join(section("In Python: the `fraccontact` package").split())
    assert "`impacts()` gives the same `Run` with every figure an array of the broadcast shape and `per_impact` " \
           "`None`" in prose


# ------------------------------------------------ item 18: docs/python.md


def installed_files():
    """The names of the files `pip install .` puts in the package beside its
    library: CMakeLists.txt's install(FILES ...) of the package build, the
    scenes' SSPs from ssp/scenes.cmake's loop."""
    cmake = (ROOT / "CMakeLists.txt").read_text()
    listed = re.search(r"install\(FILES (.*?) DESTINATION fraccontact\)", cmake, re.S).group(1)
    names = set(re.findall(r"/([\w.]+\.(?:fmu|ssp))\"", listed))
    variables = {"${FMU_FILE}": re.search(r'set\(FMU_FILE "\$\{CMAKE_BINARY_DIR\}/([\w.]+)"\)', cmake).group(1),
                 "${SSP_FILE}": re.search(r'set\(SSP_FILE "\$\{CMAKE_BINARY_DIR\}/([\w.]+)"',
                                          (ROOT / "ssp" / "CMakeLists.txt").read_text()).group(1)}
    names |= {name for variable, name in variables.items() if variable in listed}
    assert "${SCENE_SSP_FILES}" in listed
    scenes = re.search(r"foreach\(scene ([\w ]+)\)", (ROOT / "ssp" / "scenes.cmake").read_text()).group(1).split()
    return names | {f"{scene}.ssp" for scene in scenes}


def test_the_package_page_names_every_file_the_package_ships():
    shipped = installed_files()
    assert {"fraccontact.fmu", "striker.fmu", "body.fmu", "drop_test.ssp", "headform.ssp", "bumper.ssp"} <= shipped
    prose = " ".join(section("In Python: the `fraccontact` package").split())
    assert [name for name in sorted(shipped) if f"`{name}`" not in prose] == []


def test_the_package_page_names_every_command():
    prose = " ".join(text("docs/python.md").split())
    assert [c for c in cli.COMMANDS if f"`fraccontact {c}" not in prose and f"`{c}`" not in prose] == []
    assert "`fraccontact scene NAME`" in prose


def test_the_scene_api_the_page_names_exists():
    """Every `module.name(` the scenes' section calls is a function of that
    module of the package."""
    body = section("The crash scenes and their figures in Python")
    called = set(re.findall(r"`(masters|headform|bumper|crash)\.(\w+)\(", body))
    assert {("masters", "run"), ("masters", "figures"), ("crash", "figures")} <= called
    modules = {"masters": masters, "headform": headform, "bumper": bumper, "crash": crash}
    assert [f"{m}.{f}" for m, f in sorted(called) if not callable(getattr(modules[m], f, None))] == []
