"""The figures of the README and the guides of docs/ (tests/doc_pages.py),
measured. Each test finds its sentence on
whichever page holds it, reads the figure as written there, and measures it
on this build: a figure that drifts, or a sentence reworded without its test,
fails here. Figures are compared at the precision they are stated with:
"within X" and "up to X" are bounds, held within a decade (a bound ten times
too loose is a stale figure too); a bare "X" is a measurement, equal to the
measured value rounded to X's digits."""

import json
import math
import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

# The sweeps and plots these run import matplotlib, whose C++ extension does
# not load under the preloaded AddressSanitizer: the normal build checks them.
pytestmark = pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                                reason="matplotlib does not load under ASan")
from fmpy import simulate_fmu

import fraccontact
from doc_pages import all_blocks, prose, section

ROOT = pathlib.Path(__file__).resolve().parent.parent
PROSE = prose()  # every page's sentences, as one line each
FMU = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
FIGURES = ("F_peak", "eps", "x2", "E_diss")


def claim(pattern):
    """The pages' match of pattern (whitespace as one space): its groups."""
    m = re.search(pattern, PROSE)
    assert m, f"no page says {pattern!r} any more: update the sentence's test with it"
    return m.groups()


def number(text):
    return float(text.rstrip(".,;:"))


def assert_bound(measured, stated, what):
    """A stated bound 'within X' / 'up to X': it holds, and not ten times over."""
    assert measured <= stated, f"{what}: measured {measured:.3g}, README says at most {stated:g}"
    assert measured > stated / 10, f"{what}: measured {measured:.3g}, the README's bound {stated:g} is stale"


def assert_figure(measured, stated, what):
    """A stated measurement (the README's text): the measured value rounded to its digits."""
    digits = stated_digits(stated)
    assert float(f"{measured:.{digits - 1}e}") == value(stated), f"{what}: measured {measured:.3g}, README says {stated}"


# --- the FMU state's size --------------------------------------------------------

def test_the_readme_state_sizes_are_the_fmus(slave):
    """fmi2SerializedFMUstateSize through fmpy, at the defaults (the
    springpot's compressed memory) and for the dashpot."""
    springpot, dashpot = map(int, claim(r"fixed size \((\d+) bytes at the defaults, against (\d+) for the dashpot\)"))

    def size(**values):
        s = slave(**values)
        return len(s.fmu.serializeFMUstate(s.fmu.getFMUstate()))

    assert (size(damper=2), size()) == (springpot, dashpot)


# --- alpha = 1 against the dashpot -------------------------------------------------

def drop(stop, **start):
    """Every output of the FMU's drop test at every 10 us."""
    return simulate_fmu(str(FMU), stop_time=stop, output_interval=1e-5, start_values=start)


def relative_difference(a, b, name):
    """Largest difference of an output over the run, relative to its largest value."""
    return float(np.max(np.abs(a[name] - b[name])) / np.max(np.abs(a[name])))


@pytest.mark.parametrize("law", [1, 2])
def test_alpha_1_is_the_dashpot_as_the_readme_says(law):
    """With c_alpha = c: F, v_striker, x1, x2, E_diss (and so F_peak, eps)
    bit for bit at every communication point of the impact; over nine
    bounces under gravity eps, x2, E_diss within the README's bound. Independent of either damper's code: the two runs are
    different arithmetic of one model, and docs/model.md §5's springpot at
    alpha = 1 is the dashpot."""
    assert "dent and dissipated energy to the last bit over an impact" in PROSE
    stop, impacts, later = claim(r"bouncing under gravity \((\S+) s, (\w+) impacts\), eps, x2 and E_diss stay within (\S+) of")
    springpot = dict(damper=2, damper_order=1.0, c_alpha=6080.0, memory=2)
    dashpot, alpha_1 = drop(3e-3, law=law), drop(3e-3, law=law, **springpot)
    for name in ("F", "F_avg", "F_peak", "x1", "v_striker", "eps", "semi_integral", "x2", "E_diss"):
        assert np.array_equal(dashpot[name], alpha_1[name]), name
    dashpot, alpha_1 = drop(number(stop), law=law, g=9.81), drop(number(stop), law=law, g=9.81, **springpot)
    eps = [r["eps"][np.r_[True, np.diff(r["eps"]) != 0]][1:] for r in (dashpot, alpha_1)]  # each impact's
    assert len(eps[0]) == len(eps[1]) == {"nine": 9}[impacts]
    worst = max([float(np.max(np.abs(eps[1] / eps[0] - 1)))]
                + [relative_difference(dashpot, alpha_1, n) for n in ("x2", "E_diss")])
    assert_bound(worst, number(later), "eps, x2, E_diss over the bounces")


