"""fraccontact-solve from the command line: its options, its outputs, its
reference against scipy, and the model it shares with the FMU."""

import csv
import json
import math
import os
import pathlib
import pty
import re
import resource
import select
import signal
import subprocess
import time

import pytest

import fraccontact
from closed_forms import EPS
from fmu_driver import C, K, M, run_impact
from fraccontact.scipy_contact import solve_drop
from test_fmu_features import reference
from test_fmu_physics import reference_drop

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
V0 = 0.626418  # the solver's and the FMU's default impact velocity
KEYS = ("F_peak", "eps", "t_contact", "x2_end", "E_diss")  # the first impact's


def solve(*args, check=True):
    done = subprocess.run([SOLVE, *map(str, args)], capture_output=True, text=True, timeout=600)
    if check:
        assert done.returncode == 0, done.stderr
    return done


def solve_json(*args):
    return json.loads(solve(*args, "--json").stdout)


def test_help_documents_every_option():
    text = solve("--help").stdout
    options = [o["option"] for o in json.loads(solve("--list-options").stdout)]
    assert len(options) > 20
    for option in options:
        assert option in text, option
    # the model's options are the FMU's variables, '_' as '-' (--dt-max for dt_max)
    for name in ("v", "m", "R", "E_i", "nu_i", "E_s", "nu_s", "k", "c", "law", "g1_nodes", "dt_max", "scene", "g",
                 "gap0"):
        assert "--" + name.replace("_", "-") in options, name


def test_json_has_the_promised_keys():
    r = solve_json()
    for key in KEYS + ("t_onset", "v_onset", "per_impact", "end", "stopped", "steps", "cpu_seconds", "impacts",
                       "method", "k", "params"):
        assert key in r, key
    assert r["impacts"] == 1 and r["steps"] > 10000 and r["cpu_seconds"] >= 0
    assert set(r["end"]) == {"t", "F_peak", "eps", "t_contact", "E_diss", "x", "x1", "x2", "v"}


@pytest.mark.parametrize("args, method", [
    ([], "gradient"), (["--scheme", "central"], "central"), (["--reference"], "reference"),
    (["--damper", "2", "--memory", "1"], "g1_history"),
    (["--law", "2", "--tolerance", "1e-6", "--dt-max", "1e-3"], "esdirk54"),
    (["--law", "2", "--tolerance", "1e-6", "--dt-max", "1e-3", "--damper", "2", "--memory", "2"], "radau_iia"),
    (["--law", "1", "--tolerance", "1e-6"], "gradient")])  # G1 with N = steps: fixed steps (and a warning)
def test_json_names_the_method_that_ran(args, method):
    r = solve_json("--t-end", "2e-3", *args)
    assert r["method"] == method
    if method in ("esdirk54", "radau_iia"):  # its own steps, not dt_max's: the contact in far fewer than 1e-3/1e-7
        assert r["steps"] < 1000


@pytest.mark.parametrize("args, says", [
    (["--c", "-1"], "c = -1"), (["--c", "abc"], "--c 'abc'"), (["--bogus", "1"], "--bogus"),
    (["--law", "foo"], "--law 'foo'"), (["--dt-max", "-1"], "dt_max = -1"), (["--m", "0"], "m = 0"),
    (["--height", "-1e-3"], "--height"), (["--t-end", "0"], "--t-end"), (["--json=1"], "--json"),
    (["--k"], "needs a value"), (["--g1-nodes", "2.5"], "--g1-nodes"), (["--scheme", "rk4"], "--scheme")])
def test_bad_options_exit_2_with_a_clear_message(args, says):
    done = solve(*args, check=False)
    assert done.returncode == 2 and says in done.stderr, (done.returncode, done.stderr)
    assert done.stdout == ""


def test_unwritable_csv_fails_and_leaves_nothing(tmp_path):
    target = tmp_path / "missing" / "out.csv"
    done = solve("--csv", target, check=False)
    assert done.returncode == 1 and "cannot write" in done.stderr
    assert not target.parent.exists()


