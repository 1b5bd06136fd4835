"""Parameter sweeps on Dask: the drop test over a grid of heights (the
paper's 5 to 100 mm in 5 mm steps by default), masses, materials or any
solver option, or a Monte Carlo campaign over their scatter; each impact is
one run of fraccontact-solve. Prints a progress bar, writes a CSV of every
impact and a plot of F_max, eps, contact time and permanent indentation
against the swept variable.

  scripts/sweep                                   # the paper's heights, a local cluster
  scripts/sweep --vary c=2000,6080,20000 --vary height=0.01:0.1:0.01
  scripts/sweep --monte-carlo 100000 --scatter k=0.05 --scatter c=0.1 --scheduler tcp://host:8786

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
import subprocess
import sys
import time

import numpy as np

import atomic
from progress import progress

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVER = pathlib.Path(os.environ.get("FRACCONTACT_SOLVE", ROOT / "build" / "fraccontact-solve"))
OPTIONS = ("height", "v0", "m", "k", "c", "R", "E-i", "nu-i", "E-s", "nu-s", "g1-nodes", "dt", "g", "gap0")
RESULTS = ("F_peak", "eps", "t_contact", "x_perm", "E_diss")


def values(spec):
    """'a:b:step' (inclusive), or 'v1,v2,...'."""
    if ":" in spec:
        start, stop, step = (float(x) for x in spec.split(":"))
        if not step > 0 or stop < start:
            raise ValueError(f"'{spec}': start:stop:step needs step > 0 and stop >= start")
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        return [round(start + i * step, 12) for i in range(n)]
    return [float(x) for x in spec.split(",")]


def run_batch(solver, fixed, cases):
    """Runs a batch of impacts (one Dask task); returns their results."""
    out = []
    for case in cases:
        options = dict(fixed, **case)
        args = [str(solver), "--json", "--quiet"]
        for name, value in options.items():
            args += [f"--{name}", str(value)]
        done = subprocess.run(args, capture_output=True, text=True)
        if done.returncode != 0:
            out.append(dict(case, error=done.stderr.strip()))
        else:
            r = json.loads(done.stdout)
            out.append(dict(case, **{key: r[key] for key in RESULTS}, separated=r["separated"]))
    return out


def build_cases(args):
    if args.monte_carlo:
        rng = np.random.default_rng(args.seed)
        base = dict(height=0.020, k=3.299e8, c=6080.0, m=0.7437)
        base.update(args.fixed)
        scatter = dict(args.scatter)
        return [{name: float(base[name] * (1 + scatter[name] * rng.standard_normal())) for name in scatter}
                for _ in range(args.monte_carlo)]
    names = [n for n, _ in args.vary]
    return [dict(zip(names, combo)) for combo in itertools.product(*[v for _, v in args.vary])]


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


def plot(path, rows, x_name, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    good = [r for r in rows if "error" not in r]
    labels = dict(F_peak="peak force F_max [N]", eps="restitution coefficient eps", t_contact="contact time [ms]",
                  x_perm="permanent indentation [um]")
    scale = dict(F_peak=1, eps=1, t_contact=1e3, x_perm=1e6)
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    others = [k for k in (good[0] if good else {}) if k not in RESULTS + ("separated", x_name)]
    groups = sorted({tuple(r[k] for k in others) for r in good}) or [()]
    for ax, key in zip(axes.flat, ("F_peak", "eps", "t_contact", "x_perm")):
        for g in groups:
            sel = sorted((r for r in good if tuple(r[k] for k in others) == g), key=lambda r: r[x_name])
            label = ", ".join(f"{k} = {v:g}" for k, v in zip(others, g)) or None
            ax.plot([r[x_name] * (1e3 if x_name == "height" else 1) for r in sel], [r[key] * scale[key] for r in sel],
                    marker=".", label=label)
        ax.set(xlabel="drop height [mm]" if x_name == "height" else x_name, ylabel=labels[key])
        ax.grid(alpha=0.3)
        if len(groups) > 1:
            ax.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=100, metadata={"Software": None})


def histograms(path, rows, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    good = [r for r in rows if "error" not in r]
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.6))
    for ax, key in zip(axes, ("F_peak", "eps", "t_contact", "x_perm")):
        ax.hist([r[key] for r in good], bins=50)
        ax.set(xlabel=key)
    fig.suptitle(title)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=100, metadata={"Software": None})


def pair(text, convert):
    name, _, value = text.partition("=")
    name = name.strip().lstrip("-")
    if name not in OPTIONS or not value:
        raise argparse.ArgumentTypeError(f"'{text}': NAME=VALUE with NAME one of {', '.join(OPTIONS)}")
    try:
        return name, convert(value)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vary", action="append", type=lambda s: pair(s, values), default=[],
                        help="NAME=a:b:step or NAME=v1,v2,... (repeat for a grid; default height=0.005:0.1:0.005)")
    parser.add_argument("--set", dest="fixed", action="append", type=lambda s: pair(s, float), default=[],
                        help="NAME=VALUE, a solver option held fixed (e.g. c=6080, m=0.7437)")
    parser.add_argument("--monte-carlo", type=int, default=0, help="N random impacts instead of a grid")
    parser.add_argument("--scatter", action="append", type=lambda s: pair(s, float), default=[],
                        help="NAME=REL: relative standard deviation of NAME in --monte-carlo (repeat)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--law", choices=("g1", "hertz", "g1x"), default="hertz")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    parser.add_argument("--workers", type=int, default=2, help="local cluster: worker processes (default 2)")
    parser.add_argument("--batch", type=int, default=25, help="impacts per Dask task (default 25)")
    parser.add_argument("--solver", type=pathlib.Path, default=SOLVER)
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("sweep"),
                        help="folder for sweep.csv, sweep.png, sweep.json (default ./sweep)")
    args = parser.parse_args(argv)
    args.fixed = dict(args.fixed, law=args.law)
    if args.monte_carlo and not args.scatter:
        parser.error("--monte-carlo needs at least one --scatter NAME=REL")
    if not args.vary and not args.monte_carlo:
        args.vary = [("height", values("0.005:0.1:0.005"))]
    if args.workers < 1 or args.batch < 1:
        parser.error("--workers and --batch must be >= 1")
    if not args.solver.exists():
        parser.error(f"{args.solver} does not exist: run scripts/build (scripts/sweep does)")
    cases = build_cases(args)
    rows, wall = run(args, cases)
    failed = [r for r in rows if "error" in r]
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "sweep.csv", rows)
    summary = dict(impacts=len(rows), failed=len(failed), wall_seconds=wall, impacts_per_second=len(rows) / wall,
                   workers=None if args.scheduler else args.workers)
    atomic.write_text(args.out / "sweep.json", json.dumps(summary) + "\n")
    title = ", ".join([f"{len(rows)} impacts", f"{args.law} law"]
                      + [f"{k} = {v:g}" for k, v in args.fixed.items() if k != "law"])
    if args.monte_carlo:
        histograms(args.out / "sweep.png", rows, title)
    else:
        plot(args.out / "sweep.png", rows, args.vary[0][0], title)
    print(json.dumps(summary))
    for r in failed[:5]:
        print(f"failed: {r}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
