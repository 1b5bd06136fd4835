"""Parameter sweeps on Dask: the drop test over a grid of heights (the
paper's 5 to 100 mm in 5 mm steps by default), masses, materials or any
parameter of the model, or a Monte Carlo campaign over their scatter. Each
Dask task runs a chunk of cases in one call of the C library
(fraccontact.impacts: arrays in, arrays out). Prints a progress bar, writes a
CSV of every impact and a plot of F_peak, eps, contact time and permanent
indentation against the swept variable (histograms for Monte Carlo).

  fraccontact sweep                                   # the paper's heights, a local cluster
  fraccontact sweep --vary c=2000,6080,20000 --vary height=0.01:0.1:0.01
  fraccontact sweep --vary law=g1,hertz --vary t_end=0.05,0.2 --set impacts=3 --set g=9.81
  fraccontact sweep --monte-carlo 100000 --scatter k=0.05 --scatter c=10% --scheduler tcp://host:8786

NAME (--vary, --set, --scatter) is a parameter of the model, as
fraccontact.parameters() lists them (the FMU's variables v, m, R, E_i,
nu_i, E_s, nu_s, k, c, law, g1_nodes, dt_max, scene, g, gap0, the scheme and
the stop conditions t_end and impacts), or height (the drop height: v =
sqrt(2 g h)); - or _ alike: E_s or E-s, t_end or t-end. Real parameters
take a grid a:b:step or a list v1,v2, integer ones too; law, scene and
scheme also their words (law=g1,hertz,g1x). A name is given once: set
(--set), varied (--vary) or, in a Monte Carlo campaign, scattered around
its --set value (--scatter); height and v are one quantity, given once.

A grid a:b:step holds a + i step for i = 0, 1, ... while it does not pass
b, computed exactly from the numbers as typed (decimal) and then rounded
to the nearest double: 0.005:0.1:0.005 gives 0.005, 0.01, ..., 0.035, ...,
0.1, and b is in the grid when it is a + i step exactly. A sweep holds every
case and result in memory: at most 1 000 000 impacts (the product of the
grids' sizes, or --monte-carlo N); split a larger campaign.

A material (R, E_i, nu_i, E_s, nu_s) acts only through the Hertz constant
it gives when k = 0: the library's default k (the paper's fitted one) wins
over it. To sweep a material, --set k=0 --vary E_s=1e9,2e9; the sweep
warns, with the library's message, when a value it is given has no effect.

The default law: g1, the library's own (the G1 history sum, the model the
README describes); --set law=hertz for the closed form.

Monte Carlo: --monte-carlo N (N >= 1) draws N impacts instead of a grid
(no --vary beside it; --scatter and --seed only with it). --scatter
NAME=S draws NAME log-normally, with mean its nominal value (--set
NAME=VALUE, else the library's default) and coefficient of variation S
(standard deviation / mean), a fraction (0.05) or a percentage (5%).
Log-normal, it stays positive at any S. Only real parameters with a
positive nominal value scatter: a relative scatter of zero (g, gap0 at
their defaults) or of a negative value means nothing, so those are refused,
as is a negative S.

Writes to --out: sweep.csv (per impact: the inputs varied, then the run's
figures as fraccontact.impact names them: the first impact's t_onset,
v_onset, F_peak, eps, t_contact, x2_end, E_diss (NaN when none ended),
impacts, steps and k; NAME_result when NAME is also a column of the inputs,
as impacts or k; a case the library refuses has its message in the column
error), sweep.png, and sweep.json (counts and throughput; for Monte Carlo
also the mean, sample standard deviation and 5/50/95 % percentiles of every
numeric column over the impacts that succeeded, which are printed too).

Runs on a local Dask cluster (--workers processes) or on any running Dask
scheduler (--scheduler ADDRESS, refused when none answers there within 5 s;
--workers is the local cluster's), whose workers must import fraccontact
(pip install .). Every option is checked, and --out too, before the
cluster starts. The wall time and the impacts per second count the Dask tasks
alone, from the first submitted to the last finished (before, each worker
has imported the package and run the first case once).
"""

import argparse
import csv
import importlib
import itertools
import json
import math
import os
import pathlib
import sys
import time
import warnings
from fractions import Fraction

import numpy as np

from . import atomic, model
from .progress import progress