def test_csv_series(tmp_path):
    path = tmp_path / "h20.csv"
    r = solve_json("--law", "hertz", "--csv", path, "--output-interval", "1e-5")
    rows = list(csv.DictReader(open(path)))
    assert not (tmp_path / "h20.csv.tmp").exists()
    t = [float(row["t"]) for row in rows]
    assert t[0] == 0.0 and all(b > a for a, b in zip(t, t[1:]))
    assert t[1] == pytest.approx(1e-5, rel=1e-11, abs=0)  # 12 digits are written
    F = [float(row["F"]) for row in rows]
    assert max(F) <= r["F_peak"] and max(F) > 0.999 * r["F_peak"]
    for row in rows:  # 12 digits are written
        x, x1, x2 = float(row["x"]), float(row["x1"]), float(row["x2"])
        if x1 > 0:
            assert x == pytest.approx(x1 + x2, rel=1e-11, abs=0)  # three 12-digit numbers, x1, x2 > 0
        else:  # after separation: the gap to the dented surface
            assert x <= x2 * (1 + 1e-11)


def test_height_gives_the_impact_velocity():
    assert solve_json("--height", "0.02")["params"]["v"] == pytest.approx(math.sqrt(2 * 9.81 * 0.02), rel=1e-15, abs=0)


def test_reference_matches_scipy():
    """Two independent high-accuracy solvers of the same ODE (GSL rk8pd and
    scipy DOP853, each at ~1e-12): they agree to 1e-9."""
    r = solve_json("--reference", "--law", "hertz")
    ref = reference_drop(K, C, M, V0)
    ref["x2_end"] = ref.pop("x2")
    for key in KEYS:
        assert r[key] == pytest.approx(ref[key], rel=1e-9, abs=0), key


def test_stiff_reference_matches_scipy_radau():
    """c = 30: the dashpot relaxes ~100 times faster than a Hertz contact
    lasts, so the reference switches to BDF. So soft a dashpot never lets the
    striker rebound: compare the state after 10 ms with scipy's Radau."""
    c, t_end = 30.0, 0.01
    r = solve_json("--reference", "--law", "hertz", "--c", c, "--t-end", t_end)
    ref = solve_drop(K, c, M, V0, method="Radau", rtol=1e-12, t_end=t_end)
    assert r["impacts"] == 0 and not ref["separated"] and r["F_peak"] is None
    # Against GSL's own solve at rtol 1e-14, its BDF at the default 1e-12 errs up to 2e-9 (E_diss) over
    # this 10 ms stiff run and Radau 8e-12, alike with each right-hand side's rounding moved by an ulp
    # (another machine's SIMD paths or libm): 1e-8 leaves GSL's error a factor 5.
    end = r["end"]
    assert end["x2"] == pytest.approx(ref["x2"], rel=1e-8, abs=0)
    assert end["v"] == pytest.approx(ref["v_end"], rel=1e-8, abs=0)
    assert end["E_diss"] == pytest.approx(ref["E_diss"], rel=1e-8, abs=0)
    assert end["F_peak"] == pytest.approx(ref["F_peak"], rel=1e-8, abs=0)


def test_solver_and_fmu_share_the_model(slave):
    """Same code, same steps: the CLI and the FMU agree to rounding."""
    for law, name in ((1, "g1"), (2, "hertz")):
        r = solve_json("--law", name)
        f = run_impact(slave(law=law))
        # the same steps (H a multiple of dt_max): only the rounding of the time sums differs
        assert r["F_peak"] == pytest.approx(f["F_peak"], rel=1e-12, abs=0)
        assert r["eps"] == pytest.approx(f["eps"], rel=1e-12, abs=0)
        assert r["x2_end"] == pytest.approx(f["x2"], rel=1e-12, abs=0)