# --- the communication step ---------------------------------------------------------

def figures_at(H, law, stop=4e-3, **start):
    """F_peak, eps, x2, E_diss after the impact, as `fmpy simulate
    --output-interval H` gives them (its steps t_k+1 - t_k included)."""
    r = simulate_fmu(str(FMU), stop_time=stop, output_interval=H, start_values=dict(start, law=law),
                     output=list(FIGURES))
    return np.array([r[name][-1] for name in FIGURES])


def library(law, **start):
    r = fraccontact.impact(law=law, **start)
    return np.array([r.F_peak, r.eps, r.x2_end, r.E_diss])


def spread(rows):
    """The largest relative difference between any two rows, over the figures."""
    rows = np.array(rows)
    return float(np.max((rows.max(axis=0) - rows.min(axis=0)) / np.abs(rows).min(axis=0)))


INTERVALS = (1e-7, 1e-6, 1e-5, 3e-5, 1e-4, 1e-3)  # whole multiples of dt_max = 1e-7 s


def test_the_intervals_are_the_readmes():
    low, high = claim(r"agree to rounding: within \S+ for intervals from (\S+) s to (\S+) ms")
    assert (min(INTERVALS), max(INTERVALS)) == (number(low), number(high) * 1e-3)
    assert claim(r"move with the interval \((\S+) s to (\S+) ms\)") == (low, high)


@pytest.mark.parametrize("law", [1, 2])
def test_contact_on_a_communication_point_gives_the_same_figures_at_every_interval(law):
    (bound,) = claim(r"agree to rounding: within (\S+) for intervals from")
    assert_bound(spread([figures_at(H, law) for H in INTERVALS]), number(bound), f"law {law}, gap0 = 0")


def test_with_a_gap_the_figures_move_within_the_laws_error():
    """The onset falls inside a communication step, and its first internal
    steps end on the next communication point: law 2 moves at its O(h^2)
    error, law 1 at the O(1/N) of its step count, and so far from the
    library, which steps dt_max from the onset."""
    (hertz,) = claim(r"by up to (\S+) with the closed-form Hertz law")
    (g1,) = claim(r"by up to (\S+) with the G1 law \(`law = 1`\)")
    assert "they differ from the library's as much" in PROSE
    for law, stated in ((2, hertz), (1, g1)):
        at = [figures_at(H, law, gap0=1e-3) for H in INTERVALS]
        assert_bound(spread(at), number(stated), f"law {law}, gap0 = 1e-3, across intervals")
        lib = library(law, gap0=1e-3)
        assert max(spread([lib, fmu]) for fmu in at) <= number(stated), f"law {law}: the library"


def test_an_interval_off_the_grid_of_dt_max_moves_the_figures_by_the_laws_error():
    H, hertz, g1 = claim(r"at (\S+) s \(steps of \S+ s\) the figures of the default drop test move from those at "
                         r"1e-5 s by (\S+) with law 2, and by (\S+) with law 1")
    for law, stated in ((2, hertz), (1, g1)):
        moved = spread([figures_at(number(H), law), figures_at(1e-5, law)])
        assert_figure(moved, stated, f"law {law} at H = {H}")


def test_a_masters_step_computed_from_its_clock_cuts_no_extra_internal_step(slave):
    """fmpy steps by t_k+1 - t_k, which errs by an ulp of t: past t ~ 1e4 H
    that exceeds a whole multiple of dt_max by more than a relative 1e-12,
    and the FMU cut such a step into two (law 1 then moved by 6e-6 at
    H = 1e-7 s). Steps of exactly H and steps from the clock must give the
    same internal steps: the figures to rounding (a few ulp per step over
    some 2.4e4 steps, 1e-12 leaves room)."""
    H = 1e-7
    exact, clock = slave(law=1, gap0=1e-3), slave(law=1, gap0=1e-3)
    for k in range(round(4e-3 / H)):
        exact.fmu.doStep(currentCommunicationPoint=k * H, communicationStepSize=H)
        clock.fmu.doStep(currentCommunicationPoint=k * H, communicationStepSize=(k + 1) * H - k * H)
    for name in FIGURES:
        assert clock.get(name) == pytest.approx(exact.get(name), rel=1e-12, abs=0), name