DEFAULT_HEIGHTS = "0.005:0.1:0.005"
# The most impacts a sweep runs: it holds every case and every result row
# in memory on the client, as Python objects.
MAX_IMPACTS = 1_000_000
# How long --scheduler waits for its scheduler to answer [s]: a scheduler
# that is up answers at once, and a wrong address should not cost longer.
CONNECT_TIMEOUT = 5
OUTPUTS = ("sweep.csv", "sweep.png", "sweep.json")
WORKERS = 2  # the local cluster's worker processes by default
HEIGHT = dict(name="height", kind="real", unit="m", default=None, help="drop height: v = sqrt(2 g h)")
# The results of a run, as fraccontact.impacts returns them: the first
# impact's figures (NaN where none ended), then the run's counts and k.
RESULTS = model.IMPACT_FIGURES + ("impacts", "steps", "k")
COUNTS = ("impacts", "steps")
# The default chunks: up to TASKS_PER_WORKER a worker, to balance the load and
# show progress in a long campaign, but one a worker while that leaves fewer
# than CHUNK_MIN cases in a chunk (a Dask task costs about 10 ms of round trip,
# 250 cheap impacts: law 2, dt_max 3e-6).
TASKS_PER_WORKER = 4
CHUNK_MIN = 5000
# The plotted results: (key, scale to the unit shown, what it is, unit).
PLOTTED = (("F_peak", 1, "peak force F_peak", "N"), ("eps", 1, "restitution coefficient eps", "1"),
           ("t_contact", 1e3, "contact time", "ms"), ("x2_end", 1e6, "permanent indentation", "µm"))


def parameter_table():
    """The library's parameters and height, by name."""
    return {p["name"]: p for p in model.parameters() + [HEIGHT]}


def default_law():
    """The library's default law, as a word."""
    return next(word for word, code in model.WORDS["law"].items() if code == model.defaults()["law"])


def parameter(table, name):
    """The table entry of NAME (- or _ alike); refused when unknown."""
    entry = table.get(name.replace("-", "_"))
    if entry is None:
        raise ValueError(f"unknown parameter '{name}': NAME is one of {', '.join(table)} (- or _ alike)")
    return entry


def value(entry, text):
    """TEXT as the parameter's kind: a number, or for law, scene and scheme
    also one of their words."""
    name, kind = entry["name"], entry["kind"]
    words = model.WORDS.get(name, {})
    if text in words:
        return text
    try:
        return float(text) if kind == "real" else int(text)
    except ValueError:
        if words:
            raise ValueError(f"'{text}' is not one of {', '.join(words)} "
                             f"(or {', '.join(map(str, words.values()))})") from None
        raise ValueError(f"'{text}' is not {'a number' if kind == 'real' else 'a whole number'}") from None


def values(entry, spec):
    """'start:stop:step' (real and integer parameters; grid()), or 'v1,v2,...'."""
    if ":" not in spec:
        return [value(entry, v) for v in spec.split(",")]
    bounds = spec.split(":")
    if len(bounds) != 3:
        raise ValueError("a grid is start:stop:step")
    numbers = [value(entry, x) for x in bounds]
    if any(isinstance(x, str) for x in numbers):
        raise ValueError("a grid start:stop:step takes numbers")
    if not all(math.isfinite(x) for x in numbers):
        raise ValueError("a grid's start, stop and step are finite numbers")
    start, stop, step = (Fraction(x.strip()) for x in bounds)
    if not step > 0 or stop < start:
        raise ValueError("start:stop:step needs step > 0 and stop >= start")
    n = math.floor((stop - start) / step) + 1
    if n > MAX_IMPACTS:
        raise ValueError(f"{n} values, more than the {MAX_IMPACTS} impacts a sweep runs (it holds them all in memory)")
    return grid(start, step, n, entry["kind"])


