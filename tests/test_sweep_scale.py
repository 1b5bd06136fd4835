"""The columnar sweep. Each task computes its own cases (a slice of
the grid, or its draws from the seed) and writes them, inputs beside
results, as a Parquet partition; case i is the same whatever the tasks and
the workers, so the partitions are the same bytes on 1 or 2 workers, on a
local cluster or on a `dask scheduler` + `dask worker` started as
processes, and after a worker dies mid-run. The statistics, computed on the
workers from the partitions, are numpy's on the same values. The cases in
process first (fast), then the clusters (seconds each)."""

import csv
import itertools
import json
import os
import signal
import subprocess
import sys
import time
import types
from fractions import Fraction

import numpy as np
import pyarrow.parquet as pq
import pytest

import fraccontact
from fraccontact import sweep
from fraccontact.sweep import cases, cli, options, outputs, stats, tasks

pytestmark = pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                                reason="Dask workers under a preloaded sanitizer runtime")

TABLE = options.parameter_table()


def axis(name, spec):
    return options.values(TABLE[name], spec)


def concatenated(parts):
    return {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}


# ---------------------------------------------------------------- cases, in process


def test_grid_slices_are_the_grid():
    """Any split of the index range gives the rows of the full product, as
    itertools.product and the exact decimals (Fraction) give them; the
    library is handed law's codes, the partitions its words."""
    grid = cases.Grid((("height", axis("height", "0.005:0.1:0.005")), ("c", axis("c", "3000,6080")),
                       ("law", axis("law", "g1,hertz"))))
    heights = [float(Fraction(5 * i, 1000)) for i in range(1, 21)]
    expected = list(itertools.product(heights, [3000.0, 6080.0], ["g1", "hertz"]))
    assert grid.n == len(expected) == 80
    for cuts in ([0, 80], [0, 7, 30, 79, 80], list(range(81))):
        parts = [grid.inputs(a, b) for a, b in zip(cuts, cuts[1:])]
        shown = concatenated([s for s, _ in parts])
        given = concatenated([g for _, g in parts])
        assert list(zip(*(shown[k].tolist() for k in ("height", "c", "law")))) == expected
        assert given["law"].tolist() == [{"g1": 1, "hertz": 2}[law] for *_, law in expected]


def test_a_grid_of_tiny_steps_is_exact_on_both_paths():
    """A grid whose scale exceeds 2^53 takes Python's integers instead of
    doubles: both give float(Fraction) of each value, to the bit."""
    fast = axis("R", "1e-13:5e-13:1e-13")
    slow = cases.Steps(fast.first * 10 ** 6, fast.stride * 10 ** 6, fast.scale * 10 ** 6, fast.n, False)
    assert slow.scale >= cases.EXACT > fast.scale
    i = np.arange(fast.n)
    truth = [float(Fraction(fast.first + j * fast.stride, fast.scale)) for j in range(fast.n)]
    assert fast.at(i).tolist() == slow.at(i).tolist() == truth == [1e-13, 2e-13, 3e-13, 4e-13, 5e-13]


def test_monte_carlo_draws_do_not_depend_on_the_tasks():
    """Case i's draws are the same whatever the range it is drawn in (block
    edges crossed and cut), and a parameter's draws do not change when
    another scatters beside it."""
    k_alone = cases.MonteCarlo(40000, 7, (("k", 7, 3.3e8, 0.05),))
    both = cases.MonteCarlo(40000, 7, (("k", 7, 3.3e8, 0.05), ("c", 9, 6080.0, 0.1)))
    whole, _ = both.inputs(0, both.n)
    b = cases.BLOCK
    for cuts in ([0, 40000], [0, 1, b - 1, b + 1, 2 * b, 39999, 40000], [0, 12345, 23456, 40000]):
        parts = concatenated([both.inputs(x, y)[0] for x, y in zip(cuts, cuts[1:])])
        assert parts["k"].tobytes() == whole["k"].tobytes() and parts["c"].tobytes() == whole["c"].tobytes()
    assert k_alone.inputs(0, 40000)[0]["k"].tobytes() == whole["k"].tobytes()
    assert len(np.unique(whole["k"])) == 40000 and not np.array_equal(whole["k"][:b], whole["k"][b:2 * b])


