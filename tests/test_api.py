"""The Python API's contract: values without effect warn, integer
parameters take whole numbers or their words and nothing truncated, every
bad value is named with its case, and impact, impacts and simulate return
one shape of result (an empty batch's too, and a batch's per_impact None);
a striker that never reaches the specimen has one documented answer (no
impact, a warning naming v, g and gap0) in the library, the solver and the
FMU, and one that arrives later (gravity) is no such case."""

import dataclasses
import json
import math
import os
import pty
import re
import select
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest

import fraccontact
from closed_forms import EPS
from doc_pages import section
from fraccontact import model
from test_solver import SOLVE

from cpu_time import cpu_seconds, reaped


def no_warning(run):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return run()


def warned(run):
    """The warnings run gives, every one recorded."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run()
    return caught


# --- a value without effect warns with the library's message ---------------

@pytest.mark.parametrize("params", [dict(E_s=2e9), dict(damper_order=0.3), dict(damper=2, c=7000.0),
                                    dict(law="hertz", memory=1, damper=2, memory_tolerance=1e-8)])
@pytest.mark.parametrize("call", ["impact", "simulate"])
def test_a_value_without_effect_warns_with_the_librarys_message(params, call):
    """The library's own sentence (the solver and the FMU print it too),
    naming the parameter, pointing at the caller's line."""
    run = (lambda: fraccontact.impact(**params)) if call == "impact" else \
        (lambda: fraccontact.simulate(output_interval=1e-4, **params))
    caught = warned(run)
    assert [str(w.message) for w in caught] == [fraccontact.warning(**params)], caught
    assert caught[0].category.__name__ == "ParameterWarning" and issubclass(caught[0].category, UserWarning)
    assert caught[0].filename == __file__ and str(caught[0].message).split(" = ")[0] in params


def test_a_batch_warns_once_naming_the_first_case():
    caught = warned(lambda: fraccontact.impacts(E_s=np.array([1e9, 2e9, 3e9])))
    assert len(caught) == 1 and caught[0].filename == __file__
    assert str(caught[0].message) == f"case (0,): {fraccontact.warning(E_s=1e9)} (3 of 3 cases have a value " \
                                     "without effect)"
    caught = warned(lambda: fraccontact.impacts(damper_order=np.array([[0.5], [0.3]]), c=np.array([5e3, 6e3])))
    assert [str(w.message) for w in caught] == [f"case (1, 0): {fraccontact.warning(damper_order=0.3)} (2 of 4 "
                                                "cases have a value without effect)"]


def test_values_with_effect_do_not_warn():
    no_warning(lambda: fraccontact.impact(k=0, E_s=2e9))
    no_warning(lambda: fraccontact.impacts(damper=2, damper_order=np.array([0.3, 0.7])))
    no_warning(lambda: fraccontact.simulate(output_interval=1e-4, law="hertz", tolerance=1e-6))


# --- integer parameters, words, and messages that name ---------------------

@pytest.mark.parametrize("params, says", [
    (dict(law=np.array([1.0, 1.5])), r"case \(1,\): law = 1.5 is invalid: it must be a whole number"),
    (dict(law=[2.9]), r"case \(0,\): law = 2.9 is invalid"),
    (dict(g1_nodes=[10.7]), r"case \(0,\): g1_nodes = 10.7 is invalid: it must be a whole number"),
    (dict(law=True), r"law = True is invalid"),
    (dict(law=np.array([[1], [2]]), impacts=np.array([1, 2, 2.5])), r"case \(0, 2\): impacts = 2.5 is invalid"),
    (dict(impacts=[2 ** 32 + 1]), r"case \(0,\): impacts = 4294967297 is invalid: it must be a whole number that "
                                  r"fits a C int"),
    (dict(scheme=[1, np.nan]), r"case \(1,\): scheme = nan is invalid"),
    (dict(damper=np.array([True, False])), r"case \(0,\): damper = True is invalid")])
def test_a_batch_refuses_what_is_no_whole_number(params, says):
    """Nothing truncated (law 1.5 ran law 1, impacts 2**32 + 1 ran 1): the
    refusal names the parameter, the case, its value and the rule."""
    with pytest.raises(ValueError, match=says):
        fraccontact.impacts(**params)


