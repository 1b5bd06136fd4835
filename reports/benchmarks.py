"""Benchmarks, measured side by side in one run on this machine:
  1. ns per internal step of each spring law (and of the literal O(N) G1 sum);
  2. work against precision on one impact to the last bit: our
     error-controlled steps, our fixed steps, the GSL rk8pd anchor and
     scipy's solve_ivp (LSODA, DOP853, Radau) over their tolerance or step
     ladders, judged on the largest error of F_peak, eps, t_contact and
     x2_end (h20) or of F_peak (the soft dashpot over 10 ms); the cheapest
     setting of each meeting 1e-6, timed head to head; the FMU's CPU for
     one impact in one doStep, error-controlled against fixed steps;
  3. the bare G1 history sum of f(x) = x, N = 1e3 to 1e6, newest point and
     full grid, against the PyPI package differint, each result checked at
     every grid point against the closed form of docs/model.md §4;
  4. the Python package against the C core: fraccontact.impacts against
     fraccontact-bench batch (CPU per impact), a process per impact,
     fraccontact sweep on 1 and 2 local Dask workers, a 1000-row curve fit;
  5. the springpot: ns per internal step of the dashpot, the
     compressed memory and the full G1 history over the h20 impact; a
     springpot impact by both memories on N = 1e3 .. 1e6 steps of one span
     (the full history's N = 1e6 run, O(N^2), timed once: about 10 minutes),
     their F_peak and eps agreement; the FMU state sizes; and the dashpot on
     this build against the commit before the springpot (BASE, built in a
     temporary git worktree), side by side.
Writes docs/benchmarks.md and docs/benchmarks_work_precision.png. Medians of
repeated runs; CPU time of one process for 1 to 3, 5 and the per-impact costs
of 4, wall time for 4's sweeps and fit.

Regenerate: scripts/report benchmarks   (about 20 minutes)
            scripts/report benchmarks --only steps       (section 1 alone, in place)
            scripts/report benchmarks --only precision   (section 2 alone, in place)
            scripts/report benchmarks --only package     (section 4 alone, in place)
            scripts/report benchmarks --only springpot   (section 5 alone, in place)
            scripts/report benchmarks --only instructions  (the instruction counts alone, in place)
            scripts/report benchmarks --only exchange  (Model Exchange against co-simulation, and with and
                                                        without the directional derivatives, in place)
"""

import contextlib
import json
import math
import os
import pathlib
import platform
import shutil
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np
from scipy.special import gamma

import differint.differint as differint

from fraccontact import atomic, fit, fmu, model, output, solver
from fraccontact.scipy_contact import solve_drop
from reports import source_tree

plt = output.pyplot()

TARGET = 1e-6
# Section 4: (label, law, dt_max, impacts in one fraccontact.impacts call,
# impacts in a sweep). The cheap setting is the coarsest accurate to 1e-6.
SETTINGS = (("cheap: law 2 (Hertz), dt_max 3e-6", 2, 3e-6, 2000, 20000),
            ("default: law 1 (G1), dt_max 1e-7", 1, 1e-7, 300, 4000))
PROCESSES = 300  # impacts run as one fraccontact-solve process each
REPEATS = 3
FIT_ROWS = 1000
BEGIN, END = "<!-- package: begin -->", "<!-- package: end -->"
STEPS_BEGIN, STEPS_END = "<!-- step costs: begin -->", "<!-- step costs: end -->"
SPRINGPOT_BEGIN, SPRINGPOT_END = "<!-- springpot: begin -->", "<!-- springpot: end -->"
CONTROLLED_BEGIN, CONTROLLED_END = "<!-- controlled springpot: begin -->", "<!-- controlled springpot: end -->"
CONTROLLED_TOLERANCES = (1e-6, 1e-8)
CONTROLLED_REFERENCE = 1e-11  # the figures' reference: the same impact at this tolerance
# the dashpot's tolerances, four a decade, for the springpot's accuracy at the dashpot's cost
CONTROLLED_LADDER = tuple(float(f"{10 ** (-6 - k / 4):.2g}") for k in range(17))
CONTROLLED_FIGURES = ("F_peak", "eps", "t_contact", "x2_end", "E_diss")
CONTROLLED_BAR = 3.0  # the target: the springpot's impact at most 3x the dashpot's
# The steps against the springpot's order at the tightest tolerance: c_alpha
# scaled as the default pair (c 6080, c_alpha 3e5 at alpha 0.5) is, so that
# the damping at the impact's frequency stays the dashpot's.
CONTROLLED_ORDERS = (1.0, 0.9, 0.7, 0.5)
CONTROLLED_MEMORY_TOLERANCES = (1e-3, 1e-6, 1e-10)  # and against the kernel's accuracy (its number of modes)
# The sweep at scale's section: written by scripts/report sweep_scaling, kept here.
SWEEP_BEGIN, SWEEP_END = "<!-- sweep_scaling: begin -->", "<!-- sweep_scaling: end -->"
# Section 5: the commit before the springpot, whose dashpot this build's must
# match; rounds alternating its fraccontact-bench and this build's.
BASE = "65bf8cb"
BASE_ROUNDS = 7
REGENERATE = ("Regenerate: `scripts/report benchmarks` (about 20 minutes; the work against precision alone: "
              "`scripts/report benchmarks --only precision`, about 1; the springpot's section alone: "
              "`scripts/report benchmarks --only springpot`, about 12)")


def say(text):
    print(text, file=sys.stderr, flush=True)


def run(program, *args):
    try:
        return solver.run_json(program, *args)
    except solver.Failed as e:
        raise SystemExit(str(e)) from None


def solve(program, *args):
    return run(program, *args, "--json", "--quiet")


def median_cpu(fn, budget=0.3, at_least=5):
    times = []
    while len(times) < at_least or (sum(times) < budget and len(times) < 1000):
        start = time.process_time()
        fn()
        times.append(time.process_time() - start)
    return float(np.median(times))


def first_setting_that_stays_within(settings, error):
    """The coarsest setting from which on every finer one meets TARGET too."""
    chosen = None
    for s in reversed(settings):  # finest first
        if error(s) > TARGET:
            break
        chosen = s
    return chosen


# --- 1. ns per internal step -------------------------------------------------

def step_costs(bench):
    return run(bench, "step")


def steps_section(steps):
    """Section 1, between its markers: the ns per internal step of each
    spring law, the literal O(N) sum's, and the 1-minute load while it ran."""
    h = steps["ns_per_step"]
    lit = steps["ns_literal_sum"]
    out = [STEPS_BEGIN, "## Cost of an internal step", "",
           "Regenerate this section alone, in place: `scripts/report benchmarks --only steps` (under a minute; "
           f"this run's 1-minute load average {steps['load']:.2f} on {os.cpu_count()} cores). "
           "The h20 contact (dt = 1e-7 s, 13 160 steps), 100 internal steps per `contact_advance` call as the FMU "
           "takes them with a 10 us communication step (`fraccontact-bench step`).", "",
           "| spring law | ns per internal step |", "|---|---|",
           f"| G1, O(1) closed form of the straight-line sum (law 1) | {h['g1']:.1f} |",
           f"| Hertz (law 2) | {h['hertz']:.1f} |",
           f"| G1 + Richardson, two closed forms (law 3) | {h['g1x']:.1f} |", "",
           "The literal O(N) G1 sum, which the closed form replaces (and is tested against to 1e-12), costs per "
           "evaluation:", "",
           "| N | ns per literal sum | as a share of a law-1 step |", "|---|---|---|"]
    for N, ns in lit.items():
        out.append(f"| {int(N):,} | {ns:.0f} | {ns / h['g1']:.0f}x |")
    total = sum(lit["13160"] * n / 13160 for n in range(1, 13161)) * 1e-9
    return out + ["", f"Summed literally at every step (N = steps since onset), an h20 impact at dt = 1e-7 s would "
                  f"cost about {total:.1f} s instead of {h['g1'] * 13160 * 1e-6:.2f} ms.", "", STEPS_END]


def measured_steps(bench):
    """step_costs, with the load it ran under."""
    with LoadWatch() as load:
        steps = step_costs(bench)
    return dict(steps, load=float(np.median(load.samples)))


# --- 2. work against precision ---------------------------------------------------
#
# Every method solves the same impact, to the last bit: the parameters are
# read back from the reference's own run (--height 0.02 makes v = sqrt(2 g h)
# exactly; the default v is rounded), and each run is judged on the largest
# relative error of the case's figures against that reference.

FIGURES = ("F_peak", "eps", "t_contact", "x2_end")
# The stiff case: a soft dashpot, 10 ms of a contact that lasts
# about 0.3 s, judged on F_peak alone (over 10 ms no impact has ended).
SOFT = dict(k=3.299e8, c=50.0, m=0.7437, v=3.0, t_end=0.01)
REFERENCE_RTOL = 1e-14


def half_decades(loosest, tightest):
    """1e-3, 3e-4, 1e-4, ... 10^tightest (exponents given): a ladder finer than
    decades, so that no method's cheapest setting is off by a whole decade."""
    out = []
    for e in range(loosest, tightest - 1, -1):
        out.append(float(f"1e{e}"))
        if e > tightest:
            out.append(float(f"3e{e - 1}"))
    return out


ADAPTIVE_TOLERANCES = half_decades(-3, -10)
RTOLS = half_decades(-3, -12)
FIXED_STEPS = [1e-5 / 2 ** i for i in range(10)]
ADAPTIVE_DT_MAX = 1e-3
SCIPY_METHODS = ("LSODA", "DOP853", "Radau")
TIMING_BUDGET = 0.2   # seconds of repeats behind one timing
LADDER_SECONDS = 2.0  # a ladder stops after a setting costing more per impact: the tighter ones cost more still
ROUNDS = 7            # head-to-head rounds of the cheapest settings
FMU_H = 2e-3          # one doStep over the whole h20 contact (1.32 ms)
# The FMU's settings: label, tolerance, dt_max, one-doStep impacts a round.
# The target names tolerance 1e-6; 5e-8 is docs/numerics.md's setting for the four
# figures within 1e-6 (a twentieth of the target), so it is measured too.
FMU_FIXED = "fixed: tolerance 0, dt_max 1e-7 s (the defaults)"
FMU_SETTINGS = (("adaptive: tolerance 1e-6, dt_max 1e-3 s", 1e-6, 1e-3, 60),
                ("adaptive: tolerance 5e-8, dt_max 1e-3 s", 5e-8, 1e-3, 60),
                (FMU_FIXED, 0.0, 1e-7, 6))
PRECISION_BEGIN, PRECISION_END = "<!-- precision: begin -->", "<!-- precision: end -->"
PRECISION_FIGURE = "benchmarks_work_precision.png"
ADAPTIVE, FIXED = "ours, adaptive: ESDIRK 5(4), dt_max 1e-3 s", "ours, fixed discrete-gradient steps"
ANCHOR, LSODA = "GSL rk8pd anchor", "scipy LSODA"


def solver_figures(r, figures):
    """The first impact's figures from fraccontact-solve's JSON; F_peak the
    run's largest force (the soft case's impact has not ended at t_end)."""
    return {f: r["end"]["F_peak"] if f == "F_peak" else r[f] for f in figures}


def precision_cases(program):
    """h20 on all four figures, and the soft dashpot over 10 ms on F_peak;
    each with its reference and the physics every method is given."""
    soft = ["--k", SOFT["k"], "--c", SOFT["c"], "--m", SOFT["m"], "--v", SOFT["v"]]
    cases = []
    for name, args, figures in (("h20", ["--height", 0.02], FIGURES),
                                ("soft", soft + ["--t-end", SOFT["t_end"]], ("F_peak",))):
        args = ["--law", "hertz", *args]
        ref = solve(program, *args, "--reference", "--rtol", REFERENCE_RTOL)
        p = ref["params"]
        cases.append(dict(name=name, solve=args, figures=figures, reference=ref, want=solver_figures(ref, figures),
                          physics=dict(k=ref["k"], c=p["c"], m=p["m"], v0=p["v"], t_end=p["t_end"])))
    whole = solve(program, "--law", "hertz", *soft, "--reference", "--rtol", REFERENCE_RTOL)
    cases[1]["separates_at"] = whole["t_contact"]
    return cases