def test_fixed_steps_are_second_order_and_central_first_against_the_reference():
    ref = solve_json("--reference", "--law", "hertz")
    for scheme, order in (("gradient", 2.0), ("central", 1.0)):
        errors = [abs(solve_json("--law", "hertz", "--scheme", scheme, "--dt-max", dt)["x2_end"] / ref["x2_end"] - 1)
                  for dt in (4e-7, 2e-7, 1e-7)]
        observed = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
        assert all(abs(p - order) < 0.15 for p in observed), (scheme, errors, observed)


def test_extrapolated_g1_law_is_second_order():
    """Law g1x cancels G1's 3/(8N): it converges to Hertz like the scheme
    (F_peak, the largest of the step values, is left out: sampling the peak
    on the step grid makes its error oscillate)."""
    ref = solve_json("--reference", "--law", "hertz")
    for key in ("eps", "x2_end", "t_contact"):
        errors = [abs(solve_json("--law", "g1x", "--dt-max", dt)[key] / ref[key] - 1) for dt in (4e-7, 2e-7, 1e-7)]
        observed = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
        assert all(abs(p - 2) < 0.15 for p in observed), (key, errors, observed)


# ---------------------------------------------------------------- the CLI as a user meets it

def without_timing(r):
    return {key: value for key, value in r.items() if key != "cpu_seconds"}


@pytest.mark.parametrize("method", [[], ["--reference"]])
def test_no_figure_depends_on_the_output_interval(method, tmp_path):
    """Three bounces under gravity: the solve stops right after the third
    impact ends whatever the CSV's row spacing, and every figure is the same
    to the bit (rows are made from copies of the state, never by cutting the
    solve's own steps)."""
    runs = []
    for i, interval in enumerate([None, "0.5", "0.1", "1e-5", "0"]):
        args = ["--g", 9.81, "--impacts", 3, "--law", "hertz", *method, "--csv", tmp_path / f"{i}.csv"]
        if interval is not None:
            args += ["--output-interval", interval]
        runs.append(without_timing(solve_json(*args)))
    assert runs[0]["impacts"] == 3 and runs[0]["stopped"] == "impacts"
    for r in runs[1:]:
        assert r == runs[0]


def test_per_impact_figures_against_the_reference():
    """Each impact's figures from the model (Hertz law, dt 1e-7) against the
    GSL reference, impact by impact. The scheme's error at this step is about
    1e-9 relative for h20 (docs/benchmarks.md: 8.7e-10 in F_peak, 3.3e-9 in eps); free
    flight is exact, so later impacts inherit only that: 1e-7 leaves two
    orders of margin and fails any mix-up between impacts (they differ by
    tens of percent)."""
    args = ("--g", 9.81, "--impacts", 3, "--law", "hertz")
    model, ref = solve_json(*args), solve_json(*args, "--reference")
    assert len(model["per_impact"]) == len(ref["per_impact"]) == 3
    for a, b in zip(model["per_impact"], ref["per_impact"]):
        for key in ("t_onset", "v_onset", "F_peak", "eps", "t_contact", "x2_end", "E_diss"):
            assert a[key] == pytest.approx(b[key], rel=1e-7, abs=1e-7 * abs(b["t_contact"]) if key == "t_onset" else 0), key