@pytest.mark.parametrize("params, says", [
    (dict(law=2.5), "law = 2.5 is invalid: it must be a whole number that fits a C int or one of g1, hertz, g1x"),
    (dict(law=True), "law = True is invalid"), (dict(g1_nodes=10.7), "g1_nodes = 10.7 is invalid"),
    (dict(memory=False), "memory = False is invalid"), (dict(impacts=2 ** 32 + 1), "impacts = 4294967297 is invalid"),
    (dict(c="5000"), "c = '5000' is invalid: it must be a real number \\[N.s/m\\]"),
    (dict(m=True), "m = True is invalid: it must be a real number"),
    (dict(dt_max=1e-7 + 0j), r"dt_max = \(1e-07\+0j\) is invalid"),
    (dict(damper="fractional"), "damper = 'fractional' is invalid: .* or one of dashpot, springpot"),
    (dict(c=[5e3, 6e3]), r"c = \[5000.0, 6000.0\] is invalid: one run takes one value per parameter")])
def test_a_run_refuses_a_bad_value_by_its_name(params, says):
    with pytest.raises(ValueError, match=says):
        fraccontact.impact(**params)


@pytest.mark.parametrize("params, says", [
    (dict(height=[0.01, -0.02]), r"^case \(1,\): height = -0.02 is invalid: a drop height must be finite and >= 0"),
    (dict(c=[5e3, "6e3"]), r"^case \(1,\): c = '6e3' is invalid: it must be a real number"),
    (dict(c=np.array([[5e3], [6e3]]), v=np.array([0.5, -np.inf])), r"^case \(0, 1\): v = -inf is invalid"),
    (dict(c=[5e3, 6e3], law=[1, 2, 3]), r"^the arrays do not broadcast together: c \(2,\), law \(3,\)$")])
def test_a_batch_names_the_case_not_the_array(params, says):
    with pytest.raises(ValueError, match=says):
        fraccontact.impacts(**params)


def test_a_whole_float_is_its_integer():
    """2.0 is law 2, as the solver's --law 2 and the FMU's Integer 2."""
    assert fraccontact.impact(law=2.0) == fraccontact.impact(law=2)
    a = fraccontact.impacts(law=np.array([1.0, 2.0]), g1_nodes=np.array([0.0, 16.0]))
    assert a.F_peak.tolist() == [fraccontact.impact(law=1).F_peak, fraccontact.impact(law=2, g1_nodes=16).F_peak]


def solver_words(name):
    """The words fraccontact-solve --help lists for --NAME."""
    solve = os.environ.get("FRACCONTACT_SOLVE", "build/fraccontact-solve")
    text = subprocess.run([solve, "--help"], capture_output=True, text=True, check=True).stdout
    line = next(line for line in text.splitlines() if line.strip().startswith(f"--{name} "))
    return line.rsplit("; or ", 1)[1].split(", ") if "; or " in line else None


def library_words(name):
    """The words the library's help gives the codes: '1 dashpot ..., 2 springpot ...'."""
    help_ = next(p["help"] for p in fraccontact.parameters() if p["name"] == name)
    return [re.search(rf"\b{code} (?:= )?(\w+)", help_).group(1) for code in (1, 2)]


@pytest.mark.parametrize("name", ["law", "scene", "scheme", "damper", "memory"])
def test_every_enumerated_parameter_takes_the_vocabulary_words(name):
    """The words are those of the solver's --help, else the library's help
    (1 dashpot, 2 springpot; 1 full G1 history, 2 compressed), each the run
    of its code, scalar and array alike."""
    words = solver_words(name) or library_words(name)
    assert list(model.WORDS[name]) == words
    for code, word in enumerate(words, start=1):
        params = dict(damper=2) if name == "memory" else {}
        assert fraccontact.impact(**{name: word}, **params) == fraccontact.impact(**{name: code}, **params)
    batch = fraccontact.impacts(**{name: np.array(words)}, **(dict(damper=2) if name == "memory" else {}))
    assert batch.F_peak.tolist() == [fraccontact.impacts(**{name: code}, **(dict(damper=2) if name == "memory"
                                                                             else {})).F_peak.item()
                                     for code in range(1, len(words) + 1)]