# --- stale figures ------------------------------------------------------------------

def table_rows(text, first_cell):
    """Cells of the markdown table rows whose first cell contains first_cell."""
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in text.splitlines()
            if line.startswith("|")]
    return [r for r in rows if first_cell in r[0]]


def springpot_figures(r):
    return np.array([r.F_peak, r.eps, r.t_contact, r.x2_end])


def test_the_springpot_table_of_error_controlled_steps():
    """'Error-controlled steps': the h20 springpot (law 2, alpha 0.5) at fixed
    steps and two tolerances: the internal steps exactly, each figure's error
    against the full G1 history at 6.25e-8 and 3.125e-8 s extrapolated
    (second order: (4 f_fine - f_coarse) / 3) to its two digits, and the CPU
    ratios between the rows within a factor 2 (CPU itself is this machine's:
    a shared machine moves it by up to 30 %, ratios less)."""
    text = section("Error-controlled steps: `tolerance`")
    assert "full G1 history at 6.25e-8 and 3.125e-8 s extrapolated" in " ".join(text.split())
    base = dict(damper=2, law=2, height=0.02)
    coarse, fine = (springpot_figures(fraccontact.impact(memory=1, dt_max=dt, **base)) for dt in (6.25e-8, 3.125e-8))
    reference = (4 * fine - coarse) / 3
    rows = table_rows(text, "`dt_max` = 1e-")
    assert len(rows) == 3, rows
    cpu = []
    for label, steps, seconds, *errors in rows:
        tolerance = re.search(r"`tolerance` = (\S+),", label)
        settings = dict(dt_max=number(re.search(r"`dt_max` = (\S+) s", label).group(1)),
                        tolerance=number(tolerance.group(1)) if tolerance else 0.0)
        r = fraccontact.impact(**base, **settings)
        assert r.steps == int(steps.replace(" ", "")), (label, r.steps)
        measured = np.abs(springpot_figures(r) / reference - 1)
        for name, stated, error in zip(("F_peak", "eps", "t_contact", "x2_end"), errors, measured):
            assert_figure(error, stated, f"{label}: {name}")
        solve = subprocess.run([SOLVE, "--damper", "2", "--law", "2", "--height", "0.02", "--dt-max",
                                str(settings["dt_max"]), "--tolerance", str(settings["tolerance"]), "--repeat", "50",
                                "--json", "--quiet"], capture_output=True, text=True, timeout=120)
        assert solve.returncode == 0, solve.stderr
        value, unit = seconds.split()
        cpu.append((number(value) * {"ms": 1e-3, "µs": 1e-6}[unit], json.loads(solve.stdout)["cpu_seconds"]))
    for stated, measured in cpu[1:]:
        ratio = (cpu[0][0] / stated) / (cpu[0][1] / measured)
        assert 0.5 < ratio < 2, (cpu, ratio)
    (times,) = claim(r"its error is bounded relative to the elastic indentation \((\S+) times `x2_end` here\)")
    run = fraccontact.simulate(output_interval=1e-6, **base)
    assert_figure(float(np.max(run["x1"])) / fraccontact.impact(**base).x2_end, times, "x1 / x2_end")


def test_the_number_of_modes():
    """M = 59 at the defaults (in the variable table and the springpot
    section), 67 when error-controlled steps fit the kernel from 1e-9 s, at
    most 155 (over alpha) at memory_tolerance 1e-12."""
    table = variable_table_row("memory")
    (M,) = re.findall(r"M = (\d+) at the defaults", table)
    (again,) = claim(r"and 1000 s: M = (\d+) at the defaults")
    (controlled, most) = claim(r"\(M = (\d+) at the defaults; at most (\d+) at the tightest `memory_tolerance`, 1e-12\)")
    assert len(fraccontact.memory_kernel()[0]) == int(M) == int(again)
    assert len(fraccontact.memory_kernel(law=2, tolerance=1e-6)[0]) == int(controlled)
    counts = [len(fraccontact.memory_kernel(law=2, tolerance=1e-6, memory_tolerance=1e-12, damper_order=alpha)[0])
              for alpha in np.linspace(0.001, 0.999, 999)]
    assert max(counts) == int(most)