def repeats_for(seconds):
    return int(min(2001, max(5, TIMING_BUDGET / max(seconds, 1e-7))))


def ours(program, case, options):
    """fraccontact-solve: the figures of one run, and a timer: the median of
    --repeat runs, as the solver times the solve alone."""
    args = [*case["solve"], *options]
    first = solve(program, *args)
    n = repeats_for(first["cpu_seconds"])
    return (solver_figures(first, case["figures"]), first["steps"],
            lambda: solve(program, *args, "--repeat", n)["cpu_seconds"])


def gsl_anchor(bench, case, rtol):
    """fraccontact-bench anchor: the figures, right-hand sides, and a timer
    (its median of n impacts, each timed in C around the impact)."""
    p = case["physics"]
    args = ["anchor", p["k"], p["c"], p["m"], p["v0"], p["t_end"], rtol]
    first = run(bench, *args, 1)
    n = repeats_for(first["us_per_impact"] * 1e-6)
    return ({f: first[f] for f in case["figures"]}, first["rhs_evaluations"],
            lambda: run(bench, *args, n)["us_per_impact"] * 1e-6)


def scipy_runner(method):
    """solve_ivp on the same ODE (scipy_contact.solve_drop): the figures,
    right-hand sides, and a timer (the median of calls, in this process)."""
    def runner(case, rtol):
        p = case["physics"]

        def once():
            return solve_drop(p["k"], p["c"], p["m"], p["v0"], method=method, rtol=rtol, t_end=p["t_end"])
        r = once()
        r["x2_end"] = r["x2"]
        return {f: r[f] for f in case["figures"]}, r["nfev"], lambda: median_cpu(once, budget=TIMING_BUDGET)
    return runner


def precision_methods(program, bench):
    """(label, what the setting is, its ladder coarse to fine, what the work
    counts, runner(case, setting) -> figures, work, timer)."""
    return [(ADAPTIVE, "tolerance", ADAPTIVE_TOLERANCES, "steps",
             lambda case, s: ours(program, case, ["--tolerance", s, "--dt-max", ADAPTIVE_DT_MAX])),
            (FIXED, "dt_max", FIXED_STEPS, "steps",
             lambda case, s: ours(program, case, ["--dt-max", s])),
            (ANCHOR, "rtol", RTOLS, "right-hand sides", lambda case, s: gsl_anchor(bench, case, s)),
            *[(f"scipy {m}", "rtol", RTOLS, "right-hand sides", scipy_runner(m)) for m in SCIPY_METHODS]]


def ladder(case, settings, runner):
    """Each setting's errors, work and CPU per impact, coarse to fine."""
    rows = []
    for s in settings:
        figures, work, timer = runner(case, s)
        errors = {f: abs(figures[f] / case["want"][f] - 1) for f in case["figures"]}
        rows.append(dict(setting=s, errors=errors, worst=max(errors.values()), work=work, timer=timer, cpu=timer()))
        if rows[-1]["cpu"] > LADDER_SECONDS:
            break
    return rows


def head_to_head(rows):
    """The rows' CPU measured again in ROUNDS rounds, the methods in turn and
    the order rotated each round, so that a burst of other work on this
    shared machine slows them alike: the median of the rounds."""
    times = [[] for _ in rows]
    for k in range(ROUNDS):
        for i in list(range(k % len(rows), len(rows))) + list(range(k % len(rows))):
            times[i].append(rows[i]["timer"]())
    for r, t in zip(rows, times):
        r["cpu_head_to_head"] = float(np.median(t))


def precision_case(case, methods):
    """Every method's ladder on one case, the cheapest setting of each that
    meets TARGET (the coarsest from which on every finer one does: a lucky
    cancellation at a coarser one does not count), those timed head to head."""
    out = {}
    for label, name, settings, work, runner in methods:
        say(f"  {case['name']}: {label} ...")
        rows = ladder(case, settings, runner)
        out[label] = dict(setting=name, work=work, rows=rows,
                          chosen=first_setting_that_stays_within(rows, lambda r: r["worst"]))
    say(f"  {case['name']}: the cheapest settings head to head, {ROUNDS} rounds ...")
    head_to_head([m["chosen"] for m in out.values() if m["chosen"]])
    return out


def fmu_impact_steps(path, v, tolerance, dt_max, repeats):
    """One instance of the FMU (law 2, the h20 drop at v): `repeats` times
    reset and initialized (untimed), then one doStep of FMU_H over the whole
    impact timed, and a second one of free flight after it: the call's own
    cost (fmpy, ctypes, the FMU's glue) with next to nothing to integrate.
    The CPU of each, and the outputs after the impact."""
    md, folder = fmu.unpacked(str(path))
    s = fmu.Slave(md, folder, start=False)
    impact, flight = [], []
    for _ in range(repeats):
        s.fmu.reset()
        s.fmu.setupExperiment(startTime=0.0)
        s.set(law=2, v=v, tolerance=tolerance, dt_max=dt_max)
        s.start()
        t0 = time.process_time()
        s.fmu.doStep(0.0, FMU_H)
        t1 = time.process_time()
        s.fmu.doStep(FMU_H, FMU_H)
        t2 = time.process_time()
        impact.append(t1 - t0)
        flight.append(t2 - t1)
    figures = dict(F_peak=s.get("F_peak"), eps=s.get("eps"), x2_end=s.get("x2"))
    s.free()
    return impact, flight, figures


def fmu_one_step(path, case):
    """The FMU settings in ROUNDS alternating rounds (after a warm-up round),
    medians; their outputs' errors against the h20 reference."""
    v, out = case["physics"]["v0"], {}
    for k in range(ROUNDS + 1):
        for label, tolerance, dt_max, repeats in FMU_SETTINGS:
            impact, flight, figures = fmu_impact_steps(path, v, tolerance, dt_max, repeats)
            if k == 0:
                out[label] = dict(impact=[], flight=[], repeats=repeats * ROUNDS, tolerance=tolerance,
                                  errors={f: abs(x / case["want"][f] - 1) for f, x in figures.items()})
                continue
            out[label]["impact"] += impact
            out[label]["flight"] += flight
    for r in out.values():
        r["cpu"], r["flight_cpu"] = float(np.median(r.pop("impact"))), float(np.median(r.pop("flight")))
    return out


def precision_rows(root, program, bench, fmu_file):
    started = time.perf_counter()
    with LoadWatch() as load:
        cases = precision_cases(program)
        methods = precision_methods(program, bench)
        results = {case["name"]: precision_case(case, methods) for case in cases}
        say("  the FMU, one doStep over the h20 impact ...")
        fmu_cpu = fmu_one_step(fmu_file, cases[0])
    return dict(head=git(root, "rev-parse", "--short", "HEAD"),
                dirty=bool(git(root, "status", "--porcelain", "--", "model", "fmu_src", "solver", "CMakeLists.txt")),
                load=load.samples, cases={c["name"]: c for c in cases}, results=results, fmu=fmu_cpu,
                minutes=(time.perf_counter() - started) / 60)


def plot_precision(path, r):
    """Work against precision: the largest error of each case's figures
    against CPU per impact, a line per method, the cheapest meeting
    setting ringed."""
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.6))
    titles = {"h20": "h20 (v = sqrt(2 g 0.02)): largest error of F_peak, eps, t_contact, x2_end",
              "soft": "soft dashpot (c = 50, v = 3, 10 ms): error of F_peak"}
    for ax, (name, methods) in zip(axes, r["results"].items()):
        for i, (label, m) in enumerate(methods.items()):
            rows = m["rows"]
            ax.loglog([x["cpu"] * 1e6 for x in rows], [max(x["worst"], 1e-16) for x in rows], marker=".",
                      color=f"C{i}", label=label)
            if m["chosen"]:
                ax.loglog([m["chosen"]["cpu"] * 1e6], [max(m["chosen"]["worst"], 1e-16)], "o", mfc="none",
                          ms=11, color=f"C{i}")
        ax.axhline(TARGET, color="gray", lw=0.8)
        ax.set(title=titles[name], xlabel="CPU per impact [us]", ylabel="relative error")
        ax.title.set_fontsize(10)
        ax.grid(alpha=0.3, which="both")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=9)
    fig.suptitle("Work against precision (gray: 1e-6; ringed: the cheapest setting meeting it)")
    output.save(fig, path, rect=(0, 0.08, 1, 1))


def precision(root, program, bench, fmu_file, out):
    """Section 2's lines; its diagram written beside the report."""
    r = precision_rows(root, program, bench, fmu_file)
    plot_precision(out / PRECISION_FIGURE, r)
    return precision_section(r)


def us(seconds):
    return f"{seconds * 1e6:,.1f} us" if seconds < 1e-2 else f"{seconds * 1e3:,.2f} ms"


def times(q):
    return f"{q:.3g}" if q < 100 else f"{q:,.0f}"


def setting_text(m, s):
    return f"dt_max {s:.3g} s" if m["setting"] == "dt_max" else f"{m['setting']} {s:.0e}"


def met(ok):
    return "**met**" if ok else "**not met**"


def cheapest_table(methods):
    """Each method's cheapest meeting setting, its CPU head to head, and its
    CPU over the anchor's and over LSODA's."""
    others = {name: methods[name]["chosen"] for name in (ANCHOR, LSODA)}
    out = ["| method | cheapest setting meeting 1e-6 | work | largest error (of) | CPU per impact | "
           "/ anchor's | / LSODA's |", "|---|---|---|---|---|---|---|"]
    for label, m in methods.items():
        c = m["chosen"]
        if not c:
            best = min(m["rows"], key=lambda x: x["worst"])
            out.append(f"| {label} | none in the ladder (best: {best['worst']:.1e} at "
                       f"{setting_text(m, best['setting'])}) | | | | | |")
            continue
        ratios = [times(c["cpu_head_to_head"] / o["cpu_head_to_head"]) if o else "" for o in others.values()]
        out.append(f"| {label} | {setting_text(m, c['setting'])} | {c['work']:,} {m['work']} | {c['worst']:.1e} "
                   f"({max(c['errors'], key=c['errors'].get)}) | {us(c['cpu_head_to_head'])} | "
                   + " | ".join(ratios) + " |")
    return out


def error_over_tolerance(methods):
    """The adaptive ladder's largest error over its tolerance, smallest and
    largest: the tolerance bounds each step's error, not the figures'."""
    q = [x["worst"] / x["setting"] for x in methods[ADAPTIVE]["rows"]]
    return (f"- ours, adaptive: the largest error over the tolerance, across its ladder, from {min(q):.2g} to "
            f"{max(q):.2g} (the tolerance bounds the error of a step, not of the figures)")


def cpu_ratio(methods, slower, faster):
    """slower's CPU over faster's at their cheapest meeting settings, or None."""
    a, b = methods[slower]["chosen"], methods[faster]["chosen"]
    return a["cpu_head_to_head"] / b["cpu_head_to_head"] if a and b else None


def target_line(text, q, bar, aim=None):
    """A ratio against its target (and the aim beyond it, where there is one)."""
    if q is None:
        return f"- {text}: not measurable (a method never met 1e-6)"
    line = f"- {text}: {q:.2f}x; target >= {bar:g}x: {met(q >= bar)}"
    return line + (f"; aim {aim:g}x: {met(q >= aim)}" if aim else "")