def test_words_mixed_with_codes_in_one_array():
    a = fraccontact.impacts(damper=["springpot", 1])
    assert a.F_peak.tolist() == [fraccontact.impact(damper=2).F_peak, fraccontact.impact(damper=1).F_peak]


def test_a_batch_shares_a_springpots_kernel_only_between_runs_alike():
    """fc_run_batch keeps the springpot's kernel for the next run of the same
    damper_order, memory_tolerance and kernel floor (dt_max, tolerance):
    runs that differ in each, interleaved with runs alike, give exactly the
    figures of each run alone (impact calls fc_run, which builds its own).
    (dt_max = 5e-10 s: under the floor's bound of 1e-9 s, CONTACT_MEMORY_FLOOR,
    a floor of its own at the fewest internal steps.)"""
    cases = [dict(damper_order=0.5), dict(damper_order=0.3), dict(damper_order=0.5, memory_tolerance=1e-4),
             dict(damper_order=0.5), dict(damper_order=0.5, tolerance=1e-6),
             dict(damper_order=0.5, tolerance=1e-6, dt_max=5e-10), dict(damper_order=0.5, dt_max=2e-7),
             dict(damper_order=0.5), dict(damper_order=0.3)]
    columns = {name: np.array([case.get(name, default) for case in cases]) for name, default in
               (("damper_order", 0.5), ("memory_tolerance", 1e-6), ("tolerance", 0.0), ("dt_max", 0.0))}
    batch = fraccontact.impacts(damper=2, law=2, **columns)
    for i, case in enumerate(cases):
        alone = fraccontact.impact(damper=2, law=2, **case)
        assert (batch.F_peak[i], batch.eps[i], batch.x2_end[i], batch.steps[i]) == (
            alone.F_peak, alone.eps, alone.x2_end, alone.steps), case


# --- one shape of result ---------------------------------------------------

RUN_FIELDS = ["t_onset", "v_onset", "F_peak", "eps", "t_contact", "x2_end", "E_diss", "per_impact", "end",
              "stopped", "impacts", "steps", "k", "method"]
END_FIELDS = ["t", "F_peak", "eps", "t_contact", "E_diss", "x", "x1", "x2", "v"]
SERIES_FIELDS = ["t", "F", "x", "x1", "x2", "v", "E_diss", "run"]


def test_impact_impacts_and_simulate_give_one_shape():
    """Attribute and key access alike on all three; impacts() the same
    fields as impact(), arrays of the batch's shape."""
    r = fraccontact.impact(law="hertz")
    a = fraccontact.impacts(law="hertz", c=np.array([[6080.0, 5000.0]]))
    s = fraccontact.simulate(output_interval=1e-4, law="hertz")
    assert list(r) == list(a) == RUN_FIELDS and list(r.end) == list(a.end) == END_FIELDS
    assert list(s) == SERIES_FIELDS and s.run == r
    for name in RUN_FIELDS:
        assert r[name] is getattr(r, name) and a[name] is getattr(a, name)
        if name not in ("per_impact", "end"):
            assert a[name].shape == (1, 2) and a[name][0, 0] == r[name], name
            assert isinstance(r[name], type(a[name][0, 0].item())), name
    for name in END_FIELDS:
        assert a.end[name].shape == (1, 2) and a.end[name][0, 0] == r.end[name] == r["end"][name]
    assert a.per_impact is None and r.per_impact[0].F_peak == r.per_impact[0]["F_peak"] == r.F_peak
    for name in SERIES_FIELDS[:-1]:
        assert s[name] is getattr(s, name) and s[name].shape == s.t.shape
    assert dict(r)["end"] is r.end and dataclasses.asdict(r)["end"]["x2"] == r.end.x2


def test_an_empty_batch_keeps_the_types():
    a = fraccontact.impacts(c=np.array([]))
    assert a.stopped.dtype.kind == "U" and a.impacts.dtype.kind == "i" and a.steps.dtype.kind == "i"
    assert a.F_peak.shape == a.end.x2.shape == (0,)