@pytest.mark.parametrize("method", [[], ["--reference"]])
def test_top_level_figures_say_which_impact_they_describe(method):
    """The top level is the first impact; "end" holds the FMU's outputs where
    the solve stopped: F_peak the largest of all impacts, eps and t_contact
    the last one's, E_diss the sum, x2 the dent: identities on the per-impact
    list."""
    r = solve_json("--g", 9.81, "--impacts", 3, *method)
    impacts, end = r["per_impact"], r["end"]
    assert {key: r[key] for key in impacts[0]} == impacts[0]
    assert [i["F_peak"] for i in impacts] == sorted((i["F_peak"] for i in impacts), reverse=True)
    assert end["F_peak"] == max(i["F_peak"] for i in impacts)
    assert end["eps"] == impacts[-1]["eps"] and end["t_contact"] == impacts[-1]["t_contact"]
    assert end["x2"] == impacts[-1]["x2_end"]
    assert end["E_diss"] == pytest.approx(sum(i["E_diss"] for i in impacts), rel=1e-13, abs=0)
    # each impact starts where the last left off: its onset speed is the rebound falling back under g
    for a, b in zip(impacts, impacts[1:]):
        assert b["v_onset"] == pytest.approx(a["eps"] * a["v_onset"], rel=1e-9, abs=0)
    help_text = solve("--help").stdout
    for words in ("per_impact", "the first impact's figures", "(the largest\n               of the solve)",
                  "(of the last finished impact)", "stopped"):
        assert words in help_text, words


def test_text_output_has_a_per_impact_table():
    out = solve("--g", 9.81, "--impacts", 3).stdout
    header = [line for line in out.splitlines() if "t_onset [s]" in line]
    assert len(header) == 1
    rows = out.splitlines()[out.splitlines().index(header[0]) + 1:][:3]
    assert [row.split()[0] for row in rows] == ["1", "2", "3"]


def test_one_impact_per_impact_figures_match_the_closed_forms():
    """Momentum and energy of the one impact of h20 (no gravity):
    x2_end = m v0 (1 + eps) / c (the dashpot carries the impulse) and
    E_diss = m v0^2 (1 - eps^2) / 2; the dissipation is counted from each
    step's mean force, within O(dt^2) ~ 1e-9 of the integral."""
    r = solve_json("--law", "hertz")
    (i,) = r["per_impact"]
    assert i["t_onset"] == 0 and i["v_onset"] == V0
    assert i["x2_end"] == pytest.approx(M * V0 * (1 + i["eps"]) / C, rel=1e-12, abs=0)
    assert i["E_diss"] == pytest.approx(0.5 * M * V0 ** 2 * (1 - i["eps"] ** 2), rel=1e-8, abs=0)


@pytest.mark.parametrize("height", ["-1", "-1e-3", "nan", "inf", "-inf", "-0.5"])
def test_a_negative_or_nonfinite_height_is_refused(height):
    done = solve("--height", height, check=False)
    assert done.returncode == 2 and f"--height '{height}'" in done.stderr, done.stderr


@pytest.mark.parametrize("args, says", [
    (["--impacts", ""], "--impacts '' (empty)"), (["--height", "nan"], "--height 'nan'"),
    (["--t-end", "0"], "--t-end '0'"), (["--rtol", "0"], "--rtol '0'"), (["--repeat", "0"], "--repeat '0'"),
    (["--output-interval", "-1"], "--output-interval '-1'"), (["--c", "-1e0"], "--c '-1e0'"),
    (["--dt-max=-1e-9"], "--dt-max '-1e-9'"), (["--m", "-0"], "--m '-0'"), (["--E-s", "-2e9"], "--E-s '-2e9'"),
    (["--law", "9"], "--law '9'"), (["--impacts", "0"], "--impacts '0'")])
def test_every_message_names_the_option_and_the_value_as_typed(args, says):
    done = solve(*args, check=False)
    assert done.returncode == 2 and says in done.stderr, done.stderr


def test_free_flight_is_one_exact_step():
    """A drop from 1 m above the specimen under gravity: the fall is one
    step (the CLI used to step it at dt: 4.5 million steps), and the onset
    time and speed are the free-fall closed forms t = sqrt(2 h / g),
    v = sqrt(2 g h) to rounding."""
    g, gap0 = 9.81, 1.0
    r = solve_json("--g", g, "--gap0", gap0, "--v", 0, "--law", "hertz")
    (i,) = r["per_impact"]
    assert i["t_onset"] == pytest.approx(math.sqrt(2 * gap0 / g), rel=1e-14, abs=0)
    assert i["v_onset"] == pytest.approx(math.sqrt(2 * g * gap0), rel=1e-14, abs=0)
    contact_steps = math.ceil(i["t_contact"] / 1e-7)
    assert r["steps"] <= contact_steps + 2, (r["steps"], contact_steps)