# ---------------------------------------------------------------- statistics, in process


def hard_partitions(folder):
    """Partitions of awkward values: x spans 300 decades of both signs with
    ties (0 and -0 among them), NaN and infinities (not values), refused
    rows (left out); n integers with ties; one a constant; s one value."""
    rng = np.random.default_rng(5)
    files = []
    for i, size in enumerate((1, 700, 3000, 50, 2200)):
        x = np.sign(rng.normal(size=size)) * 10.0 ** rng.uniform(-150, 150, size)
        x[rng.random(size) < 0.2] = 0.0
        x[rng.random(size) < 0.05] = -0.0
        x[rng.random(size) < 0.05] = np.nan
        x[rng.random(size) < 0.01] = np.inf
        x[rng.random(size) < 0.3] = 1.5  # ties at the median
        n = rng.integers(0, 4, size)
        error = np.where(rng.random(size) < 0.1, "refused", None)
        single = np.where(np.arange(size) == 0, 2.0, np.nan) if i == 2 else np.full(size, np.nan)
        table = tasks.pa.table({"x": x, "n": n, "one": np.full(size, 0.626418), "s": single,
                                "error": tasks.pa.array(error, tasks.pa.string())})
        files.append(folder / f"part-{i}.parquet")
        pq.write_table(table, files[-1])
    return files


def task_summaries(files):
    """Each partition's statistics' summary, as its task reduces it."""
    out = []
    for f in files:
        table = pq.read_table(f)
        failed = np.flatnonzero(table.column("error").is_valid().to_numpy(zero_copy_only=False))
        numbers = {name: table.column(name).to_numpy() for name in table.column_names if name != "error"}
        out.append(stats.reduced(numbers, failed, len(out)))
    return out


def folded(summaries, order):
    """The summaries merged in the order given: a left fold, or pairs first
    (Dask's fold tree depends on which task finishes first)."""
    parts = [summaries[i] for i in order]
    while len(parts) > 1:
        parts = [stats.merged(*parts[i:i + 2]) if i + 1 < len(parts) else parts[i] for i in range(0, len(parts), 2)]
    return parts[0]


def within_bound(found, x):
    """Each percentile within the bound of numpy's over the values x: the
    bound plus the rounding of two interpolations (a few ulps of the
    values' size, 1e-15 of it)."""
    exact = np.percentile(x, [5, 50, 95])
    slack = 1e-15 * np.abs(x).max()
    return all(abs(p - e) <= found["bound"] + slack for p, e in zip([found["p5"], found["p50"], found["p95"]], exact))


def test_in_task_statistics_are_numpys_within_their_bound_on_hard_values(tmp_path):
    """The tasks' summaries merged in three orders: the same statistics to
    the bit (the bins' counts are exact integers whatever the tree, the
    moments merged in the tasks' order), each percentile
    within its stated bound of numpy's over the concatenated values
    (NaN, infinities and refused rows left out); exact where a bin holds
    one value (the constant, the integers, the single value); the mean and
    std within 1e-12 of the values' size, another summation order (5000 *
    2^-53 = 6e-13 at most)."""
    files = hard_partitions(tmp_path)
    summaries = task_summaries(files)
    found = [stats.statistics(folded(summaries, order)) for order in ([0, 1, 2, 3, 4], [4, 3, 2, 1, 0], [2, 0, 4, 1, 3])]
    assert found[0] == found[1] == found[2]
    found = found[0]
    table = pq.read_table(files)
    ok = table.column("error").is_null().to_numpy(zero_copy_only=False)
    assert set(found) == {"x", "n", "one", "s"}
    for name, s in found.items():
        x = table.column(name).to_numpy()[ok].astype(float)
        x = x[np.isfinite(x)]
        assert within_bound(s, x), (name, s, np.percentile(x, [5, 50, 95]))
        scale = np.abs(x).max()
        assert s["mean"] == pytest.approx(x.mean(), rel=1e-12, abs=1e-12 * scale), name
        if len(x) > 1:
            assert s["std"] == pytest.approx(x.std(ddof=1), rel=1e-12, abs=1e-12 * scale), name
        else:
            assert s["std"] is None and name == "s"
        if name != "x":
            assert s["bound"] == 0 and [s["p5"], s["p50"], s["p95"]] == np.percentile(x, [5, 50, 95]).tolist(), name
    assert found["x"]["bound"] > 0  # 300 decades of both signs: bins of an eighth of a binade