def ladder_table(methods, figures):
    out = ["| method | setting | work | " + " | ".join(f"{f} error" for f in figures)
           + (" | largest |" if len(figures) > 1 else " |") + " CPU per impact |",
           "|---|---|---|" + "---|" * (len(figures) + (len(figures) > 1)) + "---|"]
    for label, m in methods.items():
        for x in m["rows"]:
            errors = [f"{x['errors'][f]:.1e}" for f in figures] + ([f"{x['worst']:.1e}"] if len(figures) > 1 else [])
            out.append(f"| {label} | {setting_text(m, x['setting'])} | {x['work']:,} | " + " | ".join(errors)
                       + f" | {us(x['cpu'])} |")
    return out


def precision_section(r):
    h20, soft = r["results"]["h20"], r["results"]["soft"]
    ref, ref_soft = r["cases"]["h20"]["reference"], r["cases"]["soft"]["reference"]
    fmu_ = r["fmu"]
    load = r["load"]
    out = [PRECISION_BEGIN, "## Work against precision on all four figures", "",
           "Regenerate this section alone, in place: `scripts/report benchmarks --only precision` (this run: "
           f"{r['minutes']:.1f} minutes). Measured side by side in one run on commit {r['head']}"
           + (" (with uncommitted changes to model/, fmu_src/, solver/ or CMakeLists.txt in the working tree)"
              if r["dirty"] else "")
           + f", on {platform.processor() or platform.machine()} ({platform.system()}, {os.cpu_count()} cores "
           f"shared with other work: 1-minute load average {min(load):.2f} to {max(load):.2f}, median "
           f"{float(np.median(load)):.2f}, sampled every 10 s during the run). CPU time of one process; on this "
           "shared virtual machine a timing moves by up to 30 % from one run to the next, the ratios within a run "
           "less.", "",
           "Every method solves the same impact to the last bit: its parameters are read back from the reference "
           f"run (`fraccontact-solve --law 2 --reference --rtol {REFERENCE_RTOL:g}`: GSL rk8pd, events bracketed "
           "to the last bit), and each run is judged on the largest relative error of the figures against it.", "",
           f"- **h20**: `--height 0.02`, so v = sqrt(2 · 9.81 · 0.02) = {ref['params']['v']!r} m/s exactly (the "
           f"default v is rounded); k = {ref['k']:g}, c = {ref['params']['c']:g}, m = {ref['params']['m']:g}. "
           f"All four figures: F_peak = {ref['F_peak']:.12g} N, eps = {ref['eps']:.12g}, t_contact = "
           f"{ref['t_contact']:.12g} s, x2_end = {ref['x2_end']:.12g} m.",
           f"- **soft dashpot**: k = {SOFT['k']:g}, c = {SOFT['c']:g}, m = {SOFT['m']:g}, v = {SOFT['v']:g} m/s, over "
           f"t_end = {SOFT['t_end']:g} s: F_peak = {ref_soft['end']['F_peak']:.12g} N alone. The four figures "
           "cannot be judged there: the striker creeps into the specimen and separates only after "
           f"{r['cases']['soft']['separates_at']:.3g} s (the reference over the whole contact), so within 10 ms no "
           "impact has ended and eps, t_contact and x2_end do not exist.",
           "- **Methods**, all on the Hertz spring (law 2) in series with the dashpot: ours with error-controlled "
           f"steps (`--tolerance T --dt-max {ADAPTIVE_DT_MAX:g}`, Kvaerno's L-stable ESDIRK 5(4)) at T = 1e-3, "
           "3e-4, ... 1e-10; ours with fixed discrete-gradient steps (`--dt-max DT`, docs/model.md §11, "
           f"tolerance 0) at DT = 1e-5 s / 2^i, i = 0..{len(FIXED_STEPS) - 1}; the GSL rk8pd anchor "
           "(`fraccontact-bench anchor K C M V T_END RTOL`: adaptive rk8pd, the peak and the separation located by "
           "secant iterations, as a competent user scripts an impact) and scipy's `solve_ivp` LSODA, DOP853 and "
           "Radau on the same ODE (`fraccontact.scipy_contact.solve_drop`, the peak and the separation as events), "
           "at rtol = 1e-3, 3e-4, ... 1e-12. A ladder stops after a setting costing over "
           f"{LADDER_SECONDS:g} s per impact.",
           "- **CPU per impact**: ours, the median of `fraccontact-solve --repeat N` (timed inside, around the "
           "solve); the anchor, the median of its N impacts (timed in C around each); scipy, the median of N "
           f"`solve_drop` calls (`time.process_time`, Python included: it is scipy's cost). N: about "
           f"{TIMING_BUDGET:g} s of repeats, at least 5.",
           "- **Cheapest setting meeting 1e-6**: the coarsest setting from which on every finer one in its ladder "
           "meets 1e-6 (a coarser one meeting it by a lucky cancellation does not count). Those settings were then "
           f"timed again head to head: {ROUNDS} rounds, the methods in turn, the order rotated each round, the "
           "median of the rounds (the tables' CPU and ratios; the diagram and the ladders show the first pass).",
           "", f"![work against precision]({PRECISION_FIGURE})", "",
           "### h20: all four figures within 1e-6", ""]
    out += cheapest_table(h20)
    out += ["", target_line("the anchor's CPU over ours, adaptive", cpu_ratio(h20, ANCHOR, ADAPTIVE), 1.0,
                            aim=3.0),
            target_line("LSODA's CPU over ours, adaptive", cpu_ratio(h20, LSODA, ADAPTIVE), 100.0),
            error_over_tolerance(h20),
            "", "### The soft dashpot: F_peak within 1e-6 over 10 ms", ""]
    out += cheapest_table(soft)
    out += ["", target_line("the anchor's CPU over ours, adaptive", cpu_ratio(soft, ANCHOR, ADAPTIVE), 3.0),
            target_line("our fixed steps' CPU over ours, adaptive", cpu_ratio(soft, FIXED, ADAPTIVE), 1.0),
            error_over_tolerance(soft),
            "", "### The FMU's own CPU for one impact, in one doStep", "",
           f"The FMI 2.0 FMU (`fraccontact.fmu`) through fmpy's `FMU2Slave` in this process: law 2, the drop scene, "
           f"v = sqrt(2 · 9.81 · 0.02) as above. One instance; before each timed call it is reset, set and "
           f"initialized (untimed); then one `doStep` of H = {FMU_H * 1e3:g} ms, covering the whole "
           f"{ref['t_contact'] * 1e3:.2f} ms contact, is timed (`time.process_time`), so that no per-call overhead "
           "of the importer hides the cost; then a second `doStep` of free flight after the impact, timed too: "
           "the cost of a call with next to nothing to integrate (fmpy, ctypes, the FMU's glue). The settings "
           f"alternated in {ROUNDS} rounds after a warm-up round; medians. Errors: the outputs after the impact "
           "(`F_peak`, `eps`, `x2`) against the h20 reference.", "",
           "| setting | one doStep over the impact: CPU | repeats | a doStep of free flight | F_peak error | "
           "eps error | x2_end error |", "|---|---|---|---|---|---|---|"]
    for label, x in fmu_.items():
        e = x["errors"]
        out.append(f"| {label} | {us(x['cpu'])} | {x['repeats']} | {us(x['flight_cpu'])} | {e['F_peak']:.1e} | "
                   f"{e['eps']:.1e} | {e['x2_end']:.1e} |")
    out.append("")
    for label, x in fmu_.items():
        if label != FMU_FIXED:
            out.append(target_line(f"the fixed defaults' CPU over the adaptive one's at tolerance {x['tolerance']:g} "
                                   "(the target is set at 1e-6)", fmu_[FMU_FIXED]["cpu"] / x["cpu"], 10.0))
    out += ["- F_peak within 1e-6 of the reference after that one doStep: " + "; ".join(
                f"tolerance {x['tolerance']:g}: {'yes' if x['errors']['F_peak'] <= TARGET else '**no**'} "
                f"({x['errors']['F_peak']:.1e})" for x in fmu_.values())
            + ". (The FMU's accuracy target is at a 1e-5 s communication step, tested in "
            "tests/test_tolerance.py; in one doStep over the impact the steps are the ones the tolerance alone "
            "chooses, as in the solver's runs above.)",
            "", "### Every setting: h20", ""]
    out += ladder_table(h20, FIGURES)
    out += ["", "### Every setting: the soft dashpot", ""]
    out += ladder_table(soft, ("F_peak",))
    out.append(PRECISION_END)
    return out


# --- 3. the G1 history sum against differint -------------------------------------

def line_g1(alpha, n, delta):
    """The G1 value of D^alpha x at grid points n (docs/model.md §4), computed here
    independently of the C code: Gamma ratios directly below n = 30, and above
    Stirling's series with the O(1) terms cancelled analytically."""
    n = np.asarray(n, dtype=float)
    a = 1.0 - alpha
    small = n < 30
    ratio = np.empty_like(n)
    ns = n[small]
    ratio[small] = gamma(ns + a) / (gamma(ns) * ns ** a)
    nl = n[~small]

    def tail(z):
        r = 1 / z
        return r * (1 / 12 - r * r * (1 / 360 - r * r * (1 / 1260 - r * r / 1680)))
    ratio[~small] = np.exp((nl + a - 0.5) * np.log1p(a / nl) - a + tail(nl + a) - tail(nl))
    return ratio * (n * delta) ** a / gamma(2 - alpha)


def g1_rows(bench, alpha):
    rows = []
    for N in (1000, 10000, 100000, 1000000):
        say(f"  G1, N = {N} ...")
        ours = run(bench, "g1", N, alpha)
        delta = 1.0 / N
        f = np.arange(N + 1) * delta
        exact = np.concatenate([[0.0], line_g1(alpha, np.arange(1, N + 1), delta)])
        full = differint.GL(alpha, f, 0.0, 1.0, N + 1)
        m = min(len(full), N + 1)  # it may return fewer values than points
        err_full = np.max(np.abs(full[1:m] - exact[1:m]) / exact[1:m])
        wrong_points = int(np.sum(np.abs(full[1:m] - exact[1:m]) > 1e-9 * exact[1:m])) + (N + 1 - m)
        t_full = median_cpu(lambda: differint.GL(alpha, f, 0.0, 1.0, N + 1), budget=0.5, at_least=3)
        point = differint.GLpoint(alpha, f, 0.0, 1.0, N + 1)
        t_point = median_cpu(lambda: differint.GLpoint(alpha, f, 0.0, 1.0, N + 1), budget=0.5, at_least=3)
        rows.append(dict(N=N, ours=ours, differint_full=t_full, differint_point=t_point, differint_length=len(full),
                         differint_full_error=float(err_full), differint_wrong_points=wrong_points,
                         differint_point_error=abs(point / exact[-1] - 1)))
    return rows


# --- 4. the Python package against the C core ----------------------------------

def spread_dashpots(n):
    """The dashpots of fraccontact-bench batch: 4000..8000 N s/m."""
    return 4000.0 + 4000.0 * np.arange(n) / n


def overhead(bench, law, dt, n):
    """CPU per impact of fraccontact.impacts over n impacts and of the C
    core's fc_run_batch on the same (fraccontact-bench batch), alternated
    REPEATS times; the wall time of the Python call too."""
    c = spread_dashpots(n)
    model.impacts(law=law, dt_max=dt, c=c[:10])  # warm
    ours, wall, core = [], [], []
    for _ in range(REPEATS):
        core.append(run(bench, "batch", n, law, dt)["seconds_per_impact"])
        for _ in range(3):
            t0, w0 = time.process_time(), time.perf_counter()
            model.impacts(law=law, dt_max=dt, c=c)
            ours.append((time.process_time() - t0) / n)
            wall.append((time.perf_counter() - w0) / n)
    return dict(python=float(np.median(ours)), python_wall=float(np.median(wall)), core=float(np.median(core)))


def process_per_impact(program, law, dt, n):
    """Wall seconds per impact of one fraccontact-solve --json process each."""
    c = spread_dashpots(n)
    runs = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        for x in c:
            solve(program, "--law", law, "--dt-max", dt, "--c", x)
        runs.append((time.perf_counter() - start) / n)
    return float(np.median(runs))