@pytest.mark.parametrize("method", [[], ["--reference"]])
def test_a_receding_striker_stops_the_solve_at_once(method):
    """Nothing brings a striker that moves away back (no gravity): the solve
    stops there, says so, and does not run to --t-end."""
    r = solve_json("--v", -1, "--t-end", 1e300, *method)
    assert r["stopped"] == "receding" and r["end"]["t"] == 0 and r["impacts"] == 0 and r["steps"] <= 1
    r = solve_json("--impacts", 2, "--t-end", 1e300, *method)
    assert r["stopped"] == "receding" and r["impacts"] == 1
    assert r["end"]["t"] == pytest.approx(r["per_impact"][0]["t_contact"], rel=1e-15, abs=0)
    assert "nothing brings it back" in solve("--v", -1, *method).stdout


def test_csv_has_a_few_hundred_rows_per_contact_by_default(tmp_path):
    """h20 lasts 1.3 ms: the default spacing (1/256 of the elastic contact
    time) gives a few hundred rows; --output-interval 0 asks for every step."""
    r = solve_json("--csv", tmp_path / "default.csv")
    rows = list(csv.DictReader(open(tmp_path / "default.csv")))
    assert 200 <= len(rows) <= 400, len(rows)
    assert float(rows[-1]["t"]) == pytest.approx(r["end"]["t"], rel=1e-11, abs=0)  # 12 digits written
    r = solve_json("--csv", tmp_path / "every.csv", "--output-interval", 0)
    assert len(list(csv.DictReader(open(tmp_path / "every.csv")))) >= r["t_contact"] / 1e-7
    assert "every internal step" in solve("--help").stdout


def test_rows_are_the_model_at_their_times(tmp_path):
    """A row between steps is the model advanced to that time: with rows
    every 2.5e-7 s and steps of 1e-7 s, the rows that fall on step ends
    (every other one: 5e-7) equal the every-step series there (12 digits
    are written)."""
    solve_json("--law", "hertz", "--csv", tmp_path / "rows.csv", "--output-interval", 2.5e-7)
    solve_json("--law", "hertz", "--csv", tmp_path / "steps.csv", "--output-interval", 0)
    rows = {round(float(r["t"]) / 5e-7): r for r in csv.DictReader(open(tmp_path / "rows.csv"))
            if abs(float(r["t"]) / 5e-7 - round(float(r["t"]) / 5e-7)) < 1e-6}
    steps = {round(float(r["t"]) / 5e-7): r for r in csv.DictReader(open(tmp_path / "steps.csv"))
             if abs(float(r["t"]) / 5e-7 - round(float(r["t"]) / 5e-7)) < 1e-6}
    common = sorted(set(rows) & set(steps))
    assert len(common) > 2000
    for n in common:
        assert float(rows[n]["F"]) == pytest.approx(float(steps[n]["F"]), rel=1e-9, abs=1e-9)


def test_a_material_without_effect_is_warned_about():
    done = solve("--E-s", "1.2e9")
    assert "warning" in done.stderr and "E_s = 1.2e+09 has no effect" in done.stderr, done.stderr
    assert not solve().stderr
    # with k = 0 the materials are used: k from the Hertz closed form, no warning
    done = solve("--k", 0, "--E-s", "1.2e9", "--json")
    assert not done.stderr
    e_star = 1 / ((1 - 0.3 ** 2) / 210e9 + (1 - 0.4 ** 2) / 1.2e9)
    assert json.loads(done.stdout)["k"] == pytest.approx(4 / 3 * e_star * math.sqrt(6.35e-3), rel=1e-15, abs=0)