def grid(start, step, n, kind):
    """start + i step for i < n, computed exactly (start and step are the
    decimal numbers typed) and then rounded to the nearest double: the
    values asked for, where adding doubles would drift (0.005 + 6 * 0.005
    is 0.034999999999999996 in doubles). Integer parameters stay integers.
    Refused when the step is below what doubles resolve there."""
    if kind != "real":
        return [int(start + i * step) for i in range(n)]
    scale = math.lcm(start.denominator, step.denominator)
    first, stride = start.numerator * (scale // start.denominator), step.numerator * (scale // step.denominator)
    out = [(first + i * stride) / scale for i in range(n)]  # integer division rounds correctly
    if len(set(out)) < n:
        raise ValueError("the step is below what doubles resolve at these values: the grid would repeat them")
    return out


def scatter(entry, text):
    """The coefficient of variation in '0.05' or '5%'."""
    name = entry["name"]
    if entry["kind"] != "real":
        raise ValueError(f"only real parameters scatter, {name} is {entry['kind']}")
    try:
        cv = float(text[:-1]) / 100 if text.endswith("%") else float(text)
    except ValueError:
        raise ValueError("a fraction (0.05) or a percentage (5%)") from None
    if not 0 <= cv < math.inf:
        raise ValueError("the scatter is a coefficient of variation (standard deviation / mean), finite and never "
                         "negative")
    return cv


def named(table, option, texts):
    """[(name, spec, text)] of the option's NAME=SPEC texts, each name as the
    library spells it."""
    out = []
    for text in texts:
        name, sep, spec = text.partition("=")
        if not sep or not spec.strip():
            raise ValueError(f"{option} {text}: NAME=VALUE expected")
        try:
            entry = parameter(table, name.strip().lstrip("-"))
        except ValueError as e:
            raise ValueError(f"{option} {text}: {e}") from None
        out.append((entry["name"], spec.strip(), text))
    return out


def converted(table, option, given, convert):
    """[(name, convert(entry, spec))] of named() texts; a refusal names the
    option and the text."""
    out = []
    for name, spec, text in given:
        try:
            out.append((name, convert(table[name], spec)))
        except ValueError as e:
            raise ValueError(f"{option} {text}: {e}") from None
    return out


def nominal(entry, fixed):
    """The mean a scattered parameter is drawn around: its --set value, else
    the library's default."""
    name = entry["name"]
    if name not in fixed and entry["default"] is None:
        raise ValueError(f"--scatter {name}: it has no default; give its nominal value with --set {name}=VALUE")
    mean = fixed[name] if name in fixed else entry["default"]
    if not mean > 0:
        raise ValueError(f"--scatter {name}: needs a positive nominal value, not {mean:g} (--set {name}=VALUE); a "
                         "relative scatter of zero or of a negative value means nothing")
    return mean


def log_normal(rng, mean, cv, n):
    """n draws with that mean and coefficient of variation: the exponential
    of a normal of variance ln(1 + cv^2) and mean ln(mean) - variance / 2."""
    variance = math.log1p(cv * cv)
    return rng.lognormal(math.log(mean) - variance / 2, math.sqrt(variance), n)


def refuse_conflicts(args, vary, fixed, scattered):
    """Refuses options that contradict each other or would be ignored (the
    named() texts of --vary, --set and --scatter): each name given once,
    height and v not both, a Monte Carlo campaign's options only with it
    and never beside a grid, --workers only for the local cluster."""
    for option, given in (("--vary", vary), ("--set", fixed), ("--scatter", scattered)):
        seen = {}
        for name, _, text in given:
            if name in seen:
                raise ValueError(f"{option} {seen[name]} and {option} {text}: {name} is given twice")
            seen[name] = text
    set_texts = {name: text for name, _, text in fixed}
    for name, _, text in vary:
        if name in set_texts:
            raise ValueError(f"--set {set_texts[name]} and --vary {text}: a parameter is either held (--set) or "
                             "varied (--vary), not both")
    speeds = [(option, name, text) for option, given in (("--vary", vary), ("--set", fixed), ("--scatter", scattered))
              for name, _, text in given if name in ("height", "v")]
    if len({name for _, name, _ in speeds}) > 1:
        raise ValueError(f"{' and '.join(f'{o} {t}' for o, _, t in speeds)}: height sets v (v = sqrt(2 g h)); give "
                         "one of them")
    if args.monte_carlo is None:
        if scattered:
            raise ValueError(f"--scatter {scattered[0][2]} without --monte-carlo N: only a Monte Carlo campaign "
                             "draws values (a grid takes --vary)")
        if args.seed is not None:
            raise ValueError(f"--seed {args.seed} without --monte-carlo N: a grid draws nothing at random")
        if not vary and speeds:
            raise ValueError(f"{speeds[0][0]} {speeds[0][2]} without --vary: the default sweep varies height; "
                             "give --vary NAME=VALUES for what to sweep")
    else:
        if not 1 <= args.monte_carlo <= MAX_IMPACTS:
            raise ValueError(f"--monte-carlo {args.monte_carlo}: the number of impacts must lie in [1, "
                             f"{MAX_IMPACTS}] (a sweep holds them all in memory)")
        if not scattered:
            raise ValueError(f"--monte-carlo {args.monte_carlo} needs at least one --scatter NAME=S")
        if vary:
            raise ValueError(f"--vary {vary[0][2]} with --monte-carlo: a Monte Carlo campaign draws its cases "
                             "(--scatter) instead of a grid; hold the other parameters with --set")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: a seed is a whole number >= 0")
    if args.workers is not None and args.scheduler:
        raise ValueError(f"--workers {args.workers} with --scheduler: the scheduler's workers run the sweep; "
                         "--workers sizes the local cluster")
    if args.workers is not None and not 1 <= args.workers <= cpus():
        raise ValueError(f"--workers {args.workers}: a local cluster has 1 to {cpus()} worker processes, this "
                         "machine's CPUs (more would only compete for them)")
    if args.batch < 0:
        raise ValueError(f"--batch {args.batch}: impacts per Dask task, >= 1 (or 0, the default)")


def cpus():
    """The CPUs this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def refuse_large_grid(texts, vary):
    """Refuses a grid over the --vary values (texts as given) of more than
    MAX_IMPACTS impacts, before it is built."""
    n = math.prod(len(v) for _, v in vary)
    if n > MAX_IMPACTS:
        raise ValueError(f"{' '.join(f'--vary {text}' for _, _, text in texts)}: a grid of "
                         f"{' x '.join(str(len(v)) for _, v in vary)} = {n} impacts, more than the {MAX_IMPACTS} "
                         "a sweep runs (it holds them all in memory)")


def monte_carlo_cases(args, table):
    rng = np.random.default_rng(1 if args.seed is None else args.seed)
    draws = {name: log_normal(rng, nominal(table[name], args.fixed), cv, args.monte_carlo)
             for name, cv in args.scatter}
    return [{name: float(x[i]) for name, x in draws.items()} for i in range(args.monte_carlo)]


def grid_cases(vary):
    names = [n for n, _ in vary]
    return [dict(zip(names, combo)) for combo in itertools.product(*[v for _, v in vary])]


def unused_values(fixed, vary, first_case):
    """The library's warnings (a value without effect, such as a material
    beside a given k) for the fixed values with each varied value in turn
    (the first of each varied name), or, in a Monte Carlo campaign, with
    its first draw: what holds there holds for all its draws. A value the
    library refuses is left to its case's row."""
    checks = [[first_case]] if not vary else [[{name: v} for v in dict.fromkeys(column)] for name, column in vary]
    found = []
    for cases in checks:
        for case in cases:
            try:
                why = model.warning(**{**fixed, **case})  # a draw replaces its nominal value
            except ValueError:
                continue
            if why:
                found.append(why)
                break
    return list(dict.fromkeys(found))


