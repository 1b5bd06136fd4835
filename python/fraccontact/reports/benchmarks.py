"""Benchmarks, measured side by side in one run on this machine:
  1. ns per internal step of each spring law (and of the literal O(N) G1 sum);
  2. impacts per second for the h20 drop test with F_peak within 1e-6 of the
     reference: fraccontact-solve against scipy's solve_ivp on the same ODE
     and against the GSL reference;
  3. the bare G1 history sum of f(x) = x, N = 1e3 to 1e6, newest point and
     full grid, against the PyPI package differint, each result checked at
     every grid point against the closed form of MODEL.md §4.
Writes docs/benchmarks.md. Medians of repeated runs; CPU time of one process.

Regenerate: scripts/report benchmarks   (a few minutes)
"""

import math
import platform
import sys
import time

import numpy as np
from scipy.special import gamma

import differint.differint as differint

from .. import atomic, model, reports, solver
from ..scipy_contact import solve_drop

H20 = model.defaults()
K, C, M, V0 = H20["k"], H20["c"], H20["m"], H20["v"]
TARGET = 1e-6
DTS = [1e-5 / 2 ** i for i in range(12)]
TOLERANCES = [10.0 ** -e for e in range(3, 13)]


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


# --- 2. impacts per second at F_peak within 1e-6 --------------------------------

def impacts_per_second(program):
    ref = solve(program, "--reference", "--law", "hertz", "--rtol", "1e-12")
    rows = []
    for label, law in (("fraccontact-solve, Hertz law (SDIRK2)", "hertz"),
                       ("fraccontact-solve, G1 + Richardson (law 3)", "g1x")):
        errs = {dt: abs(solve(program, "--law", law, "--dt-max", dt)["F_peak"] / ref["F_peak"] - 1) for dt in DTS}
        dt = first_setting_that_stays_within(DTS, errs.get)
        r = solve(program, "--law", law, "--dt-max", dt, "--repeat", 301)
        rows.append(dict(label=label, setting=f"dt = {dt:.3g} s", error=errs[dt], cpu=r["cpu_seconds"]))
    say("  GSL reference ...")
    errs = {}
    for rtol in TOLERANCES:
        errs[rtol] = abs(solve(program, "--reference", "--law", "hertz", "--rtol", rtol)["F_peak"] / ref["F_peak"] - 1)
    rtol = first_setting_that_stays_within(TOLERANCES, errs.get)
    r = solve(program, "--reference", "--law", "hertz", "--rtol", rtol, "--repeat", 101)
    rows.append(dict(label="GSL odeiv2 rk8pd (fraccontact-solve --reference)", setting=f"rtol = {rtol:.0e}",
                     error=errs[rtol], cpu=r["cpu_seconds"]))
    for method in ("LSODA", "DOP853", "Radau"):
        say(f"  scipy {method} ...")
        errs = {rtol: abs(solve_drop(K, C, M, V0, method=method, rtol=rtol)["F_peak"] / ref["F_peak"] - 1)
                for rtol in TOLERANCES}
        rtol = first_setting_that_stays_within(TOLERANCES, errs.get)
        if rtol is None:
            rows.append(dict(label=f"scipy solve_ivp {method}", setting="none reaches 1e-6", error=min(errs.values()),
                             cpu=float("nan")))
            continue
        cpu = median_cpu(lambda: solve_drop(K, C, M, V0, method=method, rtol=rtol))
        rows.append(dict(label=f"scipy solve_ivp {method}", setting=f"rtol = {rtol:.0e}", error=errs[rtol], cpu=cpu))
    return rows


# --- 3. the G1 history sum against differint -------------------------------------

def line_g1(alpha, n, delta):
    """The G1 value of D^alpha x at grid points n (MODEL.md §4), computed here
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


# --- the report ---------------------------------------------------------------

def write(path, steps, impacts, g1, alpha):
    h = steps["ns_per_step"]
    lit = steps["ns_literal_sum"]
    ours = impacts[0]["cpu"]
    out = ["# Benchmarks", "",
           "Regenerate: `scripts/report benchmarks` (a few minutes). Everything below was measured side by side "
           f"in one run, on {platform.processor() or platform.machine()} ({platform.system()}), one process, "
           "CPU time, medians of repeated runs. On this shared virtual machine the same binary's timings move by "
           "up to 30 % from one run to the next; the ratios within one run are steadier.", "",
           "## Cost of an internal step", "",
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
    out += ["", f"Summed literally at every step (N = steps since onset), an h20 impact at dt = 1e-7 s would cost "
            f"about {total:.1f} s instead of {h['g1'] * 13160 * 1e-6:.2f} ms.", "",
            "## Impacts per second with F_peak within 1e-6", "",
            "The h20 drop test, first impact, against the GSL reference at rtol 1e-12. For each solver the "
            "coarsest step or loosest tolerance from which on every finer one keeps F_peak within 1e-6.", "",
            "| solver | setting | F_peak error | CPU per impact | impacts per second | CPU time / fraccontact's |",
            "|---|---|---|---|---|---|"]
    for r in impacts:
        ratio = r["cpu"] / ours
        out.append(f"| {r['label']} | {r['setting']} | {r['error']:.1e} | {r['cpu'] * 1e6:.1f} us | "
                   f"{1 / r['cpu']:,.0f} | {ratio:.1f} |" if math.isfinite(r["cpu"]) else
                   f"| {r['label']} | {r['setting']} | {r['error']:.1e} | | | |")
    out += ["", f"## G1 history sum of f(x) = x, alpha = {alpha}, against differint 1.0.0", "",
            "N intervals of [0, 1]. Newest point: `g1_history_sum` (weights included) against "
            "`differint.GLpoint`; full grid: `g1_full_grid` (zero-padded FFT, the first N/128 points summed "
            "directly) against `differint.GL`. Errors are the largest over every grid point, relative to the "
            "closed-form G1 value there (computed independently in fraccontact/reports/benchmarks.py).", "",
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
            "the direct head but is right at every point."]
    atomic.write_text(path, "\n".join(out) + "\n")


def main(argv=None, prog=None):
    parser = reports.parser(prog, __doc__)
    reports.add_solver(parser, "fraccontact-solve; fraccontact-bench is beside it")
    args = reports.parse(parser, argv)
    program, bench = args.solver, solver.bench_path(args.solver)
    say("1/3 cost of a step ...")
    steps = step_costs(bench)
    say("2/3 impacts per second ...")
    impacts = impacts_per_second(program)
    say("3/3 G1 against differint ...")
    g1 = g1_rows(bench, -0.5)
    args.out.mkdir(parents=True, exist_ok=True)
    write(args.out / "benchmarks.md", steps, impacts, g1, -0.5)
    print((args.out / "benchmarks.md").read_text())