def sweep_rate(workers, law, dt, n, folder):
    """Impacts per second of fraccontact sweep (its own count: the Dask tasks'
    wall time), Monte Carlo with k and c scattered, on a local cluster."""
    out = os.path.join(folder, f"sweep_{law}_{workers}")
    command = [sys.executable, "-m", "fraccontact", "sweep", "--monte-carlo", str(n), "--scatter", "k=0.05",
               "--scatter", "c=0.1", "--set", f"law={law}", "--set", f"dt_max={dt}", "--workers", str(workers),
               "--out", out]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed: {done.stderr.strip()[-2000:]}")
    with open(os.path.join(out, "sweep.json")) as f:
        return json.load(f)["impacts_per_second"]


def curve_fit(folder):
    """Wall seconds of a fit of a FIT_ROWS-row curve (the model's at k = 3e8,
    c = 5000, Hertz, 5 N of noise, as tests/test_fit.py makes it): fit.fit_curve
    in-process, and fraccontact fit --curve as a new process (start included)."""
    k, c = 3e8, 5000.0
    t_c = model.impact(k=k, c=c, law="hertz").t_contact
    interval = t_c / (FIT_ROWS - 1)
    s = model.simulate(output_interval=interval, k=k, c=c, law="hertz")
    while len(s["t"]) < FIT_ROWS:  # the onset and separation rows: a step a little finer
        interval *= 0.999
        s = model.simulate(output_interval=interval, k=k, c=c, law="hertz")
    t, F = s["t"][:FIT_ROWS], s["F"][:FIT_ROWS] + np.random.default_rng(7).normal(0.0, 5.0, FIT_ROWS)
    path = os.path.join(folder, "curve.csv")
    with open(path, "w") as f:
        f.write("t_s,F_N\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, F)))
    m, v = model.defaults()["m"], model.defaults()["v"]
    inproc, cli = [], []
    for _ in range(REPEATS):
        start = time.perf_counter()
        r = fit.fit_curve(t, F, m, v)
        inproc.append(time.perf_counter() - start)
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "fraccontact", "fit", "--curve", path, "--height", "0.020",
                               "--m", str(m)], capture_output=True, text=True)
        cli.append(time.perf_counter() - start)
        if done.returncode != 0:
            raise SystemExit(f"fraccontact fit failed: {done.stderr.strip()}")
    return dict(rows=len(t), inproc=float(np.median(inproc)), cli=float(np.median(cli)), k=r["k"], c=r["c"])


def package_rows(program, bench):
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for label, law, dt, n, n_sweep in SETTINGS:
            say(f"  fraccontact.impacts against the C core, {label} ...")
            r = dict(label=label, law=law, dt=dt, n=n, n_sweep=n_sweep, **overhead(bench, law, dt, n))
            if law == 2:
                say(f"  a process per impact, {PROCESSES} impacts ...")
                r["process"] = process_per_impact(program, law, dt, PROCESSES)
            for workers in (1, 2):
                say(f"  fraccontact sweep, {n_sweep} impacts, {workers} worker(s) ...")
                r[f"sweep{workers}"] = float(np.median([sweep_rate(workers, law, dt, n_sweep, folder)
                                                        for _ in range(REPEATS)]))
            rows.append(r)
        say("  a curve fit ...")
        fitted = curve_fit(folder)
    return rows, fitted


def package_section(rows, fitted):
    def met(ok):
        return "yes" if ok else "**no**"
    out = [BEGIN, "## The Python package against the C core", "",
           "Regenerate this section alone, in place: `scripts/report benchmarks --only package` (about 1.5 minutes). "
           "h20 impacts measured side by side in one run, at the cheap setting (law 2, `dt_max` 3e-6 s: F_peak "
           "within 1e-6 of the GSL reference at the h20 defaults) and at the library's default (law 1, `dt_max` "
           "1e-7 s).", "",
           "- **Overhead**: CPU per impact (`time.process_time`) of one `fraccontact.impacts(law=..., dt_max=..., "
           "c=array)` call over N impacts, dashpots spread over 4000..8000 N·s/m, against the C core's own CPU for "
           "the same N impacts in one `fc_run_batch` call (`fraccontact-bench batch N LAW DT_MAX`, its median of "
           f"5); {REPEATS} rounds alternating the two, 3 Python calls a round, medians.",
           f"- **A process per impact**: {PROCESSES} impacts, each one `fraccontact-solve --json --quiet` process "
           "started from Python and its JSON parsed (how the scripts reached the model before the package), wall "
           f"time, median of {REPEATS}; against the wall time per impact of the `fraccontact.impacts` call above.",
           "- **Sweeps**: `python -m fraccontact sweep --monte-carlo N --scatter k=0.05 --scatter c=0.1 --set "
           "law=LAW --set dt_max=DT --workers W` on a local Dask cluster; impacts per second as the sweep counts "
           f"them (wall time of its Dask tasks), median of {REPEATS} sweeps; against the C core's throughput "
           "(1 / its CPU per impact above). The machine has 2 cores: two workers "
           "share them with the scheduler and this report's process, which wait on them. The sweep at scale, end "
           "to end: [sweep_scaling.md](sweep_scaling.md).",
           f"- **Curve fit**: a {fitted['rows']}-row force curve (the model's at k = 3e8, c = 5000, Hertz, plus "
           "5 N of Gaussian noise, as tests/test_fit.py makes it), wall time of `fraccontact.fit.fit_curve` "
           "in-process and of `python -m fraccontact fit --curve FILE` (a new process, Python's start and "
           f"the reading of the file included), median of {REPEATS}.", "",
           "| setting | what | measured | against | ratio | target | met |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        ratio = r["python"] / r["core"]
        out.append(f"| {r['label']} | `fraccontact.impacts`, {r['n']:,} impacts: CPU per impact | "
                   f"{r['python'] * 1e6:.1f} us | C core: {r['core'] * 1e6:.1f} us | {ratio:.3f} | <= 1.1 | "
                   f"{met(ratio <= 1.1)} |")
        if "process" in r:
            gain = r["process"] / r["python_wall"]
            out.append(f"| {r['label']} | one `fraccontact.impacts` call: impacts/s (wall) | "
                       f"{1 / r['python_wall']:,.0f} | a process per impact: {1 / r['process']:,.0f} | "
                       f"{gain:.0f}x | >= 20x | {met(gain >= 20)} |")
        core_rate = 1 / r["core"]
        f1, f2 = r["sweep1"] / core_rate, r["sweep2"] / r["sweep1"]
        out.append(f"| {r['label']} | `fraccontact sweep`, {r['n_sweep']:,} impacts, 1 worker: impacts/s | "
                   f"{r['sweep1']:,.0f} | C core: {core_rate:,.0f} | {100 * f1:.0f} % | >= 85 % | {met(f1 >= 0.85)} |")
        out.append(f"| {r['label']} | `fraccontact sweep`, {r['n_sweep']:,} impacts, 2 workers: impacts/s | "
                   f"{r['sweep2']:,.0f} | 1 worker: {r['sweep1']:,.0f} | {f2:.2f}x | >= 1.7x | {met(f2 >= 1.7)} |")
    out.append(f"| Hertz (the fit's default law) | curve fit, {fitted['rows']:,} rows: wall seconds | "
               f"{fitted['inproc']:.2f} s in-process | {fitted['cli']:.2f} s as `fraccontact fit` | | < 2 s | "
               f"{met(fitted['cli'] < 2)} |")
    out += ["", f"The fit gave k = {fitted['k']:.4g} N/m^1.5 and c = {fitted['c']:.5g} N·s/m (made with 3e8 and "
            "5000).", END]
    return out


def kept_section(path, begin, end, otherwise):
    """The lines between begin and end (both included) of the report at
    path, which another report writes, or otherwise where it has none."""
    text = path.read_text() if path.exists() else ""
    if begin in text and end in text:
        return (begin + text.split(begin, 1)[1].split(end, 1)[0] + end).split("\n")
    return otherwise


def replace_section(path, section, begin=BEGIN, end=END):
    """The report at path with the section between begin and end replaced
    (appended when it has none), and its regeneration line brought up to
    date."""
    text = path.read_text() if path.exists() else "# Benchmarks\n"
    block = "\n".join(section) + "\n"
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        text = head + block.rstrip("\n") + rest.split(end, 1)[1]
    else:
        text = text.rstrip("\n") + "\n\n" + block
    lines = text.split("\n")
    for i, line in enumerate(lines):
        if line.startswith("Regenerate: `scripts/report benchmarks`"):
            lines[i] = REGENERATE + line[line.index(")") + 1:] if ")" in line else REGENERATE
            break
    atomic.write_text(path, "\n".join(lines))


# --- 5. the springpot --------------------------------------------------------

class LoadWatch:
    """The 1-minute load average while a block runs, sampled every 10 s."""

    def __init__(self):
        self.samples = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)

    def _sample(self):
        while not self._stop.wait(10.0):
            self.samples.append(os.getloadavg()[0])

    def __enter__(self):
        self.samples.append(os.getloadavg()[0])
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.samples.append(os.getloadavg()[0])


def git(root, *args):
    done = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"git {' '.join(args)} failed: {done.stderr.strip()}")
    return done.stdout.strip()


@contextlib.contextmanager
def base_build(root, commit, targets=("fraccontact-bench", "fraccontact_fmu")):
    """The targets (by default fraccontact-bench and the FMU) of `commit`,
    built (Release) in a temporary git worktree, which is removed afterwards."""
    folder = pathlib.Path(tempfile.mkdtemp(prefix="fraccontact-base-"))
    tree, build = folder / "tree", folder / "build"
    git(root, "worktree", "add", "--detach", str(tree), commit)
    try:
        for command in (["cmake", "-S", tree, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                         f"-DPython3_EXECUTABLE={sys.executable}"],
                        ["cmake", "--build", build, "-j2", "--target", *targets]):
            done = subprocess.run([str(c) for c in command], capture_output=True, text=True)
            if done.returncode != 0:
                raise SystemExit(f"{' '.join(map(str, command))} failed:\n{done.stdout[-3000:]}{done.stderr[-3000:]}")
        yield dict(tree=tree, bench=build / "fraccontact-bench", fmu=build / "fraccontact.fmu",
                   solve=build / "fraccontact-solve", commit=git(root, "rev-parse", "--short", commit))
    finally:
        subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(tree)], capture_output=True)
        subprocess.run(["git", "-C", str(root), "worktree", "prune"], capture_output=True)
        shutil.rmtree(folder, ignore_errors=True)


