"""The sweep's command line: its options, each checked, and the plan they
give (cases.Grid or cases.MonteCarlo, the fixed parameters, the
partitions' columns); everything refused here is refused before a cluster
starts or anything is written."""

import argparse
import importlib
import math
import os
import pathlib
import shutil
from fractions import Fraction

import numpy as np
import pyarrow as pa

from .. import model
from . import cases, tasks

DEFAULT_HEIGHTS = "0.005:0.1:0.005"
# How long --scheduler waits for its scheduler to answer [s]: a scheduler
# that is up answers at once, and a wrong address should not cost longer.
CONNECT_TIMEOUT = 5
HEIGHT = dict(name="height", kind="real", unit="m", default=None, help="drop height: v = sqrt(2 g h)")
# What --out receives: the partitions' folder, and the files.
PARTITIONS = "sweep.parquet"
FILES = ("sweep.csv", "sweep.png", "sweep.json")
# The output's size a value, to refuse a campaign the disk cannot hold
# before it starts: a double in Parquet (random doubles do not compress),
# and a generous bound of one printed in the CSV (17 digits, sign, exponent).
PARQUET_BYTES, CSV_BYTES = 8, 25
# The values of a grid axis compared for repeats when its step does not
# exceed the doubles' spacing (repeats()).
CHECKED = 1_000_000


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
    """The axis of 'start:stop:step' (real and integer parameters; steps()),
    or of 'v1,v2,...' (cases.Values: as typed, and as the library takes
    them)."""
    if ":" not in spec:
        typed = [value(entry, v) for v in spec.split(",")]
        shown = [str(v) for v in typed] if any(isinstance(v, str) for v in typed) else typed
        return cases.Values(tuple(shown), tuple(cases.code(entry["name"], v) for v in typed))
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
    return steps(start, step, math.floor((stop - start) / step) + 1, entry["kind"])


