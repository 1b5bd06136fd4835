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
scheme also their words (law=g1,hertz,g1x).

The default law: g1, the library's own (the G1 history sum, the model the
README describes); --set law=hertz for the closed form.

Monte Carlo: --scatter NAME=S draws NAME log-normally, with mean its nominal
value (--set NAME=VALUE, else the library's default) and coefficient of
variation S (standard deviation / mean), a fraction (0.05) or a percentage
(5%). Log-normal, it stays positive at any S. Only real parameters with a
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
scheduler (--scheduler ADDRESS), whose workers must import fraccontact (pip
install .). The wall time and the impacts per second count the Dask tasks
alone, from the first submitted to the last finished (before, each worker
has imported the package and run the first case once).
"""

import argparse
import csv
import importlib
import itertools
import json
import math
import pathlib
import sys
import time

import numpy as np

from . import atomic, model
from .progress import progress

DEFAULT_HEIGHTS = "0.005:0.1:0.005"
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
            raise ValueError(f"{name}={text}: {name} is one of {', '.join(words)} "
                             f"(or {', '.join(map(str, words.values()))})") from None
        raise ValueError(f"{name}={text}: not {'a number' if kind == 'real' else 'a whole number'}") from None


def values(entry, spec):
    """'a:b:step' (inclusive; real and integer parameters), or 'v1,v2,...'."""
    if ":" not in spec:
        return [value(entry, v) for v in spec.split(",")]
    bounds = spec.split(":")
    if len(bounds) != 3:
        raise ValueError(f"'{spec}': a grid is start:stop:step")
    start, stop, step = (value(entry, x) for x in bounds)
    if isinstance(start, str) or isinstance(stop, str) or isinstance(step, str):
        raise ValueError(f"'{spec}': a grid start:stop:step takes numbers")
    if not step > 0 or stop < start:
        raise ValueError(f"'{spec}': start:stop:step needs step > 0 and stop >= start")
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    return [round(start + i * step, 12) for i in range(n)]


def scatter(entry, text):
    """The coefficient of variation in '0.05' or '5%'."""
    name = entry["name"]
    if entry["kind"] != "real":
        raise ValueError(f"--scatter {name}: only real parameters scatter, {name} is {entry['kind']}")
    try:
        cv = float(text[:-1]) / 100 if text.endswith("%") else float(text)
    except ValueError:
        raise ValueError(f"--scatter {name}={text}: a fraction (0.05) or a percentage (5%)") from None
    if not 0 <= cv < math.inf:
        raise ValueError(f"--scatter {name}={text}: the scatter is a coefficient of variation (standard deviation "
                         "/ mean), finite and never negative")
    return cv


def pairs(table, texts, convert):
    """[(name, convert(entry, value))] of NAME=VALUE texts, each name as the
    library spells it."""
    out = []
    for text in texts:
        name, sep, spec = text.partition("=")
        if not sep or not spec.strip():
            raise ValueError(f"'{text}': NAME=VALUE expected")
        entry = parameter(table, name.strip().lstrip("-"))
        out.append((entry["name"], convert(entry, spec.strip())))
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


def monte_carlo_cases(args, table):
    rng = np.random.default_rng(args.seed)
    draws = {name: log_normal(rng, nominal(table[name], args.fixed), cv, args.monte_carlo)
             for name, cv in args.scatter}
    return [{name: float(x[i]) for name, x in draws.items()} for i in range(args.monte_carlo)]


def grid_cases(vary):
    names = [n for n, _ in vary]
    return [dict(zip(names, combo)) for combo in itertools.product(*[v for _, v in vary])]


def code(name, v):
    """A parameter's value as the library takes it (law=hertz -> 2)."""
    return model.WORDS[name].get(v, v) if name in model.WORDS and isinstance(v, str) else v


def run_chunk(fixed, columns):
    """One Dask task: the cases whose parameters are the arrays in columns
    (fixed holds the rest) in one library call. Returns the RESULTS as
    arrays, and {index: the library's message} of the cases it refused,
    whose results are NaN or 0 (then the cases run one by one, to tell which)."""
    fixed = {name: code(name, v) for name, v in fixed.items() if name not in columns}  # a varied name wins
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


def run(args, cases):
    """All cases on Dask, in chunks of one library call each; returns the
    rows in case order and the wall time of the tasks."""
    from dask.distributed import Client, LocalCluster, as_completed
    if args.scheduler:
        client = Client(args.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
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


def main(argv=None, prog=None):
    parser = argparse.ArgumentParser(prog=prog, description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vary", action="append", default=[], metavar="NAME=VALUES",
                        help=f"NAME=a:b:step or NAME=v1,v2,... (repeat for a grid; default height={DEFAULT_HEIGHTS})")
    parser.add_argument("--set", dest="fixed", action="append", default=[], metavar="NAME=VALUE",
                        help=f"NAME=VALUE, a parameter held fixed (e.g. c=6080, law=hertz; default law: "
                             f"{default_law()}, the library's)")
    parser.add_argument("--monte-carlo", type=int, default=0, metavar="N", help="N random impacts instead of a grid")
    parser.add_argument("--scatter", action="append", default=[], metavar="NAME=S",
                        help="NAME=S: NAME log-normal in --monte-carlo, coefficient of variation S as a fraction "
                             "(0.05) or a percentage (5%%) (repeat)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    parser.add_argument("--workers", type=int, default=2, help="local cluster: worker processes (default 2)")
    parser.add_argument("--batch", type=int, default=0,
                        help=f"impacts per Dask task, one library call (default: {TASKS_PER_WORKER} tasks a worker, "
                             f"or one while that leaves fewer than {CHUNK_MIN} impacts in a task)")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("sweep"),
                        help="folder for sweep.csv, sweep.png, sweep.json (default ./sweep)")
    args = parser.parse_args(argv)
    if args.monte_carlo and not args.scatter:
        parser.error("--monte-carlo needs at least one --scatter NAME=S")
    if args.workers < 1 or args.batch < 0:
        parser.error("--workers must be >= 1 and --batch >= 1 (or 0, the default)")
    if not args.vary and not args.monte_carlo:
        args.vary = [f"height={DEFAULT_HEIGHTS}"]
    try:
        table = parameter_table()
        args.vary = pairs(table, args.vary, values)
        args.fixed = {"law": default_law(), **dict(pairs(table, args.fixed, value))}
        args.scatter = pairs(table, args.scatter, scatter)
        cases = monte_carlo_cases(args, table) if args.monte_carlo else grid_cases(args.vary)
    except ValueError as e:
        parser.error(str(e))
    rows, wall = run(args, cases)
    failed = [r for r in rows if "error" in r]
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "sweep.csv", rows)
    summary = dict(impacts=len(rows), failed=len(failed), wall_seconds=wall, impacts_per_second=len(rows) / wall,
                   workers=None if args.scheduler else args.workers)
    stats = statistics(rows) if args.monte_carlo else {}
    atomic.write_text(args.out / "sweep.json", json.dumps(dict(summary, statistics=stats) if stats else summary) + "\n")
    if args.monte_carlo and len(failed) < len(rows):
        print_statistics(stats)
        histograms(args.out / "sweep.png", rows, stats, title_of(args, rows))
    elif not args.monte_carlo:
        plot(args.out / "sweep.png", rows, [n for n, _ in args.vary], title_of(args, rows))
    print(json.dumps(summary))
    for r in failed[:5]:
        print(f"failed: {r}", file=sys.stderr)
    return 1 if failed else 0
