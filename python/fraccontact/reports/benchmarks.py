"""Benchmarks, measured side by side in one run on this machine:
  1. ns per internal step of each spring law (and of the literal O(N) G1 sum);
  2. impacts per second for the h20 drop test with F_peak within 1e-6 of the
     reference: fraccontact-solve against scipy's solve_ivp on the same ODE
     and against the GSL reference;
  3. the bare G1 history sum of f(x) = x, N = 1e3 to 1e6, newest point and
     full grid, against the PyPI package differint, each result checked at
     every grid point against the closed form of MODEL.md §4;
  4. the Python package against the C core: fraccontact.impacts against
     fraccontact-bench batch (CPU per impact), a process per impact,
     fraccontact sweep on 1 and 2 local Dask workers, a 1000-row curve fit.
Writes docs/benchmarks.md. Medians of repeated runs; CPU time of one process
for 1 to 3 and the per-impact costs of 4, wall time for 4's sweeps and fit.

Regenerate: scripts/report benchmarks   (several minutes)
            scripts/report benchmarks --only package   (section 4 alone, in place)
"""

import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.special import gamma

import differint.differint as differint

from .. import atomic, fit, model, reports, solver
from ..scipy_contact import solve_drop

H20 = model.defaults()
K, C, M, V0 = H20["k"], H20["c"], H20["m"], H20["v"]
TARGET = 1e-6
DTS = [1e-5 / 2 ** i for i in range(12)]
TOLERANCES = [10.0 ** -e for e in range(3, 13)]
# Section 4: (label, law, dt_max, impacts in one fraccontact.impacts call,
# impacts in a sweep). The cheap setting is the coarsest accurate to 1e-6.
SETTINGS = (("cheap: law 2 (Hertz), dt_max 3e-6", 2, 3e-6, 2000, 20000),
            ("default: law 1 (G1), dt_max 1e-7", 1, 1e-7, 300, 4000))
PROCESSES = 300  # impacts run as one fraccontact-solve process each
REPEATS = 3
FIT_ROWS = 1000
BEGIN, END = "<!-- package: begin -->", "<!-- package: end -->"


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
           "share them with the scheduler and this report's process, which wait on them.",
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


def replace_section(path, section):
    """The report at path with the section between BEGIN and END replaced
    (appended when it has none)."""
    text = path.read_text() if path.exists() else "# Benchmarks\n"
    block = "\n".join(section) + "\n"
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        text = head + block.rstrip("\n") + rest.split(END, 1)[1]
    else:
        text = text.rstrip("\n") + "\n\n" + block
    atomic.write_text(path, text)


# --- the report ---------------------------------------------------------------

def write(path, steps, impacts, g1, alpha, package):
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
            "the direct head but is right at every point.", ""] + package
    atomic.write_text(path, "\n".join(out) + "\n")


def main(argv=None, prog=None):
    parser = reports.parser(prog, __doc__)
    reports.add_solver(parser, "fraccontact-solve; fraccontact-bench is beside it")
    parser.add_argument("--only", choices=["package"],
                        help="regenerate one section alone, in place (package: the Python package against the C core)")
    args = reports.parse(parser, argv)
    program, bench = args.solver, solver.bench_path(args.solver)
    args.out.mkdir(parents=True, exist_ok=True)
    if args.only == "package":
        say("the Python package against the C core ...")
        replace_section(args.out / "benchmarks.md", package_section(*package_rows(program, bench)))
        print((args.out / "benchmarks.md").read_text())
        return
    say("1/4 cost of a step ...")
    steps = step_costs(bench)
    say("2/4 impacts per second ...")
    impacts = impacts_per_second(program)
    say("3/4 G1 against differint ...")
    g1 = g1_rows(bench, -0.5)
    say("4/4 the Python package against the C core ...")
    package = package_section(*package_rows(program, bench))
    write(args.out / "benchmarks.md", steps, impacts, g1, -0.5, package)
    print((args.out / "benchmarks.md").read_text())