def test_the_reference_of_a_huge_mass_is_the_constant_rate_drive():
    """A striker of 1e300 kg does not slow down in 2 ms: the drop test is the
    driven scene at the constant rate v0 without inertia (both GSL at 1e-12,
    whose tolerance scales must come from the indentation where the dashpot
    takes over, not from the mass's astronomically large Hertz maximum)."""
    heavy = solve_json("--reference", "--law", "hertz", "--m", 1e300, "--t-end", 2e-3)
    drive = solve_json("--reference", "--law", "hertz", "--scene", "driven", "--m", 0, "--t-end", 2e-3)
    # measured 4e-12 (F_peak) to 4e-11 (E_diss, an integral); 1e-10 is a few times that
    for key in ("F_peak", "x2", "x1", "E_diss"):
        assert heavy["end"][key] == pytest.approx(drive["end"][key], rel=1e-10, abs=0), key


@pytest.mark.parametrize("method", [[], ["--reference"]])
def test_an_underflowing_indentation_is_no_separation(method):
    """v0 = 5e-324: x1 = v0 t underflows to 0 on the way in; that is no
    rebound (it used to end the contact at once with eps = -1)."""
    r = solve_json("--v", "5e-324", "--t-end", 1e-3, *method)
    assert r["impacts"] == 0 and r["end"]["eps"] == 0 and r["stopped"] == "t_end" and r["end"]["v"] == 5e-324


# ---------------------------------------------------------------- an overdamped contact at rest

def test_an_overdamped_contact_rests_instead_of_ending_at_a_denormal_eps():
    """A linear spring k = 3.3e8 N/m in series with c = 6080 N s/m under
    0.74 kg is overdamped ((k/c)^2 > 4 k/m): force and speed decay
    together, and x1 never falls through 0 on the way out. It 'ended' at
    73 ms with eps 5.5e-317 when x1 underflowed; now the run says it rests:
    no impact finished, the force and the speed below rounding of their
    peak and onset values, the momentum all in the dent (m v0 = c x2)."""
    r = fraccontact.impact(spring_exponent=1.0)
    assert r.stopped == "resting" and r.impacts == 0 and math.isnan(r.eps) and r.end.eps == 0.0
    assert abs(r.end.v) <= EPS * V0
    assert r.end.x2 == pytest.approx(M * V0 / 6080.0, rel=1e-12, abs=0)  # rounding over ~37 000 steps
    for mode in ((), ("--reference",)):
        out = solve_json("--spring-exponent", 1, *mode)
        assert out["stopped"] == "resting" and out["eps"] is None and out["impacts"] == 0, mode


def test_a_small_true_rebound_still_ends_its_impact():
    """The Hertz law with c = 100 rebounds at eps 2.4e-7 after 0.108 s
    (GSL agrees): a real separation, not a rest."""
    r = fraccontact.impact(c=100.0, law="hertz")
    ref = reference("--c", 100)
    assert r.stopped == "impacts" and r.eps == pytest.approx(ref["eps"], rel=1e-4, abs=0)



# ---------------------------------------------------------------- limits, Ctrl-C, rows' cost, options

def solve_limited(*args, seconds=30, cwd=None):
    """The solver with at most 2 GB of address space and `seconds` of time:
    code that would take the machine's memory or hours fails instead."""
    def limit():
        if os.environ.get("FRACCONTACT_SANITIZED") != "1":  # ASan reserves its shadow memory beyond any such limit
            resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    try:
        return subprocess.run([SOLVE, *map(str, args)], capture_output=True, text=True, timeout=seconds,
                              preexec_fn=limit, cwd=cwd)
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running after {seconds} s")


def refused(done, option):
    """Exit 2, one line on stderr naming the option, nothing on stdout."""
    assert done.returncode == 2, done.stderr
    assert done.stdout == "" and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(f"fraccontact-solve: {option}"), done.stderr
    return done.stderr


