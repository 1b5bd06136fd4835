"""Parameter sweeps on Dask: the drop test over a grid of heights (the
paper's 5 to 100 mm in 5 mm steps by default), masses, materials or any
solver option, or a Monte Carlo campaign over their scatter; each impact is
one run of fraccontact-solve. Prints a progress bar, writes a CSV of every
impact and a plot of F_max, eps, contact time and permanent indentation
against the swept variable (histograms for Monte Carlo).

  scripts/sweep                                   # the paper's heights, a local cluster
  scripts/sweep --vary c=2000,6080,20000 --vary height=0.01:0.1:0.01
  scripts/sweep --vary law=g1,hertz --vary t_end=0.05,0.2 --set impacts=3 --set g=9.81
  scripts/sweep --monte-carlo 100000 --scatter k=0.05 --scatter c=10% --scheduler tcp://host:8786

NAME (--vary, --set, --scatter) is any option of fraccontact-solve (see its
--help; the sweep reads them from its --list-options) without the dashes,
with - or _ alike: height, m, c, E-s or E_s, t-end or t_end, law, impacts.
Real and integer options take a grid a:b:step or a list v1,v2; word options
their choices (law=g1,hertz,g1x); flags true or false (reference=true). The
sweep passes --json --quiet itself and writes its own CSV, so json, quiet,
csv and output-interval are refused.

The default law: g1, the solver's own (the G1 history sum, the model the
README describes); --set law=hertz for the closed form.

Monte Carlo: --scatter NAME=S draws NAME log-normally, with mean its nominal
value (--set NAME=VALUE, else the default the solver states in its --help)
and coefficient of variation S (standard deviation / mean), a fraction
(0.05) or a percentage (5%). Log-normal, it stays positive at any S. Only
real options with a positive nominal value scatter: a relative scatter of
zero (g, gap0 at their defaults) or of a negative value means nothing, so
those are refused, as is a negative S.

Writes to --out: sweep.csv (per impact: the inputs varied, then every scalar
number of the solver's JSON but cpu_seconds, a timing that would make a
seeded campaign's CSV differ between runs; NAME_result when NAME is also a
column of the inputs, as impacts or k), sweep.png, and sweep.json (counts
and throughput; for Monte Carlo also the mean, sample standard deviation and
5/50/95 % percentiles of every numeric column over the impacts that
succeeded, which are printed too).

Runs on a local Dask cluster (--workers processes) or on any running Dask
scheduler (--scheduler ADDRESS), whose workers must see the same solver path
(--solver, default build/fraccontact-solve).
"""

import argparse
import csv
import itertools
import json
import math
import os
import pathlib
import re
import subprocess
import sys
import time

import numpy as np

import atomic
from progress import progress

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVER = pathlib.Path(os.environ.get("FRACCONTACT_SOLVE", ROOT / "build" / "fraccontact-solve"))
DEFAULT_LAW = "g1"
DEFAULT_HEIGHTS = "0.005:0.1:0.005"
# Solver options the sweep sets itself, or that only shape the --csv file it
# does not ask for: refused, with the reason.
SWEEP_OWNS = {
    "--json": "the sweep always passes --json --quiet",
    "--quiet": "the sweep always passes --json --quiet",
    "--csv": "the sweep writes its own CSV (sweep.csv, a row per impact), not the solver's time series",
    "--output-interval": "only spaces the rows of the solver's --csv, and the sweep writes its own CSV",
}
TIMING = "cpu_seconds"
# The plotted results: (key, scale to the unit shown, what it is, unit).
PLOTTED = (("F_peak", 1, "peak force F_max", "N"), ("eps", 1, "restitution coefficient eps", "1"),
           ("t_contact", 1e3, "contact time", "ms"), ("x2_end", 1e6, "permanent indentation", "µm"))
# "(default 3.299e8)" in an option's help: the solver's own statement.
STATED_DEFAULT = re.compile(r"\(default ([-+]?[0-9][0-9.]*(?:[eE][-+]?[0-9]+)?)")


def solver_options(solver):
    """The solver's option table (--list-options), under every accepted
    spelling of a name: without the dashes, and with _ for -."""
    done = subprocess.run([str(solver), "--list-options"], capture_output=True, text=True)
    if done.returncode != 0:
        raise ValueError(f"{solver} --list-options failed ({done.stderr.strip()}): rebuild it (scripts/build)")
    table = {}
    for entry in json.loads(done.stdout):
        name = entry["option"].lstrip("-")
        table[name] = table[name.replace("-", "_")] = entry
    return table


def option(table, name):
    """The table entry of NAME; refused when unknown or the sweep's own."""
    entry = table.get(name)
    if entry is None:
        names = sorted({e["option"][2:] for e in table.values() if e["option"] not in SWEEP_OWNS}, key=str.lower)
        raise ValueError(f"unknown option '{name}': NAME is one of {', '.join(names)} (- or _ alike)")
    if entry["option"] in SWEEP_OWNS:
        raise ValueError(f"'{name}': {SWEEP_OWNS[entry['option']]}")
    return entry


def value(entry, text):
    """TEXT as the option's kind: a number, one of its choices, true/false
    for a flag, or the text itself."""
    name, kind = entry["option"][2:], entry["kind"]
    if kind in ("real", "integer"):
        try:
            return float(text) if kind == "real" else int(text)
        except ValueError:
            raise ValueError(f"{name}={text}: not {'a number' if kind == 'real' else 'a whole number'}") from None
    choices = dict(true=True, false=False) if kind == "flag" else {c: c for c in entry.get("choices", [text])}
    if text not in choices:
        raise ValueError(f"{name}={text}: {name} is one of {', '.join(choices)}")
    return choices[text]