def variable_table_row(name):
    """The row of docs/variables.md's 'What each variable does'."""
    [row] = [line for line in section("What each variable does").splitlines() if line.startswith(f"| `{name}` |")]
    return row


def test_the_cost_per_step_is_the_benchmarks():
    """'How it computes' and the docs list quote docs/benchmarks.md's cost per
    internal step (to the ns), an h20 impact's, and the springpot's; the h20
    contact's steps at dt_max = 1e-7 s are counted here."""
    bench = (ROOT / "docs" / "benchmarks.md").read_text()

    def ns(row):
        return float(re.search(r"\| " + re.escape(row) + r"[^|]*\| ([\d.,]+) \|", bench).group(1).replace(",", ""))

    hertz, g1 = ns("Hertz (law 2)"), ns("G1, O(1) closed form of the straight-line sum (law 1)")
    springpot = float(re.search(r"\| springpot, compressed memory [^|]*\| [\d,]+ \| ([\d.]+) \|", bench).group(1))
    law2, law1 = claim(r"About (\d+) ns per internal step for law 2 and (\d+) ns for law 1")
    steps, ms, compressed = claim(r"an h20 impact at `dt_max` = 1e-7 s \(([\d ]+) steps\) costs about (\S+) ms; a "
                                  r"springpot's compressed memory about (\d+) ns per step")
    listed_hertz, listed_g1 = claim(r"about (\d+) ns per internal step \(Hertz\), (\d+) ns \(G1\)")
    assert (int(law2), int(law1)) == (int(listed_hertz), int(listed_g1)) == (round(hertz), round(g1))
    assert int(compressed) == round(springpot)
    assert_figure(float(re.search(r"instead of ([\d.]+) ms", bench).group(1)), ms, "h20 impact's CPU")
    for law in (1, 2):
        assert math.ceil(fraccontact.impact(law=law).t_contact / 1e-7) == int(steps.replace(" ", ""))


def numbers_in(text):
    """The numbers of a text as written: 25 400, 1.2e-9, 0.93, 3200."""
    return [m.rstrip(" ,") for m in re.findall(r"(?<![\w.])\d(?:[\d ,]*\d)?(?:\.\d+)?(?:e[−-]?\d+)?", text)]


def value(text):
    return float(text.replace(" ", "").replace(",", "").replace("−", "-"))


def stated_digits(text):
    mantissa = re.sub(r"e.*", "", text.replace(" ", "").replace(",", "")).replace(".", "").lstrip("0")
    return max(1, len(mantissa))


REPORT_BULLETS = [b for b in re.split(r"\n- ", section("Accuracy, stability and speed (docs/)"))[1:]]


@pytest.mark.parametrize("bullet", REPORT_BULLETS, ids=[re.search(r"docs/(\w+)\.md", b).group(1) for b in REPORT_BULLETS])
def test_the_docs_list_quotes_its_reports(bullet):
    """Each figure of the README's summary of a report is one the report
    states, at the README's digits (a weak check: a small integer may match
    an unrelated one, but a stale figure rarely survives it)."""
    report = (ROOT / "docs" / re.search(r"`docs/(\w+\.md)`", bullet).group(1)).read_text()
    there = {value(n) for n in numbers_in(report)}
    missing = [n for n in numbers_in(" ".join(bullet.split()))
               if value(n) != 0 and not any(y != 0 and float(f"{y:.{stated_digits(n) - 1}e}") == value(n) for y in there)]
    assert not missing, f"not in the report: {missing}"


def test_parameters_lists_what_the_readme_says():
    """'In Python': the names fraccontact.parameters() lists, and height beside them."""
    (listed,) = claim(r"named as the FMU's variables \((.*?), which `fraccontact.parameters\(\)` lists")
    assert set(re.findall(r"`(\w+)`", listed)) == {p["name"] for p in fraccontact.parameters()}
    assert "and `height`, the drop height [m] that sets `v`" in PROSE
    assert fraccontact.impact(height=0.02).F_peak == fraccontact.impact(v=fraccontact.drop_velocity(0.02)).F_peak