def test_rows_beyond_what_a_run_keeps_are_refused_up_front(tmp_path):
    """A row every picosecond over h20's contact is 1.2e9 rows."""
    out = tmp_path / "rows.csv"
    done = solve_limited("--csv", out, "--output-interval", "1e-12")
    why = refused(done, "--output-interval '1e-12': output_interval = 1e-12 is invalid: ")
    assert "1e+07" in why and "raise output_interval" in why
    assert list(tmp_path.iterdir()) == []


def test_an_output_interval_without_csv_is_refused():
    refused(solve("--output-interval", "1e-6", check=False), "--output-interval '1e-6': the time between the rows of --csv")


@pytest.mark.parametrize("args", [["--dt-max", "1e-15"], ["--dt-max", "1e-13", "--law", "hertz"]])
def test_a_run_beyond_a_billion_steps_is_refused_up_front(args):
    """--dt-max 1e-15 ran for hours printing nothing."""
    why = refused(solve_limited(*args), f"--dt-max '{args[1]}': dt_max = {float(args[1]):g} is invalid: ")
    assert "more than 1e+09" in why and "internal steps" in why


LONG_RUN = ["--dt-max", "1e-11"]   # 1.2e8 steps: about ten seconds


def test_ctrl_c_stops_a_solve_with_one_line_and_status_130(tmp_path):
    """SIGINT stops the solve within a fraction of a second; nothing
    is written; one line says why (no progress line off a terminal)."""
    out = tmp_path / "series.csv"
    p = subprocess.Popen([SOLVE, *LONG_RUN, "--csv", str(out), "--output-interval", "1e-6"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    ticks = os.sysconf("SC_CLK_TCK")
    with open(f"/proc/{p.pid}/stat") as f:   # CPU so far: utime and stime, fields 14 and 15
        asked = sum(int(x) for x in f.read().rsplit(")", 1)[1].split()[11:13]) / ticks
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.stdout.read(), p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    assert p.returncode == 130, stderr
    # stopped within a tenth of a second of CPU (and the clock's tick)
    assert usage.ru_utime + usage.ru_stime - asked < 0.1 + 2 / ticks
    assert stdout == "" and stderr.count("\n") == 1 and stderr.startswith("fraccontact-solve: interrupted (Ctrl-C) at t = ")
    assert list(tmp_path.iterdir()) == []


def test_a_long_solve_shows_its_progress_on_a_terminal_and_ctrl_c_stops_it():
    """On a terminal, after a few seconds of CPU, a line on stderr tells how
    far the solve is; Ctrl-C then stops it (status 130)."""
    pid, fd = pty.fork()
    if pid == 0:  # the child: the solver on the terminal
        os.execv(SOLVE, [SOLVE, *LONG_RUN])
    seen, start = b"", time.monotonic()
    try:
        while b"Ctrl-C stops" not in seen and time.monotonic() - start < 60:
            if select.select([fd], [], [], 0.1)[0]:
                seen += os.read(fd, 4096)
        os.kill(pid, signal.SIGINT)
        while True:
            try:
                chunk = os.read(fd, 4096)
            except OSError:  # the terminal closed with the solver
                break
            if not chunk:
                break
            seen += chunk
    finally:
        _, status = os.waitpid(pid, 0)
        os.close(fd)
    text = seen.decode()
    assert os.waitstatus_to_exitcode(status) == 130, text
    assert re.search(r"\r  t = [0-9.e+-]+ s of at most 1 s, [0-9]+ steps, 0 of 1 impacts \(Ctrl-C stops\)", text), text
    assert "interrupted (Ctrl-C)" in text


def test_the_springpots_csv_costs_about_what_its_solve_costs(tmp_path):
    """The run with --csv took 12.3 s of CPU against 0.014 s
    without; rows may cost about what steps cost. The ratio measured is in
    the report; 10 is a guard with room for a loaded machine."""
    args = ["--damper", "2", "--g", "9.81", "--impacts", "3", "--json"]
    without = json.loads(solve_limited(*args, "--repeat", 5).stdout)
    done = solve_limited(*args, "--csv", tmp_path / "bounces.csv", "--repeat", 5, seconds=120)
    with_rows = json.loads(done.stdout)
    assert with_rows["cpu_seconds"] < 10 * without["cpu_seconds"], (with_rows["cpu_seconds"], without["cpu_seconds"])
    assert without_timing(with_rows) == without_timing(without)


@pytest.mark.parametrize("args, says", [
    (["--law", "2.0"], "--law '2.0': one of g1, hertz, g1x or 1, 2, 3"),
    (["--scheme", "2.0"], "--scheme '2.0': one of gradient, central or 1, 2"),
    (["--scene", "3"], "--scene '3': one of drop, driven or 1, 2"),
    (["--c", "5000", "--c", "6000"], "--c given twice ('5000', then '6000')"),
    (["--c=5000", "--law", "2", "--c", "5000"], "--c given twice ('5000', then '5000')"),
    (["--json", "--json"], "--json given twice"),
    (["--reference", "--law", "g1"], "--law 'g1': --reference solves the continuous law: hertz, or g1 and g1x with "
                                     "--g1-nodes N > 0"),
    (["--reference", "--law", "3"], "--law '3': --reference solves the continuous law"),
    (["--reference", "--scheme", "central"], "--scheme 'central': --reference integrates with GSL, not with a scheme"),
    (["--reference", "--damper", "2"], "--damper '2': --reference integrates the dashpot (damper 1) only"),
    (["--rtol", "1e-9"], "--rtol '1e-9': the relative tolerance of --reference, which is not given")])
def test_options_the_solve_would_ignore_or_misread_are_refused(args, says):
    """One line naming the option, its value and the rule; exit 2."""
    refused(solve(*args, check=False), says)


@pytest.mark.parametrize("option, value", [("--dt-max", "1e-8"), ("--tolerance", "1e-6")])
def test_the_reference_warns_that_the_models_steps_change_nothing(option, value):
    done = solve("--reference", "--law", "hertz", option, value)
    assert done.stderr == (f"fraccontact-solve: warning: {option} '{value}' has no effect with --reference: GSL takes "
                           "its own steps (to --rtol)\n")
    given, default = solve_json("--reference", "--law", "hertz", option, value), solve_json("--reference", "--law", "hertz")
    for r in (given, default):
        del r["cpu_seconds"], r["params"][option[2:].replace("-", "_")]
    assert given == default


def test_the_reference_says_which_law_it_solves():
    """Without --law the reference solves the G1 law's continuous limit, the
    Hertz law, and says so; the same figures as --law hertz to the bit. With
    a fixed N it solves the G1 law on N intervals (docs/model.md §4): the
    model's figures at a fine step, not the Hertz law's."""
    assert solve("--reference").stdout.startswith("reference, law hertz,")
    hertz = without_timing(solve_json("--reference", "--law", "hertz"))
    assert without_timing(solve_json("--reference")) == hertz
    nodes = solve_json("--reference", "--law", "g1", "--g1-nodes", 10)
    model = solve_json("--law", "g1", "--g1-nodes", 10, "--dt-max", "1e-8")
    assert nodes["params"]["law"] == 1 and nodes["k"] == model["k"] == K
    # the model at dt 1e-8 errs by about 1e-11 in F_peak (second order, 1e-9 at 1e-7); 1e-8 is ample
    assert nodes["F_peak"] == pytest.approx(model["F_peak"], rel=1e-8, abs=0)
    # N = 10 stiffens the spring by Gamma(11.5)/(Gamma(10) 10^1.5) - 1 = 3.8 %: F_peak differs by percents
    assert abs(nodes["F_peak"] / hertz["F_peak"] - 1) > 1e-2