def test_in_task_percentiles_of_a_campaign_are_within_an_eight_thousandth(tmp_path):
    """Log-normal columns as a campaign gives them (10 % scatter, in ten
    partitions), and one that crosses zero: 2^BITS bins over at most two
    binades' keys are each at most 2^(1 - BITS) of the larger binade, so
    the bound is at most 2^(2 - BITS) = 1.2e-4 of the largest value, and
    every percentile is within it of numpy's."""
    rng = np.random.default_rng(3)
    parts = [dict(c=rng.lognormal(np.log(6080), 0.1, 30000), v=rng.normal(0.5, 1.0, 30000)) for _ in range(10)]
    summaries = [stats.reduced(part, [], i) for i, part in enumerate(parts)]
    found = stats.statistics(folded(summaries, range(10)))
    c = np.concatenate([p["c"] for p in parts])
    assert within_bound(found["c"], c)
    assert 0 < found["c"]["bound"] <= 2.0 ** (2 - stats.BITS) * c.max()
    assert within_bound(found["v"], np.concatenate([p["v"] for p in parts]))


def test_the_plots_histograms_count_every_value(tmp_path):
    """The plot's bins group the summary's: every value counted once, each
    within one summary bin of numpy's histogram over the same range."""
    rng = np.random.default_rng(8)
    x = rng.lognormal(0, 0.2, 50000)
    counts, low, high = stats.histogram(stats.reduced(dict(x=x), [])["x"], 40)
    exact = np.histogram(x, bins=40, range=(x.min(), x.max()))[0]
    assert (low, high) == (x.min(), x.max()) and counts.sum() == len(x)
    assert np.abs(np.cumsum(counts) - np.cumsum(exact)).max() <= 0.01 * len(x)


def test_a_tasks_summaries_use_one_scratch_array():
    """reduced() summarises twelve columns of n doubles with temporaries
    of about one column (one scratch array): beside the summaries it
    returns (their bins' counts), its peak of memory traced stays below
    one and a half columns, where a temporary for each step (deviations,
    keys, shifted keys, bins) would hold three or more at once."""
    import tracemalloc
    rng = np.random.default_rng(5)
    n = 200_000
    columns = {f"x{i}": rng.lognormal(0, 0.1, n) for i in range(12)}
    tracemalloc.start()
    try:
        summaries = stats.reduced(columns, [])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    kept = sum(s.counts.nbytes for s in summaries.values())
    assert peak - kept < 1.5 * 8 * n, (peak, kept)


# ---------------------------------------------------------------- outputs, in process


def test_outputs_replace_an_older_run_whole(tmp_path):
    """The partitions move into place as one folder; an older run's files
    that this run does not write are removed; a half-written leftover of a
    dead worker is dropped; nothing hidden is left."""
    out = tmp_path / "out"
    (out / "sweep.parquet").mkdir(parents=True)
    for name in ("sweep.parquet/part-000000.parquet", "sweep.parquet/part-000001.parquet", "sweep.csv",
                 "sweep.png", "sweep.json"):
        (out / name).write_text("old")
    staging = outputs.Staging(out)
    (staging.folder / "part-000000.parquet").write_text("new")
    (staging.folder / ".part-000001.parquet.x.tmp").write_text("half")
    (staging.folder / "sweep.json").write_text("new")
    staging.commit({"sweep.json"})
    assert sorted(p.name for p in out.iterdir()) == ["sweep.json", "sweep.parquet"]
    assert [(p.name, p.read_text()) for p in (out / "sweep.parquet").iterdir()] == [("part-000000.parquet", "new")]
    assert (out / "sweep.json").read_text() == "new"