def test_sweep_json_holds_statistics_for_monte_carlo_only(tmp_path):
    """The README: counts and throughput, statistics for a Monte Carlo campaign
    (tests/test_sweep.py checks those statistics against numpy)."""
    assert "for a Monte Carlo campaign also `statistics`: for every numeric column" in PROSE
    from fraccontact import sweep
    assert sweep.main(["--vary", "c=3000,6080", "--set", "law=hertz", "--workers", "1", "--out", str(tmp_path)]) in (0, None)
    assert "statistics" not in json.loads((tmp_path / "sweep.json").read_text())


# The README's fit commands and their example data (docs/examples/).

EXAMPLES = ROOT / "docs" / "examples"


def fit_commands():
    """(command, the output lines its comments show) of 'Calibrate from your drop tests'."""
    commands = []
    for block in re.findall(r"```sh\n(.*?)```", section("Calibrate from your drop tests"), re.S):
        for line in block.replace("\\\n", " ").splitlines():
            if line.startswith("fraccontact fit"):
                commands.append((" ".join(line.split()), []))
            elif line.startswith("# "):
                commands[-1][1].append(line[2:].rstrip(". ").rstrip())
    return commands


@pytest.mark.parametrize("command, shown", fit_commands(), ids=[c for c, _ in fit_commands()])
def test_the_readme_fit_commands_print_what_they_say(command, shown, tmp_path):
    """Run as written, from a fresh folder, on the shipped example files:
    exit 0, and each comment line is the start of a line it prints."""
    argv = [a.replace("docs/examples/", f"{EXAMPLES}/") for a in command.split()[2:]]
    run = subprocess.run([sys.executable, "-m", "fraccontact", "fit", *argv], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    printed = [line.rstrip() for line in run.stdout.splitlines()]
    for line in shown:
        assert any(p.startswith(line) for p in printed), f"{line!r} not in:\n{run.stdout}"


def test_the_readmes_fit_commands_are_the_guides():
    """The README's fit commands are among docs/fitting.md's, which the test above runs."""
    shown = {c for c, _ in fit_commands()}
    readme = [" ".join(line.split()) for block in re.findall(r"```sh\n(.*?)```", section("Calibration"), re.S)
              for line in block.splitlines() if line.startswith("fraccontact fit")]
    assert readme and set(readme) <= shown, set(readme) - shown


def load_make_examples():
    import importlib.util
    spec = importlib.util.spec_from_file_location("make_examples", EXAMPLES / "make_examples.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_example_files_are_what_their_script_makes():
    """The shipped CSVs are the model's (this build's FMU) with the script's
    seeds: the same rows to their 6 printed digits."""
    made = load_make_examples().examples(FMU)
    assert sorted(made) == sorted(p.name for p in EXAMPLES.glob("*.csv"))
    for name, (header, rows) in made.items():
        shipped = np.loadtxt(EXAMPLES / name, delimiter=",", skiprows=1)
        assert (EXAMPLES / name).read_text().splitlines()[0] == header
        assert np.allclose(shipped, np.array(list(rows)), rtol=1e-5, atol=1e-5), name


def test_the_examples_are_made_from_the_readmes_constants():
    """The constants the README names, and the dashpot fit finding them within
    two standard errors (k, c and the trigger's 50 us)."""
    made = load_make_examples()
    k, c = claim(r"`h20_dashpot.csv` from k = (\S+) N/m\^1.5 and c = (\S+) N·s/m, which the fit above finds "
                 r"within two standard errors")
    sp_k, alpha, c_alpha = claim(r"The springpot's examples: k = (\S+) N/m\^1.5, alpha = (\S+), c_alpha = (\S+) N·s\^alpha/m")
    assert (number(k), number(c), number(sp_k), number(alpha)) == (made.K, made.C, made.K, made.ALPHA)
    assert_figure(made.C_ALPHA, c_alpha, "c_alpha")
    from fraccontact import fit
    t, F = np.loadtxt(EXAMPLES / "h20_dashpot.csv", delimiter=",", skiprows=1).T
    r = fit.fit_curve(t, F, made.M, made.speed(0.020))
    for name, truth in (("k", made.K), ("c", made.C), ("t0", made.TRIGGER)):
        assert abs(r[name] - truth) < 2 * r[f"sigma_{name}"], (name, r[name], truth, r[f"sigma_{name}"])


# The README's printed examples and the paper's Table 1.

def output_block_after(text, lead):
    """The plain ``` block that follows the line containing lead."""
    after = text.split(lead, 1)[1]
    return re.search(r"```\n(.*?)```", after, re.S).group(1).splitlines()


def shown_in(shown, printed):
    """The shown lines missing from printed (each shown line, its trailing '...' cut, starts a printed line)."""
    printed = [" ".join(line.split()) for line in printed]
    return [line for line in shown
            if not any(p.startswith(" ".join(line.rstrip(". ").split()).rstrip(",")) for p in printed)]


def test_the_run_command_prints_the_readme_table(tmp_path):
    shown = output_block_after(section("Two commands"), "`scripts/run` prints the figures")
    run = subprocess.run([sys.executable, "-m", "fraccontact", "run", "--out", str(tmp_path), "--fmu", str(FMU)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert not shown_in(shown, run.stdout.splitlines()), run.stdout


def test_the_solver_prints_the_readme_table():
    command = "build/fraccontact-solve --g 9.81 --impacts 3"
    shown = output_block_after(section("The solver: fraccontact-solve"), f"`{command}`, prints:")
    run = subprocess.run([SOLVE, *command.split()[1:]], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert not shown_in(shown, run.stdout.splitlines()), run.stdout


def solve_json(*options):
    run = subprocess.run([SOLVE, *options, "--json", "--quiet"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def test_the_defaults_against_the_papers_table_1():
    """The model's h20 figures against the paper's 1004 N and 0.59, law 1
    against GSL's solution of the same ODE, the paper's central scheme, and
    k from the materials."""
    text = " ".join(section("The defaults against the paper's Table 1").split())
    F_peak, eps = re.search(r"the model gives \*\*F_peak = (\S+) N and eps = (\S+)\*\*", text).groups()
    more, less = re.search(r"\*\*\+(\S+) % in peak force, −(\S+) in restitution\*\*", text).groups()
    r = fraccontact.impact()
    assert_figure(r.F_peak, F_peak, "F_peak")
    assert_figure(r.eps, eps, "eps")
    assert_figure(100 * (r.F_peak / 1004 - 1), more, "+% in F_peak")
    assert_figure(0.59 - r.eps, less, "-eps")
    g1_F, g1_eps = re.search(r"differs from it by (\S+) \(F_peak\) to (\S+) \(eps\)", text).groups()
    reference = solve_json("--reference")
    assert_figure(abs(r.F_peak / reference["F_peak"] - 1), g1_F, "law 1's F_peak")
    assert_figure(abs(r.eps / reference["eps"] - 1), g1_eps, "law 1's eps")
    fine, fine_dt, coarse, coarse_dt = re.search(r"(\S+) N at Δt = (\S+) s, (\S+) N at (\S+) s", text).groups()
    for F, dt in ((fine, fine_dt), (coarse, coarse_dt)):
        assert_figure(solve_json("--scheme", "central", "--dt-max", dt)["F_peak"], F, f"central at {dt}")
    k, below = re.search(r"the formula gives `k` = (\S+), (\S+) % below", text).groups()
    derived = fraccontact.impact(k=0.0).k
    assert_figure(derived, k, "k from the materials")
    assert_figure(100 * (1 - derived / 3.299e8), below, "% below 3.299e8")


def cosim_commands():
    """The `fraccontact cosim` lines of the guides' shell blocks, without their comments."""
    return [line.split("#")[0].split() for _, _, lang, body in all_blocks() if lang == "sh"
            for line in body.splitlines() if line.startswith("fraccontact cosim ")]


@pytest.mark.parametrize("argv", cosim_commands(), ids=lambda argv: " ".join(argv[2:]))
def test_the_guides_cosim_commands_run_against_their_reference(argv, tmp_path):
    """Run as written: exit 0, the figures and the reference they are judged
    by in the JSON, and no energy created where docs/coupling.md says none is
    (a force the contact does not know, `--k-s`, creates some of first order
    in H, or second with --feed-a; the zero-order hold `zoh` under a Jacobi
    master pumps it through its lag)."""
    run = subprocess.run([sys.executable, "-m", "fraccontact", *argv[1:]], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert {"F_peak", "eps", "energy_error"} <= out.keys() and out.keys() & {"monolithic", "reference"}, out.keys()
    if "--k-s" not in argv and "zoh" not in argv:
        assert out["energy_error"] <= 1e-12, f"{' '.join(argv)} created energy: {out['energy_error']:.3g}"