def model_sizes(tree):
    """sizeof(contact_model) and sizeof(contact_state) of the model's header
    in tree (what an FMU instance or a library run holds in memory), or None
    without a C compiler."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if not cc:
        return None
    with tempfile.TemporaryDirectory() as folder:
        exe = os.path.join(folder, "sizes")
        source = ('#include <stdio.h>\n#include "contact.h"\nint main(void) { printf("%zu %zu\\n", '
                  'sizeof(contact_model), sizeof(contact_state)); return 0; }\n')
        # The model's folder: at the top level, or under fmu_src in commits before it moved.
        include = next(d for d in (pathlib.Path(tree) / "model", pathlib.Path(tree) / "fmu_src" / "model")
                       if (d / "contact.h").exists())
        done = subprocess.run([cc, "-I", str(include), "-x", "c", "-", "-o", exe],
                              input=source, capture_output=True, text=True)
        if done.returncode != 0:
            return None
        model_bytes, state_bytes = map(int, subprocess.run([exe], capture_output=True, text=True).stdout.split())
    return dict(model=model_bytes, state=state_bytes)


def dashpot_side_by_side(base_bench, bench):
    """The dashpot on both builds, BASE_ROUNDS rounds alternating them (the
    order swapped every round): fraccontact-bench step's ns per internal
    step (law 1 and law 2), and fc_run_batch's CPU per impact at the package
    section's two settings, with the first impact's F_peak of each."""
    keys = ("g1", "hertz", "batch_cheap", "batch_default")
    got = {side: {k: [] for k in keys} | {"F_peak": set()} for side in ("base", "this")}
    for r in range(BASE_ROUNDS):
        say(f"  the dashpot, round {r + 1} of {BASE_ROUNDS} ...")
        order = (("base", base_bench), ("this", bench))
        for side, program in (order if r % 2 == 0 else order[::-1]):
            steps = run(program, "step")["ns_per_step"]
            got[side]["g1"].append(steps["g1"])
            got[side]["hertz"].append(steps["hertz"])
            for key, (n, law, dt) in (("batch_cheap", (2000, 2, 3e-6)), ("batch_default", (300, 1, 1e-7))):
                b = run(program, "batch", n, law, dt)
                got[side][key].append(b["seconds_per_impact"])
                got[side]["F_peak"].add((key, b["F_peak_first"]))
    return got


def state_bytes(s):
    """The size of a serialized FMU state of the slave now."""
    state = s.fmu.getFMUstate()
    size = len(s.fmu.serializeFMUstate(state))
    s.fmu.freeFMUstate(state)
    return size


def fmu_state_sizes(path, **values):
    """The serialized state's bytes of the h20 drop through the FMU in 10 us
    communication steps: at the start, after 1e4 internal steps (t = 1 ms, in
    contact from t = 0 at dt_max 1e-7) and at 1.5 ms, after the impact."""
    md, folder = fmu.unpacked(str(path))
    s = fmu.Slave(md, folder, **values)
    sizes = {"start": state_bytes(s)}
    for i in range(1, 151):
        s.step(1e-5)
        if i == 100:
            sizes["1e4"] = state_bytes(s)
    sizes["after"] = state_bytes(s)
    sizes["eps"], sizes["F_peak"] = s.get("eps"), s.get("F_peak")
    s.free()
    return sizes


def resting_state_sizes(path):
    """The compressed memory's state over a long run: the striker resting on
    the specimen under gravity (v = 0, g = 9.81), in contact throughout, 1 s
    in 1 ms communication steps; the library counts the internal steps."""
    md, folder = fmu.unpacked(str(path))
    s = fmu.Slave(md, folder, damper=2, memory=2, v=0.0, g=9.81)
    start = state_bytes(s)
    for _ in range(1000):
        s.step(1e-3)
    end, contact = state_bytes(s), s.get("contact")
    s.free()
    run_ = model.impacts(damper=2, memory=2, v=0.0, g=9.81, t_end=1.0)
    return dict(start=start, end=end, contact=contact, steps=int(run_["steps"]), stopped=str(run_["stopped"]))


def springpot_rows(root, bench, fmu_file, largest):
    started = time.perf_counter()
    head = git(root, "rev-parse", "--short", "HEAD")
    dirty = bool(git(root, "status", "--porcelain", "--", "model", "fmu_src", "solver", "CMakeLists.txt"))
    with LoadWatch() as load:
        say(f"  building {BASE} in a temporary git worktree ...")
        with base_build(root, BASE) as base:
            base_sizes = model_sizes(base["tree"])
            side = dashpot_side_by_side(base["bench"], bench)
            say("  FMU states ...")
            states = {"base dashpot": fmu_state_sizes(base["fmu"])}
        states["dashpot"] = fmu_state_sizes(fmu_file)
        states["compressed"] = fmu_state_sizes(fmu_file, damper=2, memory=2)
        states["full"] = fmu_state_sizes(fmu_file, damper=2, memory=1)
        resting = resting_state_sizes(fmu_file)
        say(f"  fraccontact-bench springpot {largest:g} (the full history's largest N is O(N^2): minutes) ...")
        sp = run(bench, "springpot", f"{largest:g}")
    return dict(head=head, dirty=dirty, base=base["commit"], load=load.samples, side=side, states=states,
                resting=resting, sizes=dict(base=base_sizes, this=model_sizes(root)), sp=sp,
                minutes=(time.perf_counter() - started) / 60)


def springpot_section(r):
    sp, h20, st, side = r["sp"], r["sp"]["h20"], r["states"], r["side"]
    dash, comp, full = h20["dashpot"], h20["compressed"], h20["full"]
    bar = comp["ns_per_step"] / dash["ns_per_step"]
    load = r["load"]

    def med(side_, key):
        return float(np.median(side[side_][key]))

    def spread(side_, key):
        """The rounds' interquartile range over their median: robust to the
        odd round another process slowed."""
        q1, q2, q3 = np.percentile(side[side_][key], [25, 50, 75])
        return float((q3 - q1) / q2)

    def rel(a, b):
        return abs(a / b - 1.0)

    out = [SPRINGPOT_BEGIN, "## The springpot: compressed memory against the full G1 history", "",
           "Regenerate this section alone, in place: `scripts/report benchmarks --only springpot` (this run: "
           f"{r['minutes']:.1f} minutes, most of it the full history's N = {sp['ladder'][-1]['N']:,.0f} run). "
           f"Measured side by side in one run on commit {r['head']}"
           + (" (with uncommitted changes to model/, fmu_src/, solver/ or CMakeLists.txt in the working tree)"
              if r["dirty"] else "")
           + f", on {platform.processor() or platform.machine()} ({platform.system()}, {os.cpu_count()} cores "
           f"shared with other work: 1-minute load average {min(load):.2f} to {max(load):.2f}, median "
           f"{float(np.median(load)):.2f}, sampled every 10 s during the run), CPU time of one process. The springpot: alpha = 0.5, c_alpha = 3e5 N·s^alpha/m "
           "(the defaults: as damping as the h20 dashpot at the impact's frequency), `memory_tolerance` 1e-6; the "
           "h20 drop (v = 0.626 m/s, m = 0.7437 kg, k = 3.299e8 N/m^1.5, G1 spring law), advanced 100 internal "
           "steps per `contact_advance` call as an FMU with a 10 us communication step takes them "
           "(`fraccontact-bench springpot`).", "",
           "### Cost of an internal step", "",
           f"The h20 impact at `dt_max` = {h20['dt_max']:g} s, until it ends; medians of the repeats, the dashpot's "
           "and the compressed memory's runs alternated (a run takes a few ms: a burst of other work slows both "
           "alike). The full "
           "history's step sums over every step since t = 0, so its cost grows with the run: its figure is the mean "
           "over this impact. Memory values: what the FMU state carries beside the fixed fields "
           "(`contact_memory_count`, 8 bytes each).", "",
           "| damper | internal steps | ns per internal step | / dashpot | repeats | memory values | "
           "FMU state at 1e4 steps | after the impact |", "|---|---|---|---|---|---|---|---|"]
    for label, x, s in (("dashpot (`damper` 1)", dash, st["dashpot"]),
                        (f"springpot, compressed memory (`memory` 2, M = {comp['modes']} modes)", comp,
                         st["compressed"]),
                        ("springpot, full G1 history (`memory` 1)", full, st["full"])):
        out.append(f"| {label} | {x['steps']:,} | {x['ns_per_step']:,.1f} | "
                   f"{x['ns_per_step'] / dash['ns_per_step']:,.2f}x | {x['repeats']} | {x['memory_values']:,} | "
                   f"{s['1e4']:,} B | {s['after']:,} B |")
    paragraph = (f"The bar, a compressed step at most 5x the dashpot's: "
                 f"{'**met**' if bar <= 5 else '**not met**'} ({bar:.2f}x). "
                 f"The compressed memory's FMU state keeps its size: {st['compressed']['start']:,} B at t = 0, "
                 f"{st['compressed']['1e4']:,} B after 1e4 steps, {r['resting']['end']:,} B after "
                 f"{r['resting']['steps']:,} internal steps (a striker resting on the specimen under gravity for 1 s, "
                 f"in contact at the end: {'yes' if r['resting']['contact'] else 'no'}). The full history's grows "
                 "by 8 bytes a step (x2 at every step since t = 0) and is refused past 1,048,576 steps (about "
                 f"8 MiB); in memory it also holds the G1 weights, {full['history_bytes']:,} B of heap after this "
                 "impact.")
    if r["sizes"]["this"]:
        paragraph += (" Each model (an FMU instance, a library run) is a `contact_model` of "
                      f"{r['sizes']['this']['model']:,} B")
        if r["sizes"]["base"]:
            paragraph += f" ({r['sizes']['base']['model']:,} B before the springpot)"
        paragraph += (": the compressed memory's modes take a block of their own, sized by the kernel's mode "
                      "count (docs/reliability.md).")
    out += ["", paragraph, ""]
    out += ["### The N ladder: compressed memory against the full history", "",
            f"A springpot impact over a fixed span of {sp['span'] * 1e3:g} ms (the impact lasts 1.42 ms, then the "
            "dent recovers), `dt_max` = span / N, both memories in the same run. The full history takes exactly "
            "N steps; the compressed memory takes N steps' worth in contact and a few growing ones once the "
            "striker has left. CPU of the whole span, median of the repeats shown (as many as fit in about 2 s, "
            "at least 3; a run over a minute is timed once).", "",
            "| N | dt_max [s] | compressed: M, steps | compressed: CPU (ns per step) | repeats | "
            "full history: CPU (ns per step) | repeats | speed-up | speed-up over the previous N |",
            "|---|---|---|---|---|---|---|---|---|"]
    previous = None
    for row in sp["ladder"]:
        c, f = row["compressed"], row["full"]
        speedup = f["seconds"] / c["seconds"]
        growth = f"{speedup / previous:.1f}x" if previous else ""
        previous = speedup
        out.append(f"| {row['N']:,.0f} | {row['dt_max']:.3g} | {c['modes']}, {c['steps']:,} | "
                   f"{seconds(c['seconds'])} ({c['ns_per_step']:,.0f}) | {c['repeats']} | "
                   f"{seconds(f['seconds'])} ({f['ns_per_step']:,.0f}) | {f['repeats']}"
                   f"{' (once)' if f['repeats'] == 1 else ''} | {speedup:,.0f}x | {growth} |")
    finest = sp["ladder"][-1]["full"]
    ladder = sp["ladder"]
    ups = [row["full"]["seconds"] / row["compressed"]["seconds"] for row in ladder]
    per_decade = (ups[-1] / ups[0]) ** (1.0 / math.log10(ladder[-1]["N"] / ladder[0]["N"])) if len(ups) > 1 else 0
    ns_c = [row["compressed"]["ns_per_step"] for row in ladder]
    modes = [row["compressed"]["modes"] for row in ladder]
    out += ["", f"The compressed memory's cost per step stays between {min(ns_c):.0f} and {max(ns_c):.0f} ns (M "
            f"from {min(modes)} to {max(modes)} modes: its kernel spans `dt_max` to 1e3 s, so M grows slowly as "
            "`dt_max` falls); the full history's grows like N, its work like N^2. The speed-up grows by "
            f"{per_decade:.1f}x per decade of N on average (10x would be exactly like N).", "",
            "At the same accuracy: the first impact's F_peak and eps by both memories at each N, their relative "
            f"difference, and each against the full history at the largest N ({finest['steps']:,} steps) as the "
            "reference.", "",
            "| N | F_peak compressed [N] | F_peak full [N] | difference | eps compressed | eps full | difference | "
            "F_peak against the reference: compressed, full | eps against the reference: compressed, full |",
            "|---|---|---|---|---|---|---|---|---|"]
    for row in sp["ladder"]:
        c, f = row["compressed"], row["full"]
        out.append(f"| {row['N']:,.0f} | {c['F_peak']:.9g} | {f['F_peak']:.9g} | {rel(c['F_peak'], f['F_peak']):.1e} | "
                   f"{c['eps']:.9f} | {f['eps']:.9f} | {rel(c['eps'], f['eps']):.1e} | "
                   f"{rel(c['F_peak'], finest['F_peak']):.1e}, {rel(f['F_peak'], finest['F_peak']):.1e} | "
                   f"{rel(c['eps'], finest['eps']):.1e}, {rel(f['eps'], finest['eps']):.1e} |")
    out += ["", "Both memories converge to the same impact; at a given N their difference is that of two second-order "
            "time schemes (SDIRK2 on the modes, BDF2 with the G1 sum shifted to the step's end) plus the kernel's "
            "tolerance, not the memory's compression alone.", "",
            f"### The dashpot pays nothing? This build against {r['base']}, the commit before the springpot", "",
            f"{r['base']} built in a temporary git worktree (Release, removed afterwards), its `fraccontact-bench` "
            f"and this build's alternated for {BASE_ROUNDS} rounds, the order swapped every round; medians, and the "
            "spread of the rounds (their interquartile range over the median). `step`: ns per internal step over the "
            "h20 impact, 100 steps per call; `batch`: the library's CPU per impact of one `fc_run_batch` call "
            "(median of 5 inside). FMU state: serialized through fmpy after the h20 impact by each build's FMU.",
            "", f"| measure | {r['base']} | this commit | this / {r['base']} |", "|---|---|---|---|"]
    rows = (("ns per internal step, law 1 (G1), `fraccontact-bench step`", "g1", 1.0, "{:.1f}"),
            ("ns per internal step, law 2 (Hertz), `fraccontact-bench step`", "hertz", 1.0, "{:.1f}"),
            ("us per impact, 2,000 impacts, law 2, dt_max 3e-6, `fraccontact-bench batch`", "batch_cheap", 1e6,
             "{:.2f}"),
            ("us per impact, 300 impacts, law 1, dt_max 1e-7, `fraccontact-bench batch`", "batch_default", 1e6,
             "{:.1f}"))
    ratios, noise = [], []
    for label, key, scale, fmt in rows:
        b, t = med("base", key), med("this", key)
        ratios.append(t / b)
        noise.append(max(spread("base", key), spread("this", key)))
        out.append(f"| {label} | {fmt.format(b * scale)} (spread {100 * spread('base', key):.0f} %) | "
                   f"{fmt.format(t * scale)} (spread {100 * spread('this', key):.0f} %) | {t / b:.3f} |")
    sb, sa = st["base dashpot"]["after"], st["dashpot"]["after"]
    out.append(f"| FMU state after the h20 impact | {sb:,} B | {sa:,} B | {sa / sb:.3f} |")
    if r["sizes"]["this"] and r["sizes"]["base"]:
        out.append(f"| `sizeof(contact_model)`: an instance's model in memory | {r['sizes']['base']['model']:,} B | "
                   f"{r['sizes']['this']['model']:,} B | {r['sizes']['this']['model'] / r['sizes']['base']['model']:.1f} |")
    same = side["base"]["F_peak"] == side["this"]["F_peak"]
    slower = [row[0] for row, q, n in zip(rows, ratios, noise) if q - 1.0 > max(2 * n, 0.03)]
    faster = [row[0] for row, q, n in zip(rows, ratios, noise) if 1.0 - q > max(2 * n, 0.03)]
    verdict = (f"slower beyond the noise of this machine in {len(slower)} of {len(rows)} measures (**"
               + "; ".join(slower) + "**)" if slower else "nowhere slower beyond the noise of this machine")
    if faster:
        verdict += f", faster in {len(faster)} ({'; '.join(faster)})"
    out += ["", f"Per step and per impact the dashpot is {verdict}: ratios {min(ratios):.3f} to {max(ratios):.3f}, "
            "a ratio counting as beyond the noise when it is off 1 by more than twice the larger spread of its row "
            f"and by over 3 %. Its results are {'bit-identical' if same else '**not identical**'} "
            f"(the first impact's F_peak of both batch settings). Its FMU state "
            + ("is the same size." if sa == sb else
               f"is {sa - sb:+d} bytes ({sb} to {sa}: the new parameters `spring_exponent` and `damper` are saved in "
               "every state; a dashpot's carries no memory values)."),
            SPRINGPOT_END]
    return out


def seconds(x):
    return f"{x * 1e3:.3g} ms" if x < 1 else f"{x:,.1f} s"


# --- the report ---------------------------------------------------------------

# --- 6. the springpot under error control --------------------------------------

def controlled_rows(bench):
    """fraccontact-bench controlled at each tolerance (the dashpot and the
    springpot side by side), each damper's figures at the reference
    tolerance from the library, the dashpot along a ladder of tolerances
    (for the springpot's accuracy at the dashpot's cost), and the
    springpot's steps against its order at the tightest tolerance."""
    rows = [run(bench, "controlled", f"{tol:g}") for tol in CONTROLLED_TOLERANCES]
    ladder = [run(bench, "controlled", f"{tol:g}") for tol in CONTROLLED_LADDER]
    reference = {name: model.impacts(law=2, damper=damper, tolerance=CONTROLLED_REFERENCE)
                 for name, damper in (("dashpot", 1), ("springpot", 2))}
    default = model.impacts(law=2, damper=2, tolerance=CONTROLLED_TOLERANCES[-1])
    orders, given = np.array(CONTROLLED_ORDERS), model.defaults()
    c, order = given["c"], given["damper_order"]
    c_alpha = c * (given["c_alpha"] / c) ** ((1.0 - orders) / (1.0 - order))
    steps = model.impacts(law=2, damper=2, damper_order=orders, c_alpha=c_alpha,
                          tolerance=CONTROLLED_TOLERANCES[-1]).steps
    kernels = np.array(CONTROLLED_MEMORY_TOLERANCES)
    by_kernel = model.impacts(law=2, damper=2, memory_tolerance=kernels, tolerance=CONTROLLED_TOLERANCES[-1]).steps
    modes = [len(model.memory_kernel(law=2, damper=2, memory_tolerance=tol, tolerance=CONTROLLED_TOLERANCES[-1])[0])
             for tol in CONTROLLED_MEMORY_TOLERANCES]
    return (rows, ladder, reference, list(zip(CONTROLLED_ORDERS, (int(n) for n in steps))),
            list(zip(CONTROLLED_MEMORY_TOLERANCES, modes, (int(n) for n in by_kernel))), int(default.steps))