def test_a_failed_sweep_leaves_nothing(tmp_path):
    """discard(): the hidden folder goes, and so do the folders the sweep
    made for --out; an existing --out keeps what it held."""
    out = tmp_path / "a" / "b"
    staging = outputs.Staging(out)
    (staging.folder / "part-000000.parquet").write_text("partial")
    staging.discard()
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "kept").mkdir()
    (tmp_path / "kept" / "mine.txt").write_text("x")
    staging = outputs.Staging(tmp_path / "kept")
    staging.discard()
    assert [p.name for p in (tmp_path / "kept").iterdir()] == ["mine.txt"]


# ---------------------------------------------------------------- clusters


MC = ["--monte-carlo", "12000", "--scatter", "k=0.05", "--scatter", "c=10%", "--set", "law=hertz",
      "--set", "dt_max=3e-6", "--seed", "4", "--batch", "4000"]  # 3 tasks, whatever the workers


def partitions(out):
    files = sorted((out / "sweep.parquet").iterdir())
    return [f.name for f in files], [f.read_bytes() for f in files]


@pytest.fixture(scope="module")
def local_runs(tmp_path_factory):
    """The same campaign on 1 and 2 local workers, threads (the second with
    --csv), and on 2 worker processes."""
    out = tmp_path_factory.mktemp("local")
    assert sweep.main(MC + ["--workers", "1", "--out", str(out / "one")]) == 0
    assert sweep.main(MC + ["--workers", "2", "--csv", "--out", str(out / "two")]) == 0
    assert sweep.main(MC + ["--workers", "2", "--processes", "--out", str(out / "processes")]) == 0
    return out / "one", out / "two", out / "processes"


def test_partitions_are_the_same_bytes_on_one_and_two_workers(local_runs):
    one, two, processes = local_runs
    names, data = partitions(one)
    assert names == ["part-000000.parquet", "part-000001.parquet", "part-000002.parquet"]
    assert partitions(two) == (names, data)
    assert partitions(processes) == (names, data)
    assert json.loads((processes / "sweep.json").read_text())["statistics"] == \
        json.loads((one / "sweep.json").read_text())["statistics"]


def test_library_calls_in_chunks_are_one_batch(monkeypatch):
    """A task's cases in library calls of a few cases each (chunk sizes 3,
    then at most 10) give fraccontact.impacts' results for the same
    arrays in one batch, to the bit; a refused case is NaN in k with its
    message, the others unmoved."""
    monkeypatch.setattr(tasks, "FIRST", 3)
    monkeypatch.setattr(tasks, "CHUNK", 10)
    rng = np.random.default_rng(2)
    c = rng.lognormal(np.log(6080), 0.1, 57)
    k = rng.lognormal(np.log(3.3e8), 0.05, 57)
    fixed = dict(law=2, dt_max=3e-6)
    results, errors, _ = tasks.library_results(fixed, dict(c=c, k=k), 57)
    truth = fraccontact.impacts(c=c, k=k, law="hertz", dt_max=3e-6)
    for key in sweep.RESULTS:
        assert results[key].tobytes() == np.asarray(getattr(truth, key)).astype(results[key].dtype).tobytes(), key
    assert errors == {}
    c[40] = -1.0
    results, errors, _ = tasks.library_results(fixed, dict(c=c, k=k), 57)
    assert list(errors) == [40] and "c" in errors[40] and np.isnan(results["k"][40])
    assert np.delete(results["F_peak"], 40).tobytes() == np.delete(truth.F_peak, 40).tobytes()


