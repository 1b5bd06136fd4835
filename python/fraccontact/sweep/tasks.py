"""What a Dask task of a sweep does, on its worker: computes its cases from
the plan and its index range, runs them in one library call, writes them,
inputs beside results, as a Parquet partition (and a CSV part when asked),
and returns a small summary: counts, the first refusals, the moments of
every numeric column. Nothing of the cases goes back to the client."""

import time
import warnings
from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import pyarrow.csv
import pyarrow.parquet as pq

from .. import atomic, model
from . import stats

# The results of a run, as fraccontact.impacts returns them: the first
# impact's figures (NaN where none ended), then the run's counts and k.
RESULTS = model.IMPACT_FIGURES + ("impacts", "steps", "k")
COUNTS = ("impacts", "steps")
ERRORS_KEPT = 5  # refusals a summary carries, to be printed


@dataclass(frozen=True)
class Plan:
    """What every task is given: the cases (cases.Grid or
    cases.MonteCarlo), the fixed parameters as the library takes them, the
    partitions' schema and the names of their files."""
    cases: object
    fixed: dict
    schema: pa.Schema
    width: int  # digits of a partition's number: the files sort in case order

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
    began = time.perf_counter()
    shown, given = plan.cases.inputs(start, stop)
    with warnings.catch_warnings():  # the client has warned once already
        warnings.simplefilter("ignore")
        results, errors = library_results(plan.fixed, given, stop - start)
    table = pa.Table.from_arrays([*shown.values(), *results.values(), pa.array(errors, pa.string())],
                                 schema=plan.schema)
    write(table, plan, folder, index, csv)
    failed = [i for i, why in enumerate(errors) if why is not None]
    return dict(impacts=stop - start, failed=len(failed), seconds=time.perf_counter() - began, tasks=1,
                errors=[(start + i, {name: column[i].item() for name, column in shown.items()}, errors[i])
                        for i in failed[:ERRORS_KEPT]],
                moments=stats.moments(table))


def merged(*summaries):
    """The summary of several tasks: counts and seconds added, the first
    refusals kept, the moments merged."""
    moments = {}
    for s in summaries:
        moments = stats.merged_moments(moments, s["moments"])
    return dict({key: sum(s[key] for s in summaries) for key in ("impacts", "failed", "seconds", "tasks")},
                errors=sorted((e for s in summaries for e in s["errors"]), key=lambda e: e[0])[:ERRORS_KEPT], moments=moments)


def library_results(fixed, given, n):
    """The RESULTS of the cases whose parameters are the arrays in given
    (fixed holds the rest; a draw replaces its nominal value) in one library
    call, and a list of each case's refusal (None where it ran). A batch the
    library refuses runs its cases one by one, to tell which."""
    fixed = {name: v for name, v in fixed.items() if name not in given}
    try:
        out = model.impacts(**fixed, **given)
        return {key: np.asarray(out[key]) for key in RESULTS}, [None] * n
    except (ValueError, RuntimeError):
        pass
    results = {key: np.zeros(n, dtype=np.int64) if key in COUNTS else np.full(n, np.nan) for key in RESULTS}
    errors = [None] * n
    for i in range(n):
        try:
            out = model.impacts(**fixed, **{name: a[i] for name, a in given.items()})
        except (ValueError, RuntimeError) as e:
            errors[i] = str(e)
            continue
        for key in RESULTS:
            results[key][i] = out[key]
    return results, errors


def write(table, plan, folder, index, csv):
    """The partition, each file whole or not at all (a task run again after
    its worker died writes the same bytes over it)."""
    with atomic.replacing(plan.path(folder, index, "parquet"), "wb") as f:
        pq.write_table(table, f)
    if csv:
        with atomic.replacing(plan.path(folder, index, "csv"), "wb") as f:
            pyarrow.csv.write_csv(table, f)
