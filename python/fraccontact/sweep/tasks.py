"""What a Dask task of a sweep does, on its worker: computes its cases from
the plan and its index range, runs them in calls of the library, writes them,
inputs beside results, as a Parquet partition (and a CSV part when asked),
and returns a small summary: counts, the first refusals, and for a Monte
Carlo campaign the statistics' summary of every numeric column (stats.py).
Nothing of the cases goes back to the client."""

import ctypes
import time
import warnings
from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .. import _lib, atomic, model
from . import stats

# The results of a run, as fraccontact.impacts returns them: the first
# impact's figures (NaN where none ended), then the run's counts and k.
RESULTS = model.IMPACT_FIGURES + ("impacts", "steps", "k")
COUNTS = ("impacts", "steps")
ERRORS_KEPT = 5  # refusals a summary carries, to be printed
# Cases a library call runs: at most CHUNK, so that the batch's parameters
# and outcomes stay a few megabytes however large the task, and about SLICE
# seconds of them (a task of expensive impacts stops within that much of
# a stop), starting from FIRST.
CHUNK = 1 << 14
SLICE = 0.1
FIRST = 64
# STATE["stop"] is set by the client of a local cluster of threads when it
# stops (Ctrl-C): a thread cannot be killed, so its task stops at its next
# library call. A plain dict: the task's functions stay picklable by value.
STATE = {"stop": False}
ADDED = ("impacts", "failed", "seconds", "cpu_seconds", "library_cpu_seconds", "tasks")  # a summary's sums


@dataclass(frozen=True)
class Plan:
    """What every task is given: the cases (cases.Grid or
    cases.MonteCarlo), the fixed parameters as the library takes them, the
    partitions' schema and the names of their files."""
    cases: object
    fixed: dict
    schema: pa.Schema
    width: int  # digits of a partition's number: the files sort in case order
    statistics: bool  # whether the tasks summarise their columns for the statistics (Monte Carlo)

    def path(self, folder, index, suffix):
        return folder / f"part-{index:0{self.width}d}.{suffix}"


def schema(inputs):
    """The partitions' columns: the inputs ((name, arrow type), ...), the
    results (NAME_result when NAME is an input too: the input is asked,
    impacts at most 3; the result is what happened, 1 finished), and error,
    the library's message for a case it refused (null for the others)."""
    names = {name for name, _ in inputs}
    results = [(f"{key}_result" if key in names else key, pa.int64() if key in COUNTS else pa.float64())
               for key in RESULTS]
    return pa.schema(list(inputs) + results + [("error", pa.string())])


def run(plan, index, start, stop, folder, csv):
    """Task `index`: cases start to stop - 1, written under folder; returns
    its summary."""
    began, cpu = time.perf_counter(), time.thread_time()
    shown, given = plan.cases.inputs(start, stop)
    results, errors, library_cpu = library_results(plan.fixed, given, stop - start)
    table = pa.Table.from_arrays([*shown.values(), *results.values(), messages(errors, stop - start)],
                                 schema=plan.schema)
    write(table, plan, folder, index, csv)
    failed = sorted(errors)
    columns = dict(zip(plan.schema.names, [*shown.values(), *results.values()]))
    summaries = stats.reduced(columns, failed, index) if plan.statistics else {}
    return dict(impacts=stop - start, failed=len(failed), seconds=time.perf_counter() - began,
                cpu_seconds=time.thread_time() - cpu, library_cpu_seconds=library_cpu, tasks=1,
                errors=[(start + i, {name: column[i].item() for name, column in shown.items()}, errors[i])
                        for i in failed[:ERRORS_KEPT]], statistics=summaries)


def merged(*summaries):
    """The summary of several tasks: counts and times added, the first
    refusals kept, the statistics' summaries merged."""
    statistics = stats.merged(*(s["statistics"] for s in summaries))
    errors = sorted((e for s in summaries for e in s["errors"]), key=lambda e: e[0])[:ERRORS_KEPT]
    return dict({key: sum(s[key] for s in summaries) for key in ADDED}, errors=errors, statistics=statistics)


PARAMS, OUTCOME = np.dtype(_lib.Params), np.dtype(_lib.Outcome)


def record(fixed, given):
    """The parameters every case of a batch shares: the library's defaults
    and the fixed values (a draw replaces its nominal value)."""
    p = _lib.Params()
    _lib.LIB.fc_params_default(ctypes.byref(p))
    shared = np.frombuffer(bytes(p), dtype=PARAMS).copy()
    for name, x in fixed.items():
        if name not in given:
            shared["v" if name == "height" else name] = velocities(x) if name == "height" else x
    return shared