def controlled_error(x, ref):
    """The largest relative error of the figures against the reference's."""
    return max(abs(x[f] - float(getattr(ref, f))) / abs(float(getattr(ref, f))) for f in CONTROLLED_FIGURES)


def span(first, last):
    """Two ratios as "a to b" in one decimal, or one number where they round alike."""
    a, b = f"{min(first, last):.1f}", f"{max(first, last):.1f}"
    return a if a == b else f"{a} to {b}"


def as_accurate(error, ladder, reference):
    """The dashpot at the loosest tolerance of the ladder whose figures are
    at least as accurate as `error`: (tolerance, its error, us per impact),
    or None when none is."""
    for r in ladder:
        e = controlled_error(r["dashpot"], reference["dashpot"])
        if e <= error:
            return r["tolerance"], e, r["dashpot"]["seconds_per_impact"] * 1e6
    return None


def widest_vectors():
    """The widest vectors radau_iia.c picks on this machine's CPU, from the
    flags Linux reports (its run-time choice reads the same CPUID bits)."""
    try:
        flags = next((line.split(":", 1)[1].split() for line in open("/proc/cpuinfo") if line.startswith("flags")), [])
    except OSError:
        flags = []
    return "AVX-512" if "avx512f" in flags else "AVX" if "avx" in flags else "SSE2"


def controlled_section(rows, ladder, reference, by_order, by_kernel, default_steps):
    out = [CONTROLLED_BEGIN, "## The springpot under error control", "",
           "Regenerate this section alone, in place: `scripts/report benchmarks --only controlled` (a few "
           "seconds). The h20 impact (law 2, error-controlled steps) of the dashpot (`damper` 1: Kvaerno's ESDIRK "
           "5(4)) and of the springpot (`damper` 2, alpha 0.5, c_alpha 3e5, compressed memory: Radau IIA with five "
           "stages, docs/model.md §12), CPU per impact of `fc_run_batch` batches alternated between the two, "
           "medians (`fraccontact-bench controlled TOLERANCE`); steps of the whole run (the flight to the specimen "
           "is one), and CPU per step the impact's over them. "
           f"Errors: the largest relative error of {', '.join(CONTROLLED_FIGURES)} against the same damper's "
           f"impact at tolerance {CONTROLLED_REFERENCE:g}.", "",
           "| tolerance | dashpot: us per impact | steps | us per step | largest error | springpot: us per impact | "
           "steps | us per step | largest error | springpot / dashpot |", "|---|---|---|---|---|---|---|---|---|---|"]
    ratios, errors, counts = [], {"dashpot": [], "springpot": []}, {"dashpot": [], "springpot": []}
    for r in rows:
        cells = [f"{r['tolerance']:g}"]
        for name in ("dashpot", "springpot"):
            x = r[name]
            error = controlled_error(x, reference[name])
            errors[name].append(error)
            counts[name].append(x["steps"])
            cells += [f"{x['seconds_per_impact'] * 1e6:.1f}", f"{x['steps']}",
                      f"{x['seconds_per_impact'] / x['steps'] * 1e6:.2f}", f"{error:.1e}"]
        ratios.append(r["springpot"]["seconds_per_impact"] / r["dashpot"]["seconds_per_impact"])
        cells.append(f"{ratios[-1]:.2f}x")
        out.append("| " + " | ".join(cells) + " |")
    met = all(q <= CONTROLLED_BAR for q in ratios)
    step_ratios = [r["springpot"]["seconds_per_impact"] / r["springpot"]["steps"]
                   / (r["dashpot"]["seconds_per_impact"] / r["dashpot"]["steps"]) for r in rows]
    order = {name: math.log(errors[name][0] / errors[name][-1]) / math.log(counts[name][-1] / counts[name][0])
             for name in errors}
    out += ["", f"The bar, the springpot's impact at most {CONTROLLED_BAR:g}x the dashpot's at both "
            f"tolerances: **{'met' if met else 'not met'}** ({', '.join(f'{q:.2f}x' for q in ratios)}). "
            f"The springpot takes {span(counts['springpot'][0] / counts['dashpot'][0], counts['springpot'][-1] / counts['dashpot'][-1])} "
            f"times the dashpot's steps, and each costs {span(*step_ratios)} "
            "times a dashpot step: its five coupled stages (the simplified Newton iteration in A's eigenbasis) "
            f"and, per trial, a pass over its modes in the CPU's widest vectors (here {widest_vectors()}; the "
            "same bits at every width: docs/model.md §12). "
            "From the first tolerance to the second the error falls like the steps to the "
            f"power {order['dashpot']:.1f} for the dashpot and {order['springpot']:.1f} for the springpot, whose "
            "embedded estimate (order 5) is far more cautious than its solution (order 9): at the same tolerance "
            "its figures are the more accurate.", "",
            f"At the same accuracy instead: the dashpot at the loosest of the tolerances {CONTROLLED_LADDER[0]:g} "
            f"to {CONTROLLED_LADDER[-1]:g}, four a decade (each run side by side with the springpot, as above), "
            "whose largest error is at most the springpot's:", "",
            "| springpot at tolerance | its largest error | us per impact | dashpot at tolerance | its largest error "
            "| us per impact | springpot / dashpot |", "|---|---|---|---|---|---|---|"]
    for r, error in zip(rows, errors["springpot"]):
        match = as_accurate(error, ladder, reference)
        mine = r["springpot"]["seconds_per_impact"] * 1e6
        out.append(f"| {r['tolerance']:g} | {error:.1e} | {mine:.1f} | "
                   + (f"{match[0]:g} | {match[1]:.1e} | {match[2]:.1f} | {mine / match[2]:.1f}x |" if match else
                      f"none down to {CONTROLLED_LADDER[-1]:g} | | | |"))
    out += ["", "The steps of the springpot's impact at tolerance "
            f"{CONTROLLED_TOLERANCES[-1]:g} against its order alpha (c_alpha = c w^(1 - alpha), w fixed by the "
            "defaults c and c_alpha at alpha 0.5, so that the damping at the impact's frequency stays the "
            "dashpot's): "
            + ", ".join(f"alpha {a:g}: {n}" for a, n in by_order)
            + f" (the default springpot's: {default_steps}); against the kernel's accuracy, alpha 0.5: "
            + ", ".join(f"memory_tolerance {tol:g} ({m} modes): {n}" for tol, m, n in by_kernel) + ".", "",
            CONTROLLED_END]
    return out