def steps(start, step, n, kind):
    """start + i step for i < n (start and step the decimal numbers typed;
    cases.Steps), never built here. Refused when the step is below what
    doubles resolve there."""
    scale = math.lcm(start.denominator, step.denominator)
    axis = cases.Steps(start.numerator * (scale // start.denominator), step.numerator * (scale // step.denominator),
                       scale, n, kind != "real")
    if kind == "real" and repeats(axis, start, step):
        raise ValueError("the step is below what doubles resolve at these values: the grid would repeat them")
    return axis


def repeats(axis, start, step):
    """Whether rounding to doubles makes two values of the axis one. Never
    when the step exceeds the doubles' spacing at its largest value (two
    values rounded to one double d lie within half a spacing of d, which is
    no larger there); else its values are compared, up to CHECKED of them,
    and a longer axis is taken to repeat."""
    largest = max(abs(start), abs(start + (axis.n - 1) * step))
    if step > Fraction(math.ulp(float(largest))):
        return False
    if axis.n > CHECKED:
        return True
    x = axis.at(np.arange(axis.n))
    return bool(np.any(x[1:] == x[:-1]))  # increasing: a repeat is a neighbour


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
        if args.monte_carlo < 1:
            raise ValueError(f"--monte-carlo {args.monte_carlo}: the number of impacts must be >= 1")
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
    if args.processes and args.scheduler:
        raise ValueError("--processes with --scheduler: the scheduler's workers run the sweep; --processes makes "
                         "the local cluster's workers processes")
    if args.workers is not None and not 1 <= args.workers <= cpus():
        raise ValueError(f"--workers {args.workers}: a local cluster has 1 to {cpus()} workers, this machine's "
                         "CPUs (more would only compete for them)")
    if args.batch is not None and args.batch < 1:
        raise ValueError(f"--batch {args.batch}: impacts per Dask task, >= 1")


def cpus():
    """The CPUs this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1




def size_text(n):
    """A number of bytes for a person: 1.2 GB."""
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1000


def refuse_oversized(what, n, columns, csv, out):
    """Refuses a campaign of n impacts whose output (columns values an
    impact) would not fit in the space free at --out, before it starts."""
    existing = next(p for p in (out, *out.parents) if p.exists())
    need = n * columns * (PARQUET_BYTES + (CSV_BYTES if csv else 0))
    free = shutil.disk_usage(existing).free
    if need > free:
        raise ValueError(f"{what} {n} impacts would write about {size_text(need)} to --out, more than the "
                         f"{size_text(free)} free there ({PARQUET_BYTES} bytes a value in Parquet"
                         f"{f', {CSV_BYTES} in the CSV' if csv else ''}; {columns} values an impact)")


def unused_values(fixed, plan_cases):
    """The library's warnings (a value without effect, such as a material
    beside a given k) for the fixed values with the values of each varied
    name in turn (those listed, or a grid's first and last), or, in a Monte
    Carlo campaign, with its first draw: what holds there holds for all its
    draws. A value the library refuses is left to its case."""
    if isinstance(plan_cases, cases.MonteCarlo):
        first, _ = plan_cases.inputs(0, 1)
        checks = [[{name: float(x[0]) for name, x in first.items()}]]
    else:
        checks = [[{name: v} for v in dict.fromkeys(axis.codes if isinstance(axis, cases.Values)
                                                    else axis.at(np.array([0, axis.n - 1])).tolist())]
                  for name, axis in plan_cases.axes]
    found = []
    for trials in checks:
        for case in trials:
            try:
                why = model.warning(**{**fixed, **case})  # a draw replaces its nominal value
            except ValueError:
                continue
            if why:
                found.append(why)
                break
    return list(dict.fromkeys(found))


def writable_folder(path):
    """Refuses --out where the results could not be written: a path that is
    no folder, a folder that cannot be created or written, or a result's
    name taken by something else. Nothing is created before the sweep runs."""
    if path.exists() and not path.is_dir():
        raise ValueError(f"--out {path}: not a folder (it receives {PARTITIONS}/, {', '.join(FILES)})")
    existing = next(p for p in (path, *path.parents) if p.exists())
    if not existing.is_dir():
        raise ValueError(f"--out {path}: {existing} is not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"--out {path}: {existing} is not writable")
    for name in FILES:
        if (path / name).is_dir():
            raise ValueError(f"--out {path}: {path / name} is a folder")
    if (path / PARTITIONS).exists() and not (path / PARTITIONS).is_dir():
        raise ValueError(f"--out {path}: {path / PARTITIONS} is not a folder")


def arguments(argv, prog):
    parser = argparse.ArgumentParser(prog=prog, description=importlib.import_module(__package__).__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vary", action="append", default=[], metavar="NAME=VALUES",
                        help=f"NAME=a:b:step or NAME=v1,v2,... (repeat for a grid; default height={DEFAULT_HEIGHTS}); "
                             "a material only with --set k=0")
    parser.add_argument("--set", dest="fixed", action="append", default=[], metavar="NAME=VALUE",
                        help=f"NAME=VALUE, a parameter held fixed (e.g. c=6080, law=hertz; default law: "
                             f"{default_law()}, the library's)")
    parser.add_argument("--monte-carlo", type=int, metavar="N", help="N random impacts instead of a grid (N >= 1)")
    parser.add_argument("--scatter", action="append", default=[], metavar="NAME=S",
                        help="NAME=S: NAME log-normal in --monte-carlo, coefficient of variation S as a fraction "
                             "(0.05) or a percentage (5%%) (repeat)")
    parser.add_argument("--seed", type=int, help="--monte-carlo: the random generator's seed (default 1)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    parser.add_argument("--workers", type=int,
                        help="local cluster: its workers, threads of the process that runs the sweep (default: the "
                             "CPUs, at most as many)")
    parser.add_argument("--processes", action="store_true",
                        help="local cluster: --workers processes of one thread instead of threads")
    parser.add_argument("--batch", type=int,
                        help=f"impacts per Dask task, >= 1 (default: about {cases.TASKS} tasks, "
                             f"{cases.TASK_MIN} to {cases.TASK_MAX} impacts each)")
    parser.add_argument("--csv", action="store_true", help="also write every impact to sweep.csv")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("sweep"),
                        help=f"folder for {PARTITIONS}/, {', '.join(FILES)} (default ./sweep)")
    return parser, parser.parse_args(argv)


def grid_plan(args):
    """The grid's cases and their columns, refused when its output would not
    fit on the disk."""
    grid = cases.Grid(tuple(args.vary))
    inputs = [(name, pa.string() if isinstance(axis, cases.Values) and isinstance(axis.shown[0], str)
               else pa.int64() if isinstance(axis.at(np.array([0]))[0], np.integer) else pa.float64())
              for name, axis in args.vary]
    return grid, inputs


def monte_carlo_plan(args, table):
    streams = list(table)
    scattered = tuple((name, streams.index(name), nominal(table[name], args.fixed), cv) for name, cv in args.scatter)
    return cases.MonteCarlo(args.monte_carlo, 1 if args.seed is None else args.seed, scattered), \
        [(name, pa.float64()) for name, cv in args.scatter]


def what_is_run(given, plan_cases):
    """The options that set the campaign's size, for a refusal."""
    if isinstance(plan_cases, cases.MonteCarlo):
        return f"--monte-carlo {plan_cases.n}:"
    texts = " ".join(f"--vary {text}" for _, _, text in given)
    if len(plan_cases.axes) == 1:
        return f"{texts}:"
    return f"{texts}: a grid of {' x '.join(str(len(axis)) for _, axis in plan_cases.axes)} ="


def prepared(args):
    """The plan of the sweep the options ask for, every option checked
    (args.vary, args.fixed and args.scatter turned into axes and values),
    and the warnings of values without effect; ValueError for a bad option."""
    table = parameter_table()
    given = {option: named(table, option, texts) for option, texts in
             (("--vary", args.vary), ("--set", args.fixed), ("--scatter", args.scatter))}
    refuse_conflicts(args, given["--vary"], given["--set"], given["--scatter"])
    if not given["--vary"] and args.monte_carlo is None:
        given["--vary"] = named(table, "--vary", [f"height={DEFAULT_HEIGHTS}"])
    args.vary = converted(table, "--vary", given["--vary"], values)
    args.fixed = {"law": default_law(), **dict(converted(table, "--set", given["--set"], value))}
    args.scatter = converted(table, "--scatter", given["--scatter"], scatter)
    writable_folder(args.out)
    plan_cases, inputs = monte_carlo_plan(args, table) if args.monte_carlo else grid_plan(args)
    schema = tasks.schema(inputs)
    refuse_oversized(what_is_run(given["--vary"], plan_cases), plan_cases.n, len(schema) - 1, args.csv, args.out)
    fixed = {name: cases.code(name, v) for name, v in args.fixed.items()}
    size = cases.task_size(plan_cases.n, args.batch)
    plan = tasks.Plan(plan_cases, fixed, schema, max(6, len(str((plan_cases.n - 1) // size))),
                      isinstance(plan_cases, cases.MonteCarlo))
    return plan, size, unused_values(args.fixed, plan_cases)