def test_the_shape_is_documented_in_one_place():
    """The module docstring names every field of every result."""
    for name in RUN_FIELDS + END_FIELDS + SERIES_FIELDS:
        assert re.search(rf"\b{name}\b", model.__doc__), name
    for cls in ("Run", "Series", "End", "Impact"):
        assert cls in model.__doc__ and hasattr(fraccontact, cls)


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def readme_python_section():
    text = open(os.path.join(ROOT, "docs", "python.md")).read()
    return text.split("## In Python: the `fraccontact` package", 1)[1].split("\n## ", 1)[0]


def test_the_readmes_python_section_runs_and_tells_the_shape():
    """Its example runs as written, each result as its comments and the
    text after it say; the words and limits it states are the package's."""
    section = readme_python_section()
    example = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    names = {}
    exec(example, names)
    r, a, s = names["r"], names["a"], names["s"]
    assert isinstance(r, fraccontact.Run) and isinstance(a, fraccontact.Run) and isinstance(s, fraccontact.Series)
    assert a.F_peak.shape == (1000,) and s.run.F_peak == fraccontact.impact().F_peak
    prose = " ".join(section.split())
    for name in RUN_FIELDS + END_FIELDS + SERIES_FIELDS:
        assert f"`{name}`" in prose, name
    for name, words in model.WORDS.items():
        assert f"`{name}` {', '.join(words)}" in prose, name
    steps, rows = (float(x) for x in re.search(r"more than (\S+) internal steps .*? more than (\S+) rows", prose).groups())
    for run, limit in ((lambda: fraccontact.impact(dt_max=1e-13), steps),
                       (lambda: fraccontact.simulate(output_interval=1e-12), rows)):
        with pytest.raises(ValueError) as refused:
            run()
        assert float(re.search(r"more than (?:the )?(\S+)", str(refused.value)).group(1).rstrip(";,")) == limit


# --- rows beyond what the machine holds, refused up front -------------------

def test_a_series_too_long_for_memory_is_refused_up_front():
    """output_interval 1e-12 over a 1 s run asks for 1e12 rows (24 GB were
    taken before): refused at once, under a 2 GB address-space limit."""
    limit = "" if os.environ.get("FRACCONTACT_SANITIZED") == "1" else \
        "import resource; resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))\n"  # ASan reserves its shadow memory beyond any such limit
    code = (limit + "import fraccontact\n"
            "try:\n    fraccontact.simulate(output_interval=1e-12)\n"
            "except ValueError as e:\n    print(e)\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0 and run.stdout.strip(), run.stderr
    assert "output_interval" in run.stdout and "1e-12" in run.stdout, run.stdout


# --- Ctrl-C stops a long call; a terminal sees its progress -----------------

# The h20 impact in 6.6e8 internal steps: under the library's limit of 1e9,
# so accepted, and about a minute and a half of work.
LONG = "dt_max=2e-12"
CALLS = [f"fraccontact.impact({LONG})", f"fraccontact.impacts({LONG}, c=np.array([5e3, 6e3]))",
         f"fraccontact.simulate(output_interval=1e-4, {LONG})"]


def started(call, stderr):
    """A Python process well inside the library call: it said so, and had
    time to pass the delay after which a terminal sees a progress line."""
    code = f"import numpy as np\nimport fraccontact\nprint('calling', flush=True)\n{call}\n"
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=stderr, text=True)
    assert p.stdout.readline() == "calling\n"
    time.sleep(model.SHOW_AFTER + 1.0)
    return p


def interrupted(p):
    """CPU seconds the process used from Ctrl-C (SIGINT) until it ended (its
    own time, whatever the load; the clock gives it 10 s)."""
    try:
        asked = cpu_seconds(p.pid)
        p.send_signal(signal.SIGINT)
        total = reaped(p, 10)
        assert total is not None, "still running 10 s after Ctrl-C"
        return total - asked
    finally:
        p.kill()


@pytest.mark.parametrize("call", CALLS)
def test_ctrl_c_stops_a_long_call_within_a_second(call):
    p = started(call, subprocess.PIPE)
    assert interrupted(p) < 1.0
    err = p.stderr.read()
    assert p.returncode == -signal.SIGINT and err.rstrip().endswith("KeyboardInterrupt"), err
    assert "fraccontact: " not in err  # no progress line but on a terminal