# --- instruction counts ------------------------------------------------------

INSTRUCTIONS_BEGIN, INSTRUCTIONS_END = "<!-- instruction counts: begin -->", "<!-- instruction counts: end -->"
# The regression table: the dashpot's paths before the four changes that
# slowed them (b022927) and where they were found slowed (26f430c), each built anew.
INSTRUCTIONS_BEFORE, INSTRUCTIONS_FOUND = "b022927", "26f430c"
INSTRUCTIONS_REGRESSION_ROWS = (("law 1, fixed steps, per step", "law1_fixed"),
                           ("law 2, fixed steps, per step", "law2_fixed"),
                           ("law 2, `--tolerance 1e-7 --dt-max 1e-3`, per impact", "dashpot_controlled_1e-7"))


def instruction_counter(root):
    """tests/instruction_counts.py, the guard's own counting, as a module."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("instruction_counts", root / "tests" / "instruction_counts.py")
    counter = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(counter)
    return counter


def instruction_rows(root, program, fmu_file):
    """Every row of the record counted on this build, and the regression table's
    rows on the two commits it compares."""
    counter = instruction_counter(root)
    toolchain, record = counter.read_record()
    build = pathlib.Path(program).parent
    paths = {"fraccontact-solve": program, "fraccontact-bench": build / "fraccontact-bench",
             "fmu_importer": build / "fmu_importer",
             "FMU_BINARY": pathlib.Path(str(fmu_file) + ".d") / "binaries" / "linux64" / "fraccontact.so"}
    here = [dict(row, value=counter.measure(row, paths)) for row in record]
    by_name = {row["name"]: row for row in record}
    then = {}
    for commit in (INSTRUCTIONS_BEFORE, INSTRUCTIONS_FOUND):
        say(f"  building {commit} in a temporary git worktree ...")
        with base_build(root, commit, ("fraccontact-solve",)) as base:
            then[commit] = {name: counter.measure(by_name[name], {"fraccontact-solve": base["solve"]})
                            for _, name in INSTRUCTIONS_REGRESSION_ROWS}
    compiler = [line.split("=", 1)[1] for line in (build / "CMakeCache.txt").read_text().splitlines()
                if line.startswith("CMAKE_C_COMPILER:")][0]
    return dict(here=here, then=then, toolchain=counter.toolchain_of(compiler), recorded=toolchain,
                head=git(root, "rev-parse", "--short", "HEAD"))


def instruction_count(value):
    return f"{value / 1e3:.1f} k" if value >= 1e4 else f"{value:.0f}"


def instructions_section(r):
    before, found = (r["then"][c] for c in (INSTRUCTIONS_BEFORE, INSTRUCTIONS_FOUND))
    here = {row["name"]: row for row in r["here"]}
    out = [INSTRUCTIONS_BEGIN, "## Instruction counts", "",
           "Regenerate this section alone, in place: `scripts/report benchmarks --only instructions` (under a "
           f"minute: it builds {INSTRUCTIONS_BEFORE} and {INSTRUCTIONS_FOUND} in temporary git worktrees). "
           "Instructions counted by valgrind's callgrind as the difference of two repeat counts, so that start-up "
           "and output cancel: exact, whatever the machine's load (the commands: `tests/instruction_counts.tsv`). "
           f"Measured on commit {r['head']}, built by {r['toolchain']}"
           + ("." if r["toolchain"] == r["recorded"] else f" (the record's: {r['recorded']})."), "",
           f"| run | {INSTRUCTIONS_BEFORE} | {INSTRUCTIONS_FOUND} | this commit | this / {INSTRUCTIONS_BEFORE} |",
           "|---|---|---|---|---|"]
    for label, name in INSTRUCTIONS_REGRESSION_ROWS:
        v = here[name]["value"]
        out.append(f"| {label} | {instruction_count(before[name])} | {instruction_count(found[name])} | "
                   f"{instruction_count(v)} | {v / before[name]:.3f} |")
    worst = max(here[name]["value"] / before[name] for _, name in INSTRUCTIONS_REGRESSION_ROWS)
    out += ["", f"Every row at or below {INSTRUCTIONS_BEFORE}'s: **{'yes' if worst <= 1.0 else 'no'}** "
            f"(at most {worst:.3f} of it).", "",
            "The guard: `ctest -R instruction_counts` (in the normal build, where valgrind is installed; not in the "
            "sanitizer build) counts these rows and fails one more than 2 % above its record in "
            "`tests/instruction_counts.tsv`, or more than 10 % below it (a record that low would let a regression "
            "of that size pass). The record holds for the toolchain it names; another one skips the test. After a "
            "change that moves a count on purpose, `cmake --build build --target update-instruction-counts` "
            "rewrites the record, in a commit that says why.", "",
            "| row | command | per | record | this build | this / record |", "|---|---|---|---|---|---|"]
    for row in r["here"]:
        out.append(f"| {row['name']} | `{row['command']}` | {row['unit']} | {row['record']:,.1f} | "
                   f"{row['value']:,.1f} | {row['value'] / row['record']:.4f} |")
    out += ["", INSTRUCTIONS_END]
    return out


def write(path, steps, precision, g1, alpha, package, springpot, controlled):
    out = ["# Benchmarks", "",
           f"{REGENERATE}. Everything below was measured side by side "
           f"in one run, on {platform.processor() or platform.machine()} ({platform.system()}), one process, "
           "CPU time, medians of repeated runs. On this shared virtual machine the same binary's timings move by "
           "up to 30 % from one run to the next; the ratios within one run are steadier.", "",
           *kept_section(path, SWEEP_BEGIN, SWEEP_END, [
               "The sweep at scale (`fraccontact sweep` end to end against the C core, one worker and "
               "two, the serial fraction, the client's memory): [sweep_scaling.md](sweep_scaling.md), regenerated "
               "by `scripts/report sweep_scaling`."]), "",
           *steps_section(steps), ""]
    out += precision
    out += ["", f"## G1 history sum of f(x) = x, alpha = {alpha}, against differint 1.0.0", "",
            "N intervals of [0, 1]. Newest point: `g1_history_sum` (weights included) against "
            "`differint.GLpoint`; full grid: `g1_full_grid` (zero-padded FFT, the first N/128 points summed "
            "directly) against `differint.GL`. Errors are the largest over every grid point, relative to the "
            "closed-form G1 value there (computed independently in reports/benchmarks.py).", "",
            "| N | ours, newest point | differint GLpoint | ratio | ours, full grid | differint GL | ratio | "
            "our worst error | differint GL worst error | differint GL points off by > 1e-9 | "
            "differint GLpoint error |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in g1:
        o = r["ours"]
        out.append(f"| {r['N']:,} | {o['newest_seconds'] * 1e6:.1f} us | {r['differint_point'] * 1e6:.0f} us | "
                   f"{r['differint_point'] / o['newest_seconds']:.0f}x | {o['full_seconds'] * 1e3:.2f} ms | "
                   f"{r['differint_full'] * 1e3:.2f} ms | {r['differint_full'] / o['full_seconds']:.2f}x | "
                   f"{max(o['full_max_error'], o['newest_error']):.1e} | {r['differint_full_error']:.1e} | "
                   f"{r['differint_wrong_points']:,} of {r['N']:,} | {r['differint_point_error']:.1e} |")
    lengths = ", ".join(f"{r['differint_length']:,} for {r['N'] + 1:,}" for r in g1)
    out += ["", "differint's `GL` multiplies the FFTs of the weights and the samples without zero padding: a "
            "circular convolution, so the oldest weights wrap around onto the newest samples and the points are "
            f"wrong; for an odd number of points it also returns one value too few ({lengths} points; a missing "
            "point counts as off). `GLpoint` scales by (N+1)/(b-a) where the grid's step is (b-a)/N, an O(1/N) "
            "error. Ours is compiled and O(N) at the newest point; over the full grid it pays for the padding and "
            "the direct head but is right at every point.", ""] + package + [""] + springpot + [""] + controlled
    out += [""] + kept_section(path, INSTRUCTIONS_BEGIN, INSTRUCTIONS_END, [])
    atomic.write_text(path, "\n".join(out) + "\n")


# --- Model Exchange ----------------------------------------------------------

EXCHANGE_BEGIN, EXCHANGE_END = "<!-- model exchange: begin -->", "<!-- model exchange: end -->"
EXCHANGE_STOP, EXCHANGE_INTERVAL = 2e-3, 1e-5  # the h20 impact's run and its output (communication) points
EXCHANGE_RTOLS = tuple(10.0 ** -k for k in range(6, 13))  # fmpy CVode's relative tolerance, coarse to fine
COSIM_TOLERANCES = tuple(10.0 ** -k for k in range(6, 13))  # the co-simulation's error-controlled steps
SPRINGPOT_RTOL = 1e-8  # the springpot's run in Model Exchange, with and without the directional derivatives


def cvode_counting():
    """fmpy's CVode with its work counted (steps, right-hand sides, Jacobians,
    the right-hand sides of its difference-quotient Jacobians), and, with
    jacobian=True, its Newton matrix from the FMU's fmi2GetDirectionalDerivative
    instead of difference quotients. The class fmpy.simulate_fmu makes (patched
    in by exchange_run); the instance it made last is its `last`."""
    import ctypes
    from fmpy import sundials
    from fmpy.sundials.libraries import sundials_cvode, sundials_sunmatrixdense

    counters = {name: getattr(sundials_cvode, "CVodeGet" + name) for name in
                ("NumSteps", "NumRhsEvals", "NumJacEvals", "NumLinRhsEvals")}
    for fn in counters.values():
        fn.argtypes, fn.restype = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_long)], ctypes.c_int
    set_jacobian = sundials_cvode.CVodeSetJacFn
    vector, matrix = sundials.N_Vector, sundials.SUNMatrix
    jacobian_type = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, vector, vector, matrix, ctypes.c_void_p,
                                     vector, vector, vector)
    set_jacobian.argtypes, set_jacobian.restype = [ctypes.c_void_p, jacobian_type], ctypes.c_int
    matrix_data = sundials_sunmatrixdense.SUNDenseMatrix_Data
    matrix_data.argtypes, matrix_data.restype = [matrix], ctypes.c_void_p

    class Counting(sundials.CVodeSolver):
        jacobian = False
        model_description = None
        last = None

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.totals = dict.fromkeys(counters, 0)
            type(self).last = self
            if self.jacobian:
                self.use_directional_derivatives(kwargs["set_time"].__self__)  # fmpy's FMU2Model

        def use_directional_derivatives(self, fmu):
            states = [d.variable.derivative.valueReference for d in self.model_description.derivatives]
            n = len(states)
            unknowns = (ctypes.c_uint * n)(*(d.variable.valueReference for d in self.model_description.derivatives))
            known, seed = ctypes.c_uint(), ctypes.c_double(1.0)
            directional = fmu.dll.fmi2GetDirectionalDerivative
            directional.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p,
                                    ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
            directional.restype = ctypes.c_int

            def jacobian(t, y, fy, jac, user_data, tmp1, tmp2, tmp3):
                self.set_time(t)
                self.set_x(sundials.NV_DATA_S(y), n)
                column = matrix_data(jac)
                for j, vr in enumerate(states):  # the matrix's columns follow each other
                    known.value = vr
                    if directional(fmu.component, unknowns, n, ctypes.byref(known), 1, ctypes.byref(seed),
                                   column + 8 * n * j) != 0:
                        return -1
                return 0

            self.jacobian_ = jacobian_type(jacobian)
            assert set_jacobian(self.cvode_mem, self.jacobian_) == 0

        def live(self):
            value = ctypes.c_long()
            found = {}
            for name, fn in counters.items():
                fn(self.cvode_mem, ctypes.byref(value))
                found[name] = value.value
            return found

        def reset(self, time):  # CVodeReInit starts the counts again
            for name, value in self.live().items():
                self.totals[name] += value
            return super().reset(time)

        def counts(self):
            return {name: self.totals[name] + value for name, value in self.live().items()}

    return Counting


def exchange_run(folder, model_description, rtol, jacobian=False, **start):
    """One Model Exchange run of the h20 drop test (law 2) in fmpy's CVode:
    its final row, and CVode's counts."""
    from unittest import mock
    from fmpy import simulate_fmu, sundials
    counting = cvode_counting()
    counting.jacobian, counting.model_description = jacobian, model_description
    with mock.patch.object(sundials, "CVodeSolver", counting):
        r = simulate_fmu(folder, fmi_type="ModelExchange", solver="CVode", relative_tolerance=rtol,
                         stop_time=EXCHANGE_STOP, output_interval=EXCHANGE_INTERVAL,
                         start_values=dict(law=2, **start), output=["F_peak", "eps", "x2"],
                         model_description=model_description)
    return r[-1], counting.last.counts()