def velocities(height):
    """v of each drop height (fraccontact.drop_velocity, once a distinct
    height); NaN for a height the library cannot drop from, so that its
    case is refused."""
    heights, where = np.unique(np.atleast_1d(np.asarray(height, dtype=np.float64)), return_inverse=True)
    v = np.array([model.drop_velocity(h) if np.isfinite(h) and h >= 0 else np.nan for h in heights])
    return v[where.reshape(np.shape(height))]


def library_results(fixed, given, n):
    """The RESULTS of the cases whose parameters are the arrays in given
    (fixed holds the rest; a draw replaces its nominal value), in calls of
    the library's fc_run_batch (chunk() cases each); {index: the library's
    message} of the cases it refused (their results NaN, or 0 for the
    counts); the CPU seconds of the library calls. The library is called directly, without
    the Python objects fraccontact.impacts makes for each case (the stop's
    word, its checks), which would cost time beside every impact; a
    refused case's message is still fraccontact.impacts' own, from that
    case alone."""
    results = {name: np.empty(n) for name in model.IMPACT_FIGURES}
    results.update(impacts=np.empty(n, dtype=np.int64), steps=np.empty(n, dtype=np.int64), k=np.empty(n))
    status = np.empty(n, dtype=OUTCOME["status"])
    # One batch and one outcome buffer for every call: only the given
    # parameters change between calls, and the library writes every outcome.
    batch, out = np.tile(record(fixed, given), min(CHUNK, n)), np.empty(min(CHUNK, n), dtype=OUTCOME)
    figures = out["first"]
    cpu, a, b = 0.0, 0, min(FIRST, n)
    while a < n:
        if STATE["stop"]:
            raise RuntimeError("the sweep stopped")
        m = b - a
        for name, x in given.items():
            batch["v" if name == "height" else name][:m] = velocities(x[a:b]) if name == "height" else x[a:b]
        began = time.thread_time()
        _lib.LIB.fc_run_batch(m, batch.ctypes.data, out.ctypes.data)
        spent = time.thread_time() - began
        cpu += spent
        for name in model.IMPACT_FIGURES:
            results[name][a:b] = figures[name][:m]
        for name in ("impacts", "steps", "k"):
            results[name][a:b] = out[name][:m]
        status[a:b] = out["status"][:m]
        a, b = b, min(b + chunk(m, spent), n)
    unended = results["impacts"] <= 0  # no impact ended: its figures do not exist
    for name in model.IMPACT_FIGURES:
        results[name][unended] = np.nan
    refused = np.flatnonzero(status != _lib.FC_OK)
    results["k"][refused] = np.nan
    errors = {int(i): refusal({**fixed, **{name: x[i] for name, x in given.items()}}, status[i])
              for i in refused}
    return results, errors, cpu


def chunk(cases, seconds):
    """The cases of the next library call: about SLICE seconds at the pace
    of the last, CHUNK at most."""
    return min(CHUNK, max(1, int(SLICE * cases / seconds))) if seconds > 0 else CHUNK


def messages(errors, n):
    """The error column: each refusal's message, null for the cases that ran."""
    if not errors:
        return pa.nulls(n, pa.string())
    column = np.full(n, None, dtype=object)
    column[list(errors)] = list(errors.values())
    return pa.array(column, pa.string())


def refusal(case, status):
    """The library's message for a case it refused, as fraccontact.impacts
    gives it."""
    with warnings.catch_warnings():  # the client has warned once already
        warnings.simplefilter("ignore")
        try:
            model.impacts(**case)
        except (ValueError, RuntimeError) as e:
            return str(e)
    return f"the run failed (status {status})"


def write(table, plan, folder, index, csv):
    """The partition, each file whole or not at all (a task run again after
    its worker died writes the same bytes over it)."""
    with atomic.replacing(plan.path(folder, index, "parquet"), "wb") as f:
        # Random doubles neither compress nor fit a dictionary: trying costs most of a write.
        pq.write_table(table, f, use_dictionary=False, compression="none")
    if csv:
        import pyarrow.csv  # only asked for with --csv
        with atomic.replacing(plan.path(folder, index, "csv"), "wb") as f:
            pyarrow.csv.write_csv(table, f)