def terminal_text(fd):
    text = b""
    while select.select([fd], [], [], 5)[0]:
        try:
            chunk = os.read(fd, 4096)
        except OSError:  # the other end closed
            break
        if not chunk:
            break
        text += chunk
    return text.decode()


def test_a_long_call_shows_its_progress_on_a_terminal():
    """On a terminal, after a few seconds: where the run is, and that Ctrl-C
    stops it; the line ends before the traceback."""
    ours, theirs = pty.openpty()
    p = started(CALLS[0], theirs)
    os.close(theirs)
    assert interrupted(p) < 1.0
    text = terminal_text(ours)
    os.close(ours)
    line = re.search(r"\rfraccontact: t = [0-9.e-]+ s, (\d+) internal steps, 0 impacts \(Ctrl-C stops\)\r?\n", text)
    assert line and int(line.group(1)) > 0, text
    assert text[line.end():].startswith("Traceback") and text.rstrip().endswith("KeyboardInterrupt"), text


def test_a_short_call_draws_nothing_on_a_terminal():
    ours, theirs = pty.openpty()
    p = subprocess.Popen([sys.executable, "-c", "import fraccontact; fraccontact.impacts(c=[5e3, 6e3])"],
                         stderr=theirs)
    os.close(theirs)
    assert p.wait(timeout=60) == 0
    assert terminal_text(ours) == ""
    os.close(ours)


# --- a striker that never reaches the specimen: no impact, said so ---------

NEVER = "the striker never reaches the specimen"


def result_and_warnings(run):
    """What run returns and the messages of the warnings it gives."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = run()
    return result, [str(w.message) for w in caught if issubclass(w.category, fraccontact.ParameterWarning)]


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
    r, messages = result_and_warnings(lambda: fraccontact.impact(v=v, g=g, gap0=gap0))
    assert len(messages) == 1 and messages[0].startswith(f"v = {v:g} with g = {g:g} and gap0 = {gap0:g}: {NEVER}")
    assert messages[0] == fraccontact.warning(v=v, g=g, gap0=gap0)
    assert (r.stopped, r.impacts, r.steps, r.per_impact) == ("receding", 0, 0, [])
    assert all(math.isnan(r[name]) for name in fraccontact.model.IMPACT_FIGURES)
    assert (r.end.F_peak, r.end.eps, r.end.t_contact, r.end.E_diss, r.end.v) == (0.0, 0.0, 0.0, 0.0, v)


@pytest.mark.parametrize("v, g, gap0", ARRIVES)
def test_a_striker_that_arrives_later_does_not_warn(v, g, gap0):
    """Its onset is the flight's root (the model's exact parabola: to a few
    roundings, 4 ulp) and it has its impact."""
    r, messages = result_and_warnings(lambda: fraccontact.impact(v=v, g=g, gap0=gap0))
    t, speed = onset(v, g, gap0)
    assert messages == [] and r.impacts == 1 and r.F_peak > 0
    assert r.t_onset == pytest.approx(t, rel=4 * EPS, abs=0)
    assert r.v_onset == pytest.approx(speed, rel=4 * EPS, abs=0)


def test_a_batch_with_strikers_that_never_arrive_warns_once_and_runs_the_others():
    a, messages = result_and_warnings(lambda: fraccontact.impacts(v=np.array([0.5, -1.0, 0.0])))
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


# --- the batch's result ------------------------------------------------------

def test_an_empty_batch_keeps_methods_type():
    assert fraccontact.impacts(c=np.array([])).method.dtype.kind == fraccontact.impacts(c=np.array([5e3])).method.dtype.kind == "U"


def test_the_batchs_per_impact_is_none_as_the_docs_say():
    assert fraccontact.impacts(c=np.array([5e3])).per_impact is None
    prose = " ".join(section("In Python: the `fraccontact` package").split())
    assert "`impacts()` gives the same `Run` with every figure an array of the broadcast shape and `per_impact` " \
           "`None`" in prose