@pytest.mark.parametrize("scheduler, workers, preloaded_after", [(None, 2, 4), (None, 1, 0), ("tcp://host:8786", 2, 0)])
def test_the_plots_library_is_imported_once_a_cpu_is_free(monkeypatch, scheduler, workers, preloaded_after):
    """On 2 CPUs, 5 tasks: with a local worker thread on every CPU, the
    plot's library is imported (in the background, once) when the fourth
    task has ended and one is left; with a CPU to spare, or a remote
    cluster, at once."""
    monkeypatch.setattr(options, "cpus", lambda: 2)
    ended, started = [0], []
    monkeypatch.setattr(outputs, "preload", lambda: started.append(ended[0]))
    plot_import = cli.PlotImport(types.SimpleNamespace(scheduler=scheduler, workers=workers), 5)
    for _ in range(5):
        ended[0] += 1
        plot_import.task_ended()
    assert started == [preloaded_after]


def test_a_monte_carlo_campaign_reads_no_partition_back(tmp_path, monkeypatch):
    """The statistics and the histograms come from the tasks' summaries:
    the sweep (its workers threads of this process) never reads a Parquet
    file."""
    def refused(*args, **kw):
        raise AssertionError("a partition was read")
    monkeypatch.setattr(pq, "read_table", refused)
    monkeypatch.setattr(pq, "ParquetFile", refused)
    assert sweep.main(MC + ["--workers", "2", "--out", str(tmp_path / "out")]) == 0
    assert set(json.loads((tmp_path / "out" / "sweep.json").read_text())["statistics"]) >= {"F_peak", "eps"}


def test_the_inputs_are_beside_the_library_results(local_runs):
    """Each partition holds the drawn inputs, then every result of the
    library for them: a sample of rows against fraccontact.impact, a run of
    its own for each (bit for bit: test_package.py)."""
    table = pq.read_table(local_runs[0] / "sweep.parquet")
    assert table.column_names == ["k", "c"] + [f"{key}_result" if key == "k" else key for key in sweep.RESULTS] + \
        ["error"]
    assert table.num_rows == 12000 and table.column("error").null_count == 12000
    rows = table.to_pylist()
    for i in (0, 4999, 5000, 11999):
        r = fraccontact.impact(k=rows[i]["k"], c=rows[i]["c"], law="hertz", dt_max=3e-6)
        for key in sweep.RESULTS:
            assert rows[i][f"{key}_result" if key == "k" else key] == getattr(r, key), (i, key)