def cosim_run(folder, model_description, tolerance):
    """The co-simulation FMU on the same impact and communication points:
    the error-controlled steps (ESDIRK 5(4)) at `tolerance`."""
    from fmpy import simulate_fmu
    r = simulate_fmu(folder, stop_time=EXCHANGE_STOP, output_interval=EXCHANGE_INTERVAL,
                     start_values=dict(law=2, tolerance=tolerance), output=["F_peak", "eps", "x2"],
                     model_description=model_description)
    return r[-1]


def exchange_rows(program, fmu_file):
    """The h20 impact by Model Exchange (CVode) against co-simulation, each at
    the coarsest setting whose F_peak stays within TARGET of GSL's, timed side
    by side; the compressed springpot in Model Exchange with and without the
    directional derivatives."""
    from fmpy import extract, read_model_description
    folder = extract(str(fmu_file or fmu.fmu_path()))
    md = read_model_description(folder)
    F_peak = solve(program, "--reference", "--law", "hertz")["F_peak"]
    error = lambda row: abs(row["F_peak"] / F_peak - 1.0)
    me_errors = {rtol: error(exchange_run(folder, md, rtol)[0]) for rtol in EXCHANGE_RTOLS}
    cs_errors = {tol: error(cosim_run(folder, md, tol)) for tol in COSIM_TOLERANCES}
    rtol = first_setting_that_stays_within(EXCHANGE_RTOLS, me_errors.get)
    tol = first_setting_that_stays_within(COSIM_TOLERANCES, cs_errors.get)
    me_cpu, cs_cpu = [], []
    for _ in range(REPEATS):  # alternating, so that the machine's load falls on both alike
        me_cpu.append(median_cpu(lambda: exchange_run(folder, md, rtol), budget=1.0, at_least=3))
        cs_cpu.append(median_cpu(lambda: cosim_run(folder, md, tol), budget=1.0, at_least=3))
    h20 = dict(rtol=rtol, tolerance=tol, me_error=me_errors[rtol], cs_error=cs_errors[tol],
               me_cpu=float(np.median(me_cpu)), cs_cpu=float(np.median(cs_cpu)),
               me_counts=exchange_run(folder, md, rtol)[1], me_errors=me_errors, cs_errors=cs_errors)
    cpu = {False: [], True: []}
    for _ in range(REPEATS):  # alternating too
        for jacobian in cpu:
            cpu[jacobian].append(median_cpu(lambda: exchange_run(folder, md, SPRINGPOT_RTOL, jacobian, damper=2),
                                            budget=1.0, at_least=3))
    springpot = {}
    for jacobian in cpu:
        row, counts = exchange_run(folder, md, SPRINGPOT_RTOL, jacobian, damper=2)
        springpot[jacobian] = dict(F_peak=row["F_peak"], eps=row["eps"], cpu=float(np.median(cpu[jacobian])),
                                   counts=counts)
    return h20, springpot


def exchange_section(h20, springpot):
    from fmpy import __version__ as fmpy_version
    c, j = springpot[False], springpot[True]
    out = [EXCHANGE_BEGIN, "## Model Exchange against co-simulation, and the directional derivatives", "",
           "Regenerate this section alone, in place: `scripts/report benchmarks --only exchange` (under a minute). "
           f"The h20 impact (law 2, the dashpot) over {EXCHANGE_STOP * 1e3:g} ms with output points "
           f"{EXCHANGE_INTERVAL * 1e6:g} us apart, through fmpy {fmpy_version}'s `simulate_fmu` and the FMI 2.0 "
           "FMU: by Model Exchange, fmpy's CVode (BDF, its Newton matrix by difference quotients), and by co-simulation, the "
           "FMU's error-controlled steps (ESDIRK 5(4), each output point a communication step); each at the "
           "coarsest setting from which on every finer one keeps F_peak within 1e-6 of GSL's "
           "(`fraccontact-solve --reference --law hertz`), CPU time of the whole run, fmpy's Python loop included, "
           f"medians of {REPEATS} alternating rounds.", "",
           "| interface | setting | F_peak error | CPU per impact |", "|---|---|---|---|",
           f"| Model Exchange (CVode) | rtol {h20['rtol']:.0e} | {h20['me_error']:.1e} | "
           f"{h20['me_cpu'] * 1e3:.1f} ms |",
           f"| co-simulation | tolerance {h20['tolerance']:.0e} | {h20['cs_error']:.1e} | "
           f"{h20['cs_cpu'] * 1e3:.1f} ms |", "",
           f"Model Exchange takes {h20['me_cpu'] / h20['cs_cpu']:.1f}x the co-simulation's CPU here: CVode took "
           f"{h20['me_counts']['NumSteps']} steps and {h20['me_counts']['NumRhsEvals']} derivative evaluations "
           f"(and {h20['me_counts']['NumLinRhsEvals']} for {h20['me_counts']['NumJacEvals']} difference-quotient "
           "Jacobians), each a call from Python into the FMU. The F_peak errors over the ladders:", "",
           "| setting | Model Exchange (rtol) | co-simulation (tolerance) |", "|---|---|---|"]
    for rtol, tol in zip(EXCHANGE_RTOLS, COSIM_TOLERANCES):
        out.append(f"| {rtol:.0e} | {h20['me_errors'][rtol]:.1e} | {h20['cs_errors'][tol]:.1e} |")
    out += ["", f"The compressed springpot (damper 2, memory 2, its default kernel) in the same drop test by Model "
            f"Exchange at rtol {SPRINGPOT_RTOL:.0e}, 164 states: CVode's Newton matrix by its difference quotients "
            "(a derivative evaluation per state and Jacobian) against the FMU's directional derivatives "
            "(`fmi2GetDirectionalDerivative`, a column per call, through a Jacobian function given to fmpy's "
            "CVode, which fmpy's `simulate_fmu` does not offer; `reports/benchmarks.py` adds it), CPU medians of "
            f"{REPEATS} alternating rounds.", "",
            "| Newton matrix | CPU per impact | steps | derivative evaluations | Jacobians | derivative evaluations "
            "for Jacobians | F_peak |", "|---|---|---|---|---|---|---|"]
    for label, r in (("difference quotients", c), ("directional derivatives", j)):
        k = r["counts"]
        out.append(f"| {label} | {r['cpu'] * 1e3:.1f} ms | {k['NumSteps']} | {k['NumRhsEvals']} | "
                   f"{k['NumJacEvals']} | {k['NumLinRhsEvals']} | {r['F_peak']:.9g} N |")
    out += ["", f"The directional derivatives take {j['cpu'] / c['cpu']:.2f}x the difference quotients' CPU; "
            f"their F_peak differ by {abs(j['F_peak'] / c['F_peak'] - 1):.1e} (relative), within the host's "
            "tolerance.", EXCHANGE_END]
    return out


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    output.add_solver(parser, "fraccontact-solve; fraccontact-bench is beside it")
    output.add_fmu(parser)
    parser.add_argument("--only", choices=["steps", "precision", "package", "springpot", "controlled", "instructions",
                                           "exchange"],
                        help="regenerate one section alone, in place (steps: the ns per internal step of each "
                             "spring law; precision: work against precision on all four "
                             "figures, and the FMU's one-doStep impact; package: the Python package against the C "
                             "core; springpot: the springpot's memories, and the dashpot against the commit before "
                             "them; controlled: the springpot against the dashpot under error control; "
                             "instructions: the instruction counts of the guard's runs, and the regression table; "
                             "exchange: Model Exchange against co-simulation, and with and without the directional "
                             "derivatives)")
    parser.add_argument("--largest-n", type=float, default=1e6,
                        help="the springpot ladder's largest N (default 1e6; smaller for a quick look)")
    args = output.parse(parser, argv)
    program, bench = args.solver, solver.bench_path(args.solver)
    if args.only == "steps":
        say("cost of a step ...")
        replace_section(args.out / "benchmarks.md", steps_section(measured_steps(bench)), STEPS_BEGIN, STEPS_END)
        print((args.out / "benchmarks.md").read_text())
        return
    if args.only == "precision":
        say("work against precision ...")
        section = precision(source_tree(), program, bench, args.fmu, args.out)
        replace_section(args.out / "benchmarks.md", section, PRECISION_BEGIN, PRECISION_END)
        print((args.out / "benchmarks.md").read_text())
        return
    if args.only == "package":
        say("the Python package against the C core ...")
        replace_section(args.out / "benchmarks.md", package_section(*package_rows(program, bench)))
        print((args.out / "benchmarks.md").read_text())
        return
    if args.only == "springpot":
        say("the springpot ...")
        section = springpot_section(springpot_rows(source_tree(), bench, args.fmu, args.largest_n))
        replace_section(args.out / "benchmarks.md", section, SPRINGPOT_BEGIN, SPRINGPOT_END)
        print((args.out / "benchmarks.md").read_text())
        return
    if args.only == "controlled":
        say("the springpot under error control ...")
        replace_section(args.out / "benchmarks.md", controlled_section(*controlled_rows(bench)), CONTROLLED_BEGIN,
                        CONTROLLED_END)
        print((args.out / "benchmarks.md").read_text())
        return
    if args.only == "instructions":
        say("instruction counts ...")
        section = instructions_section(instruction_rows(source_tree(), program, args.fmu))
        replace_section(args.out / "benchmarks.md", section, INSTRUCTIONS_BEGIN, INSTRUCTIONS_END)
        print((args.out / "benchmarks.md").read_text())
        return
    if args.only == "exchange":
        say("Model Exchange ...")
        replace_section(args.out / "benchmarks.md", exchange_section(*exchange_rows(program, args.fmu)),
                        EXCHANGE_BEGIN, EXCHANGE_END)
        print((args.out / "benchmarks.md").read_text())
        return
    root = source_tree()
    say("1/5 cost of a step ...")
    steps = measured_steps(bench)
    say("2/5 work against precision ...")
    precision_lines = precision(root, program, bench, args.fmu, args.out)
    say("3/5 G1 against differint ...")
    g1 = g1_rows(bench, -0.5)
    say("4/5 the Python package against the C core ...")
    package = package_section(*package_rows(program, bench))
    say("5/5 the springpot ...")
    springpot = springpot_section(springpot_rows(root, bench, args.fmu, args.largest_n))
    say("the springpot under error control ...")
    controlled = controlled_section(*controlled_rows(bench))
    write(args.out / "benchmarks.md", steps, precision_lines, g1, -0.5, package, springpot, controlled)
    say("Model Exchange ...")
    replace_section(args.out / "benchmarks.md", exchange_section(*exchange_rows(program, args.fmu)), EXCHANGE_BEGIN,
                    EXCHANGE_END)
    print((args.out / "benchmarks.md").read_text())