def values(entry, spec):
    """'a:b:step' (inclusive; real and integer options), or 'v1,v2,...'."""
    if ":" not in spec or entry["kind"] not in ("real", "integer"):
        return [value(entry, v) for v in spec.split(",")]
    bounds = spec.split(":")
    if len(bounds) != 3:
        raise ValueError(f"'{spec}': a grid is start:stop:step")
    start, stop, step = (value(entry, x) for x in bounds)
    if not step > 0 or stop < start:
        raise ValueError(f"'{spec}': start:stop:step needs step > 0 and stop >= start")
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    return [round(start + i * step, 12) for i in range(n)]


def scatter(entry, text):
    """The coefficient of variation in '0.05' or '5%'."""
    name = entry["option"][2:]
    if entry["kind"] != "real":
        raise ValueError(f"--scatter {name}: only real options scatter, {name} is {entry['kind']}")
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
    solver spells its option (without the dashes)."""
    out = []
    for text in texts:
        name, sep, spec = text.partition("=")
        if not sep or not spec.strip():
            raise ValueError(f"'{text}': NAME=VALUE expected")
        entry = option(table, name.strip().lstrip("-"))
        out.append((entry["option"][2:], convert(entry, spec.strip())))
    return out


def nominal(entry, fixed):
    """The mean a scattered option is drawn around: its --set value, else
    the default the solver states."""
    name = entry["option"][2:]
    stated = STATED_DEFAULT.search(entry["help"])
    if name not in fixed and not stated:
        raise ValueError(f"--scatter {name}: the solver states no default for it; give its nominal value with "
                         f"--set {name}=VALUE")
    mean = fixed[name] if name in fixed else float(stated.group(1))
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


def command(solver, options):
    """The solver's command line: a flag appears when true, any other option
    with its value."""
    args = [str(solver), "--json", "--quiet"]
    for name, v in options.items():
        if v is True:
            args.append(f"--{name}")
        elif v is not False:
            args += [f"--{name}", str(v)]
    return args


def scalar_results(result, case):
    """What of the solver's JSON fits a CSV cell: numbers and true/false, and
    NaN for a figure of the first impact when none ended (null). Strings
    (stopped, method), lists and objects are skipped, cpu_seconds too (a
    timing). A result named like an input of the case gets the suffix
    _result: the input is asked (impacts: at most 3), the result is what
    happened (impacts: 1 finished; k: the one derived from E_s when k = 0)."""
    return {f"{key}_result" if key in case else key: math.nan if v is None else v for key, v in result.items()
            if (v is None or isinstance(v, (int, float))) and key != TIMING}


def run_batch(solver, fixed, cases):
    """Runs a batch of impacts (one Dask task); returns their results."""
    out = []
    for case in cases:
        done = subprocess.run(command(solver, dict(fixed, **case)), capture_output=True, text=True)
        if done.returncode != 0:
            out.append(dict(case, error=done.stderr.strip()))
        else:
            out.append(dict(case, **scalar_results(json.loads(done.stdout), case)))
    return out


def run(args, cases):
    """All cases on Dask, in batches; returns the results in case order and
    the wall time."""
    from dask.distributed import Client, LocalCluster, as_completed
    if args.scheduler:
        client = Client(args.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    batches = [cases[i:i + args.batch] for i in range(0, len(cases), args.batch)]
    start = time.perf_counter()
    futures = {client.submit(run_batch, str(args.solver), args.fixed, b, pure=False): i for i, b in enumerate(batches)}
    results = [None] * len(batches)
    for done, future in enumerate(as_completed(futures), 1):
        results[futures[future]] = future.result()
        progress(done, len(batches), f"{min(done * args.batch, len(cases))} of {len(cases)} impacts")
    wall = time.perf_counter() - start
    client.close()
    if cluster:
        cluster.close()
    return [r for batch in results for r in batch], wall


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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vary", action="append", default=[], metavar="NAME=VALUES",
                        help=f"NAME=a:b:step or NAME=v1,v2,... (repeat for a grid; default height={DEFAULT_HEIGHTS})")
    parser.add_argument("--set", dest="fixed", action="append", default=[], metavar="NAME=VALUE",
                        help=f"NAME=VALUE, a solver option held fixed (e.g. c=6080, law=hertz; default law: "
                             f"{DEFAULT_LAW}, the solver's)")
    parser.add_argument("--monte-carlo", type=int, default=0, metavar="N", help="N random impacts instead of a grid")
    parser.add_argument("--scatter", action="append", default=[], metavar="NAME=S",
                        help="NAME=S: NAME log-normal in --monte-carlo, coefficient of variation S as a fraction "
                             "(0.05) or a percentage (5%%) (repeat)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    parser.add_argument("--workers", type=int, default=2, help="local cluster: worker processes (default 2)")
    parser.add_argument("--batch", type=int, default=25, help="impacts per Dask task (default 25)")
    parser.add_argument("--solver", type=pathlib.Path, default=SOLVER)
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("sweep"),
                        help="folder for sweep.csv, sweep.png, sweep.json (default ./sweep)")
    args = parser.parse_args(argv)
    if args.monte_carlo and not args.scatter:
        parser.error("--monte-carlo needs at least one --scatter NAME=S")
    if args.workers < 1 or args.batch < 1:
        parser.error("--workers and --batch must be >= 1")
    if not args.solver.exists():
        parser.error(f"{args.solver} does not exist: run scripts/build (scripts/sweep does)")
    if not args.vary and not args.monte_carlo:
        args.vary = [f"height={DEFAULT_HEIGHTS}"]
    try:
        table = solver_options(args.solver)
        args.vary = pairs(table, args.vary, values)
        args.fixed = {"law": DEFAULT_LAW, **dict(pairs(table, args.fixed, value))}
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


if __name__ == "__main__":
    sys.exit(main())