def test_the_csv_is_written_on_request_with_the_same_rows(local_runs):
    one, two, _ = local_runs
    assert not (one / "sweep.csv").exists()
    with open(two / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    table = pq.read_table(two / "sweep.parquet").to_pylist()
    assert len(rows) == len(table) == 12000
    for r, p in zip(rows[::997], table[::997]):
        assert r["error"] == "" and p["error"] is None
        assert {k: float(v) for k, v in r.items() if k != "error"} == {k: v for k, v in p.items() if k != "error"}


def test_statistics_are_numpys_on_the_partitions(local_runs):
    """sweep.json's statistics (mean and std within 1e-12 of the values'
    size, another summation order; percentiles within their bound) over
    the Parquet partitions' values, and the same on 1 and 2 workers."""
    table = pq.read_table(local_runs[1] / "sweep.parquet")
    found = json.loads((local_runs[1] / "sweep.json").read_text())["statistics"]
    assert found == json.loads((local_runs[0] / "sweep.json").read_text())["statistics"]
    assert set(found) == set(table.column_names) - {"error"}
    for name, s in found.items():
        x = table.column(name).to_numpy().astype(float)
        x = x[np.isfinite(x)]
        assert within_bound(s, x), name
        scale = np.abs(x).max()
        assert s["mean"] == pytest.approx(x.mean(), rel=1e-12, abs=1e-12 * scale), name
        assert s["std"] == pytest.approx(x.std(ddof=1), rel=1e-12, abs=1e-12 * scale), name


def start(*command, env=None):
    return subprocess.Popen([sys.executable, "-m", "dask", *command], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=env)


def stop(processes):
    """Ends the cluster's processes, each by its own id: nothing of theirs
    is worth a graceful close."""
    for p in processes:
        if p.poll() is None:
            p.kill()
        p.wait()


class Cluster:
    """`dask scheduler` and `dask worker`s started as a user starts them,
    as processes on the loopback address, without nannies (a worker
    killed stays dead)."""

    def __init__(self, folder, workers, env=None):
        self.file = folder / "scheduler.json"
        self.processes = [start("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                "--scheduler-file", str(self.file))]
        try:
            self.address = self.wait_for_address()
            self.workers = [start("worker", self.address, "--host", "127.0.0.1", "--nthreads", "1", "--no-nanny",
                                  "--no-dashboard", env=env) for _ in range(workers)]
            self.processes += self.workers
            from dask.distributed import Client
            with Client(self.address, timeout=30) as client:
                client.wait_for_workers(workers, timeout=60)
        except BaseException:
            stop(self.processes)
            raise

    def wait_for_address(self):
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if self.file.exists():
                try:
                    return json.loads(self.file.read_text())["address"]
                except (ValueError, KeyError):
                    pass
            time.sleep(0.1)
        raise TimeoutError("dask scheduler did not start within 60 s")


@pytest.fixture
def cluster(tmp_path):
    made = []

    def make(workers, env=None):
        made.append(Cluster(tmp_path, workers, env))
        return made[-1]
    yield make
    for c in made:
        stop(c.processes)


def test_a_scheduler_and_a_worker_started_as_processes(cluster, local_runs, tmp_path):
    """--scheduler ADDRESS: the same partitions as the local cluster's."""
    remote = cluster(1)
    assert sweep.main(MC + ["--scheduler", remote.address, "--out", str(tmp_path / "out")]) == 0
    assert partitions(tmp_path / "out") == partitions(local_runs[0])
    assert json.loads((tmp_path / "out" / "sweep.json").read_text())["statistics"] == \
        json.loads((local_runs[0] / "sweep.json").read_text())["statistics"]


def test_a_relative_out_is_the_sweeps_for_the_workers_too(cluster, tmp_path, monkeypatch):
    """--out taken from the sweep's working folder, which is not the
    workers' (they started before the chdir): the workers write there
    (26f430c: refused, "the workers ... do not see it")."""
    remote = cluster(1)
    monkeypatch.chdir(tmp_path)
    assert sweep.main(MC + ["--scheduler", remote.address, "--out", "relative"]) == 0
    assert json.loads((tmp_path / "relative" / "sweep.json").read_text())["impacts"] == int(MC[1])
    assert list((tmp_path / "relative" / "sweep.parquet").glob("part-*.parquet"))


def test_workers_without_the_package_are_refused_in_one_line(cluster, tmp_path, capsys):
    """A worker started where fraccontact is not installed (no PYTHONPATH
    to this source tree): one line saying so, exit status 2, nothing
    written."""
    remote = cluster(1, env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"})
    assert sweep.main(MC + ["--scheduler", remote.address, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "the workers cannot import the sweep" in err[-1] and "pip install" in err[-1], err[-3:]
    assert not (tmp_path / "out").exists()


DEATH = ["--monte-carlo", "1000", "--scatter", "c=10%", "--batch", "50", "--seed", "9"]  # 20 tasks of some 40 ms


def test_a_worker_killed_mid_run_loses_nothing(cluster, tmp_path):
    """One of two workers killed (SIGKILL) once the first partition is
    written: Dask runs its tasks again on the other, and every partition is
    the bytes the tasks give without Dask (tasks.run in this process)."""
    remote = cluster(2)
    out = tmp_path / "out"
    sweeping = subprocess.Popen([sys.executable, "-m", "fraccontact", "sweep", *DEATH, "--scheduler", remote.address,
                                 "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not list(out.glob(".sweep.parquet.*/part-*.parquet")) and time.monotonic() < deadline:
            time.sleep(0.02)
        victim = remote.workers[0]
        victim.send_signal(signal.SIGKILL)
        stdout, stderr = sweeping.communicate(timeout=120)
    finally:
        if sweeping.poll() is None:
            sweeping.kill()
            sweeping.wait()
    assert victim.wait(timeout=10) == -signal.SIGKILL
    assert sweeping.returncode == 0, stderr[-3000:]
    assert json.loads(stdout.splitlines()[-1])["impacts"] == 1000
    args = options.arguments(DEATH + ["--out", str(tmp_path / "reference")], "sweep")[1]
    plan, size, _ = options.prepared(args)
    (tmp_path / "reference").mkdir()
    for i, a, b in cases.ranges(plan.cases.n, size):
        tasks.run(plan, i, a, b, tmp_path / "reference", False)
    names, data = partitions(out)
    assert len(names) == 20
    assert [(tmp_path / "reference" / name).read_bytes() for name in names] == data


# ---------------------------------------------------------------- the benchmark's figures


def test_the_benchmarks_quote_the_scaling_report():
    """docs/benchmarks.md's section on the sweep at scale gives the figures
    docs/sweep_scaling.md measured (scripts/report sweep_scaling writes
    both), and every run there gave the same bytes."""
    root = os.path.join(os.path.dirname(__file__), "..")
    doc = open(os.path.join(root, "docs", "sweep_scaling.md")).read()
    benchmarks = open(os.path.join(root, "docs", "benchmarks.md")).read()
    section = benchmarks.split("<!-- sweep_scaling: begin -->")[1].split("<!-- sweep_scaling: end -->")[0]

    def cell(row):
        line = next(line for line in doc.splitlines() if line.startswith(f"| {row}"))
        return line.split("|")[4].strip()
    rows = [("one worker, 1,000,000 impacts, end to end: impacts/s", "one worker, 10,000,000 impacts, end to end: "
             "impacts/s"), ("two workers, 1,000,000 impacts, end to end", "two workers, 10,000,000 impacts, end to end"),
            ("serial fraction, one worker, 1,000,000 impacts: time", "serial fraction, one worker, 10,000,000 impacts |")]
    for small, large in rows:
        assert f"| {cell(small)}; {cell(large)}" in section, (small, large)
    assert f"| {cell('client')} |" in section
    assert "**different**" not in doc and doc.count("(identical)") == 4 and "| identical | yes |" in section


@pytest.mark.parametrize("signum, status, said", [
    (signal.SIGINT, 130, "interrupted; nothing written"),
    (signal.SIGTERM, 143, "terminated (SIGTERM); nothing written"),  # 26f430c left the hidden folder
], ids=["ctrl-c", "sigterm"])
def test_a_signal_stops_the_sweep_and_leaves_nothing(signum, status, said, tmp_path):
    """SIGINT (Ctrl-C) or SIGTERM (timeout, batch systems) while the tasks
    run: exit status 128 + the signal within seconds, one line saying so,
    no traceback, and --out (which the sweep made) gone."""
    out = tmp_path / "out"
    sweeping = subprocess.Popen([sys.executable, "-m", "fraccontact", "sweep", "--monte-carlo", "10000000",
                                 "--scatter", "c=10%", "--workers", "1", "--out", str(out)],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 60
        while not list(out.glob(".sweep.parquet.*")) and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)  # the tasks under way
        sweeping.send_signal(signum)
        stopped = time.monotonic()
        _, stderr = sweeping.communicate(timeout=30)
    finally:
        if sweeping.poll() is None:
            sweeping.kill()
            sweeping.wait()
    assert sweeping.returncode == status and time.monotonic() - stopped < 10, stderr[-3000:]
    assert said in stderr and "Traceback" not in stderr
    assert not out.exists()