def code(name, v):
    """A parameter's value as the library takes it (law=hertz -> 2)."""
    return model.WORDS[name].get(v, v) if name in model.WORDS and isinstance(v, str) else v


def run_chunk(fixed, columns):
    """One Dask task: chunk_results() without the library's warnings, of
    which the client has warned once already."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return chunk_results(fixed, columns)


def chunk_results(fixed, columns):
    """The cases whose parameters are the arrays in columns (fixed holds the
    rest) in one library call. Returns the RESULTS as arrays, and {index:
    the library's message} of the cases it refused, whose results are NaN
    or 0 (then the cases run one by one, to tell which)."""
    fixed = {name: code(name, v) for name, v in fixed.items() if name not in columns}  # draws replace the nominal
    arrays = {name: np.array([code(name, v) for v in column]) for name, column in columns.items()}
    n = len(next(iter(arrays.values())))
    try:
        out = model.impacts(**fixed, **arrays)
        return {key: out[key] for key in RESULTS}, {}
    except (ValueError, RuntimeError):
        results = {key: np.zeros(n, dtype=np.int64) if key in COUNTS else np.full(n, np.nan) for key in RESULTS}
        errors = {}
        for i in range(n):
            try:
                out = model.impacts(**fixed, **{name: a[i] for name, a in arrays.items()})
            except (ValueError, RuntimeError) as e:
                errors[i] = str(e)
                continue
            for key in RESULTS:
                results[key][i] = out[key]
        return results, errors


def rows_of(cases, results, errors):
    """A row per case: its inputs, then its results (NAME_result when NAME is
    an input too: the input is asked, impacts at most 3; the result is what
    happened, 1 finished; k the one derived from E_s when k = 0), or the
    library's message under error."""
    columns = {key: results[key].tolist() for key in RESULTS}
    rows = []
    for i, case in enumerate(cases):
        if i in errors:
            rows.append(dict(case, error=errors[i]))
        else:
            rows.append(dict(case, **{f"{key}_result" if key in case else key: columns[key][i] for key in RESULTS}))
    return rows


def chunks(cases, size):
    """The cases in chunks of size, each as {name: [values]}."""
    for start in range(0, len(cases), size):
        part = cases[start:start + size]
        yield start, {name: [case[name] for case in part] for name in part[0]}


def connect(args):
    """(client, cluster): a Dask client of the scheduler at --scheduler
    (cluster None), refused in one line when none answers there within
    CONNECT_TIMEOUT, or of a local cluster of --workers processes."""
    from dask.distributed import Client, LocalCluster
    if not args.scheduler:
        cluster = LocalCluster(n_workers=args.workers or WORKERS, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        return Client(cluster), cluster
    try:
        return Client(args.scheduler, timeout=CONNECT_TIMEOUT), None
    except ValueError as e:  # an address Dask cannot parse
        raise ValueError(f"--scheduler {args.scheduler}: {e}") from None
    except OSError:
        raise ValueError(f"--scheduler {args.scheduler}: no Dask scheduler answered there within "
                         f"{CONNECT_TIMEOUT:g} s") from None


def run(args, client, cluster, cases):
    """All cases on Dask, in chunks of one library call each; returns the
    rows in case order and the wall time of the tasks."""
    from dask.distributed import as_completed
    # Before the clock starts, every worker imports the package and runs the
    # first case once: the library loaded, the path of a chunk and its
    # results taken (the first costs some 20 ms more than the next).
    client.run(importlib.import_module, __name__)
    workers = list(client.scheduler_info()["workers"])
    _, first_case = next(chunks(cases[:1], 1))
    client.gather([client.submit(run_chunk, args.fixed, first_case, workers=[w], pure=False) for w in workers])
    n, w = len(cases), len(workers)
    size = args.batch or max(math.ceil(n / (TASKS_PER_WORKER * w)), min(math.ceil(n / w), CHUNK_MIN))
    parts, errors = {}, {}
    start = time.perf_counter()
    futures = {client.submit(run_chunk, args.fixed, columns, pure=False): first
               for first, columns in chunks(cases, size)}
    for done, future in enumerate(as_completed(futures), 1):
        first = futures[future]
        parts[first], failed = future.result()
        errors.update({first + i: why for i, why in failed.items()})
        progress(done, len(futures), f"{min(done * size, len(cases))} of {len(cases)} impacts")
    wall = time.perf_counter() - start
    client.close()
    if cluster:
        cluster.close()
    results = {key: np.concatenate([parts[first][key] for first in sorted(parts)]) for key in RESULTS}
    return rows_of(cases, results, errors), wall


def write_csv(path, rows):
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with atomic.replacing(path, newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def statistics(rows):
    """Mean, sample standard deviation (none of one impact) and the 5, 50 and
    95 % percentiles (numpy's linear interpolation) of every numeric column,
    over the impacts that succeeded and where the figure exists (an impact
    that did not end by t_end has no eps)."""
    good = [r for r in rows if "error" not in r]
    out = {}
    for key in dict.fromkeys(k for r in good for k in r):
        column = [r.get(key) for r in good]
        if all(is_number(v) for v in column):
            x = np.array(column, dtype=float)
            x = x[np.isfinite(x)]
            if not len(x):
                continue
            p5, p50, p95 = np.percentile(x, (5, 50, 95))
            out[key] = dict(mean=float(x.mean()), std=float(x.std(ddof=1)) if len(x) > 1 else None,
                            p5=float(p5), p50=float(p50), p95=float(p95))
    return out


def print_statistics(stats):
    print(f"{'':<12}" + "".join(f"{h:>14}" for h in ("mean", "std", "5 %", "50 %", "95 %")))
    for key, s in stats.items():
        print(f"{key:<12}" + "".join(f"{'-' if v is None else format(v, '.6g'):>14}" for v in s.values()))


def shown(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


def plot(path, rows, names, title):
    """Each plotted result against the first varied name, a line for each
    combination of the others."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    good = [r for r in rows if "error" not in r]
    x_name, others = names[0], names[1:]
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    groups = sorted({tuple(r[k] for k in others) for r in good}) or [()]
    for ax, (key, scale, what, unit) in zip(axes.flat, PLOTTED):
        for g in groups:
            sel = sorted((r for r in good if tuple(r[k] for k in others) == g), key=lambda r: r[x_name])
            legend = ", ".join(f"{k} = {shown(v)}" for k, v in zip(others, g)) or None
            ax.plot([r[x_name] * 1e3 if x_name == "height" else r[x_name] for r in sel],
                    [r[key] * scale for r in sel], marker=".", label=legend)
        ax.set(xlabel="drop height [mm]" if x_name == "height" else x_name, ylabel=f"{what} [{unit}]")
        ax.grid(alpha=0.3)
        if len(groups) > 1:
            ax.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=100, metadata={"Software": None})


def histograms(path, rows, stats, title):
    """A histogram of each plotted result, its mean and 5/50/95 % percentiles
    marked; sqrt(N) bins (5 to 50): enough to show the shape, few enough
    that each bin holds several impacts."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    good = [r for r in rows if "error" not in r]
    bins = int(np.clip(round(math.sqrt(len(good))), 5, 50))
    fig, axes = plt.subplots(1, 4, figsize=(17, 4.4))
    for ax, (key, scale, what, unit) in zip(axes, PLOTTED):
        ax.hist([r[key] * scale for r in good if math.isfinite(r[key])], bins=bins, color="tab:blue", alpha=0.7)
        s = {k: v * scale for k, v in stats[key].items() if v is not None}
        u = "" if unit == "1" else f" {unit}"
        spread = f" ± {s['std']:.3g}{u} (std)" if "std" in s else u
        ax.axvline(s["mean"], color="k", label=f"mean {s['mean']:.4g}{spread}")
        ax.axvline(s["p50"], color="tab:red", ls="--", label=f"median {s['p50']:.4g}{u}")
        ax.axvline(s["p5"], color="tab:red", ls=":", label=f"5 / 95 %: {s['p5']:.4g} / {s['p95']:.4g}{u}")
        ax.axvline(s["p95"], color="tab:red", ls=":")
        ax.set(xlabel=f"{what} [{unit}]", ylabel="impacts")
        ax.set_ylim(top=1.4 * ax.get_ylim()[1])  # room for the legend above the bars
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle(title)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=100, metadata={"Software": None})


def title_of(args, rows):
    varied = {n for n, _ in args.vary} | {n for n, _ in args.scatter}
    parts = [f"{len(rows)} impacts"] + [f"{k} = {shown(v)}" for k, v in args.fixed.items() if k not in varied]
    parts += [f"{n} log-normal, CV {100 * cv:g} %" for n, cv in args.scatter]
    return ", ".join(parts)


def writable_folder(path):
    """Refuses --out where the results could not be written: a path that is
    no folder, a folder that cannot be created or written, or a result's
    name taken by a folder. Nothing is created before the sweep has run."""
    if path.exists() and not path.is_dir():
        raise ValueError(f"--out {path}: not a folder (it receives {', '.join(OUTPUTS)})")
    existing = next(p for p in (path, *path.parents) if p.exists())
    if not existing.is_dir():
        raise ValueError(f"--out {path}: {existing} is not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"--out {path}: {existing} is not writable")
    for name in OUTPUTS:
        if (path / name).is_dir():
            raise ValueError(f"--out {path}: {path / name} is a folder")


def arguments(argv, prog):
    parser = argparse.ArgumentParser(prog=prog, description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vary", action="append", default=[], metavar="NAME=VALUES",
                        help=f"NAME=a:b:step or NAME=v1,v2,... (repeat for a grid; default height={DEFAULT_HEIGHTS}); "
                             "a material only with --set k=0")
    parser.add_argument("--set", dest="fixed", action="append", default=[], metavar="NAME=VALUE",
                        help=f"NAME=VALUE, a parameter held fixed (e.g. c=6080, law=hertz; default law: "
                             f"{default_law()}, the library's)")
    parser.add_argument("--monte-carlo", type=int, metavar="N",
                        help=f"N random impacts instead of a grid (1 to {MAX_IMPACTS})")
    parser.add_argument("--scatter", action="append", default=[], metavar="NAME=S",
                        help="NAME=S: NAME log-normal in --monte-carlo, coefficient of variation S as a fraction "
                             "(0.05) or a percentage (5%%) (repeat)")
    parser.add_argument("--seed", type=int, help="--monte-carlo: the random generator's seed (default 1)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    parser.add_argument("--workers", type=int,
                        help=f"local cluster: worker processes (default {WORKERS}, at most the CPUs)")
    parser.add_argument("--batch", type=int, default=0,
                        help=f"impacts per Dask task, one library call (default: {TASKS_PER_WORKER} tasks a worker, "
                             f"or one while that leaves fewer than {CHUNK_MIN} impacts in a task)")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("sweep"),
                        help="folder for sweep.csv, sweep.png, sweep.json (default ./sweep)")
    return parser, parser.parse_args(argv)


def prepared(args):
    """The cases of the sweep the options ask for, every option checked
    (args.vary, args.fixed and args.scatter turned into the values), and
    the warnings of values without effect; ValueError for a bad option."""
    table = parameter_table()
    given = {option: named(table, option, texts) for option, texts in
             (("--vary", args.vary), ("--set", args.fixed), ("--scatter", args.scatter))}
    refuse_conflicts(args, given["--vary"], given["--set"], given["--scatter"])
    if not given["--vary"] and args.monte_carlo is None:
        given["--vary"] = named(table, "--vary", [f"height={DEFAULT_HEIGHTS}"])
    args.vary = converted(table, "--vary", given["--vary"], values)
    args.fixed = {"law": default_law(), **dict(converted(table, "--set", given["--set"], value))}
    args.scatter = converted(table, "--scatter", given["--scatter"], scatter)
    if args.monte_carlo is None:
        refuse_large_grid(given["--vary"], args.vary)
    writable_folder(args.out)
    cases = monte_carlo_cases(args, table) if args.monte_carlo else grid_cases(args.vary)
    return cases, unused_values(args.fixed, args.vary, cases[0])


def main(argv=None, prog=None):
    parser, args = arguments(argv, prog)
    try:
        cases, unused = prepared(args)
    except ValueError as e:
        parser.error(str(e))
    for why in unused:
        print(f"{parser.prog}: warning: {why}", file=sys.stderr)
    try:
        client, cluster = connect(args)
    except ValueError as e:
        parser.error(str(e))
    rows, wall = run(args, client, cluster, cases)
    monte_carlo = args.monte_carlo is not None
    failed = [r for r in rows if "error" in r]
    summary = dict(impacts=len(rows), failed=len(failed), wall_seconds=wall, impacts_per_second=len(rows) / wall,
                   workers=None if args.scheduler else args.workers or WORKERS)
    stats = statistics(rows) if monte_carlo else {}
    try:
        args.out.mkdir(parents=True, exist_ok=True)
        write_csv(args.out / "sweep.csv", rows)
        atomic.write_text(args.out / "sweep.json",
                          json.dumps(dict(summary, statistics=stats) if stats else summary) + "\n")
        if monte_carlo and len(failed) < len(rows):
            print_statistics(stats)
            histograms(args.out / "sweep.png", rows, stats, title_of(args, rows))
        elif not monte_carlo:
            plot(args.out / "sweep.png", rows, [n for n, _ in args.vary], title_of(args, rows))
    except OSError as e:
        print(f"{parser.prog}: --out {args.out}: cannot write the results: {e.strerror or e}", file=sys.stderr)
        return 2
    print(json.dumps(summary))
    for r in failed[:5]:
        print(f"failed: {r}", file=sys.stderr)
    return 1 if failed else 0
