"""The sweep at scale (issue 26): `fraccontact sweep` against the C core on
the same cases, at the error-controlled setting of a calibration campaign
(law 2, tolerance 3e-8, dt_max 1e-3; k and c scattered 5 % and 10 %):
  - one worker, end to end (from the command's first statement, Python's own
    start excluded, to its written output), against the C core's
    single-thread throughput: fc_run_batch timed around each call, in this
    process, on the same cases in the same tasks, in the same run;
  - two workers against one;
  - the serial fraction: the one-worker time outside its tasks over the
    one-worker time, and where it goes;
  - the client's peak RSS for 10^5 and 10^7 impacts;
  - the partitions, bit for bit, on 1 and 2 local workers and on 4 workers
    of a `dask scheduler` + `dask worker` started as processes.
The sweeps run as processes, interleaved with the C core's timing, REPEATS
times; medians. Writes docs/sweep_scaling.md (docs/benchmarks.md links it).

Regenerate: scripts/report sweep_scaling   (about 10 minutes on 2 cores)
"""

import json
import os
import pathlib
import platform
import subprocess
import sys
import tempfile
import time

import numpy as np

from .. import _lib, atomic, reports
from ..sweep import cases, options, tasks
from .benchmarks import LoadWatch, git, say

SETTING = ["--scatter", "k=0.05", "--scatter", "c=10%", "--set", "law=2", "--set", "tolerance=3e-8",
           "--set", "dt_max=1e-3"]
IMPACTS = 1_000_000
LARGE, SMALL = 10_000_000, 100_000  # the client's memory, small and large campaigns
REPEATS = 3
REMOTE_WORKERS = 4
# The child that runs a sweep: its clock starts at its first statement (the
# interpreter is up), stops when the outputs are in place; its peak RSS is
# the client's alone, its children's CPU the workers'.
CHILD = """\
import time
began = time.perf_counter()
if __name__ == "__main__":
    import json, resource, sys
    from fraccontact.sweep import cli, outputs
    marks = {}
    def timed(name, function):
        def call(*args, **kw):
            marks[name + "_begins"] = time.perf_counter() - began
            out = function(*args, **kw)
            marks[name + "_ends"] = time.perf_counter() - began
            return out
        return call
    cli.connect = timed("connect", cli.connect)
    cli.simulate = timed("tasks", cli.simulate)
    outputs.Staging.commit = timed("output", outputs.Staging.commit)
    code = cli.main(sys.argv[2:], prog="fraccontact sweep")
    marks["exit"] = time.perf_counter() - began
    me, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    json.dump(dict(marks, code=code, rss=me.ru_maxrss * 1024, client_cpu=me.ru_utime + me.ru_stime,
                   workers_cpu=children.ru_utime + children.ru_stime), open(sys.argv[1], "w"))
"""


def sweep(folder, name, impacts, *extra):
    """One `fraccontact sweep` as a process: its marks, peak RSS, CPU and
    sweep.json."""
    out, marks = folder / name, folder / f"{name}.marks.json"
    args = ["--monte-carlo", str(impacts), *SETTING, "--out", str(out), *extra]
    done = subprocess.run([sys.executable, "-c", CHILD, str(marks), *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"fraccontact sweep {' '.join(args)} failed: {done.stderr.strip()[-3000:]}")
    return dict(json.loads(marks.read_text()), summary=json.loads((out / "sweep.json").read_text()), out=out)


def core(impacts, folder):
    """The C core alone on the sweep's cases and tasks: wall and CPU
    seconds inside fc_run_batch (this thread), around each call."""
    args = options.arguments(["--monte-carlo", str(impacts), *SETTING, "--out", str(folder / "core")], "")[1]
    plan, size, _ = options.prepared(args)
    real = _lib.LIB.fc_run_batch
    spent = dict(wall=0.0, cpu=0.0)

    def timed(*call):
        wall, cpu = time.perf_counter(), time.thread_time()
        status = real(*call)
        spent["wall"] += time.perf_counter() - wall
        spent["cpu"] += time.thread_time() - cpu
        return status
    _lib.LIB.fc_run_batch = timed
    try:
        for _, start, stop in cases.ranges(plan.cases.n, size):
            tasks.library_results(plan.fixed, plan.cases.inputs(start, stop)[1], stop - start)
    finally:
        _lib.LIB.fc_run_batch = real
    return spent


def partitions(out):
    return [(f.name, f.read_bytes()) for f in sorted((out / "sweep.parquet").iterdir())]


class Remote:
    """`dask scheduler` and `dask worker --nworkers N` as processes on the
    loopback address, ended by their own ids."""

    def __init__(self, folder, workers):
        from dask.distributed import Client
        file = folder / "scheduler.json"
        self.processes = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1",
                                            "--port", "0", "--no-dashboard", "--scheduler-file", str(file)],
                                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
        try:
            deadline = time.monotonic() + 60
            while not file.exists() and time.monotonic() < deadline:
                time.sleep(0.1)
            time.sleep(0.2)
            self.address = json.loads(file.read_text())["address"]
            self.processes.append(subprocess.Popen(
                [sys.executable, "-m", "dask", "worker", self.address, "--host", "127.0.0.1", "--nworkers",
                 str(workers), "--nthreads", "1", "--no-dashboard"], stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL))
            with Client(self.address, timeout=30) as client:
                client.wait_for_workers(workers, timeout=120)
        except BaseException:
            self.close()
            raise

    def close(self):
        for p in self.processes:
            if p.poll() is None:
                p.terminate()
        for p in self.processes:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def measure(folder):
    runs = dict(core=[], one=[], two=[])
    for r in range(REPEATS):
        say(f"  round {r + 1} of {REPEATS}: the C core, then 1 and 2 workers, {IMPACTS:,} impacts ...")
        runs["core"].append(core(IMPACTS, folder))
        runs["one"].append(sweep(folder, f"one{r}", IMPACTS, "--workers", "1"))
        runs["two"].append(sweep(folder, f"two{r}", IMPACTS, "--workers", "2"))
    say(f"  {LARGE:,} impacts on 1 and 2 workers, {SMALL:,} on 2 ...")
    runs["large_one"] = sweep(folder, "large_one", LARGE, "--workers", "1")
    runs["large_two"] = sweep(folder, "large_two", LARGE, "--workers", "2")
    runs["small_two"] = sweep(folder, "small_two", SMALL, "--workers", "2")
    say(f"  {IMPACTS:,} impacts on {REMOTE_WORKERS} workers of dask scheduler + dask worker processes ...")
    remote = Remote(folder, REMOTE_WORKERS)
    try:
        runs["remote"] = sweep(folder, "remote", IMPACTS, "--scheduler", remote.address)
    finally:
        remote.close()
    reference = partitions(runs["one"][0]["out"])
    runs["identical"] = {name: partitions(run["out"]) == reference
                         for name, run in (("two workers", runs["two"][0]), ("remote", runs["remote"]),
                                           ("one worker again", runs["one"][-1]))}
    runs["partitions"] = len(reference)
    return runs


def median(values):
    return float(np.median(list(values)))


def met(ok):
    return "yes" if ok else "**no**"


def serial(run):
    """Where one run's time goes: seconds from its start, to its output."""
    m, s = run, run["summary"]
    return dict(total=m["output_ends"], start=m["tasks_begins"], cluster=m["connect_ends"] - m["connect_begins"],
                tasks=m["tasks_ends"] - m["tasks_begins"], inside=s["task_seconds"],
                statistics=s["statistics_seconds"],
                writing=m["output_ends"] - m["tasks_ends"] - s["statistics_seconds"])


def lines(runs, load, head, minutes):
    core_wall = median(c["wall"] for c in runs["core"])
    core_rate, core_cpu_rate = IMPACTS / core_wall, IMPACTS / median(c["cpu"] for c in runs["core"])
    one = median(serial(r)["total"] for r in runs["one"])
    two = median(serial(r)["total"] for r in runs["two"])
    inside_one = median(r["summary"]["wall_seconds"] for r in runs["one"])
    inside_two = median(r["summary"]["wall_seconds"] for r in runs["two"])
    parts = {key: median(serial(r)[key] for r in runs["one"]) for key in serial(runs["one"][0])}
    outside = parts["total"] - parts["inside"]
    fraction = outside / parts["total"]
    large = serial(runs["large_one"])
    large_fraction = (large["total"] - large["inside"]) / large["total"]
    large_two = serial(runs["large_two"])
    rss_small, rss_large = runs["small_two"]["rss"], runs["large_two"]["rss"]
    cpu_one = median(r["client_cpu"] + r["workers_cpu"] for r in runs["one"])
    library_cpu = median(r["summary"]["library_cpu_seconds"] for r in runs["one"]) / IMPACTS
    task_cpu = median(r["summary"]["task_cpu_seconds"] for r in runs["one"]) / IMPACTS
    amdahl = 1 / (fraction + (1 - fraction) / 16)
    return [
        "# The sweep at scale", "",
        "Regenerate: `scripts/report sweep_scaling` (this run: "
        f"{minutes:.0f} minutes). Measured side by side in one run on commit {head}, on "
        f"{platform.processor() or platform.machine()} ({platform.system()}, {os.cpu_count()} cores shared with "
        f"other work: 1-minute load average {min(load):.2f} to {max(load):.2f}, median {np.median(load):.2f}, "
        "sampled every 10 s). Wall time, medians of "
        f"{REPEATS} rounds, each the C core's timing then `fraccontact sweep` on 1 and 2 local workers; on this "
        "shared machine a wall time moves with the other work, the ratios within a round less.", "",
        "The campaign: `fraccontact sweep --monte-carlo N " + " ".join(SETTING) + "` (the error-controlled "
        "setting of a calibration campaign: law 2, `tolerance` 3e-8, `dt_max` 1e-3), its statistics and "
        "histograms included, Parquet only. End to end: from the command's first statement (the interpreter "
        "up: Python's own start excluded) to its outputs in place. The C core: `fc_run_batch` timed around "
        "each call, in one thread of the report's process, on the same cases in the same tasks.", "",
        "| what | measured | against | ratio | target | met |", "|---|---|---|---|---|---|",
        f"| one worker, {IMPACTS:,} impacts, end to end: impacts/s | {IMPACTS / one:,.0f} | C core: "
        f"{core_rate:,.0f} | {100 * IMPACTS / one / core_rate:.0f} % | >= 90 % | "
        f"{met(IMPACTS / one >= 0.9 * core_rate)} |",
        f"| one worker, {IMPACTS:,} impacts, in the tasks (first given to last done): impacts/s | "
        f"{IMPACTS / inside_one:,.0f} | C core: {core_rate:,.0f} | "
        f"{100 * IMPACTS / inside_one / core_rate:.0f} % | | |",
        f"| one worker, {LARGE:,} impacts, end to end: impacts/s | {LARGE / large['total']:,.0f} | C core: "
        f"{core_rate:,.0f} | {100 * LARGE / large['total'] / core_rate:.0f} % | >= 90 % | "
        f"{met(LARGE / large['total'] >= 0.9 * core_rate)} |",
        f"| two workers, {IMPACTS:,} impacts, end to end: impacts/s | {IMPACTS / two:,.0f} | one worker: "
        f"{IMPACTS / one:,.0f} | {one / two:.2f}x | >= 1.9x | {met(one / two >= 1.9)} |",
        f"| two workers, {IMPACTS:,} impacts, in the tasks: impacts/s | {IMPACTS / inside_two:,.0f} | one worker: "
        f"{IMPACTS / inside_one:,.0f} | {inside_one / inside_two:.2f}x | | |",
        f"| two workers, {LARGE:,} impacts, end to end: impacts/s | {LARGE / large_two['total']:,.0f} | one worker: "
        f"{LARGE / large['total']:,.0f} | {large['total'] / large_two['total']:.2f}x | >= 1.9x | "
        f"{met(large['total'] / large_two['total'] >= 1.9)} |",
        f"| serial fraction, one worker, {IMPACTS:,} impacts: time outside the tasks / end to end | "
        f"{outside:.2f} s | {parts['total']:.2f} s | {100 * fraction:.1f} % | <= 2 % | {met(fraction <= 0.02)} |",
        f"| serial fraction, one worker, {LARGE:,} impacts | {large['total'] - large['inside']:.2f} s | "
        f"{large['total']:.2f} s | {100 * large_fraction:.1f} % | <= 2 % | {met(large_fraction <= 0.02)} |",
        f"| client's peak RSS, {LARGE:,} impacts against {SMALL:,} (2 workers) | {rss_large / 1e6:.0f} MB | "
        f"{rss_small / 1e6:.0f} MB | {rss_large / rss_small:.2f}x | <= 2x | {met(rss_large <= 2 * rss_small)} |",
        "", f"Where the one-worker time goes ({IMPACTS:,} impacts, medians): {parts['start']:.2f} s before the "
        f"first task (imports, the options, {parts['cluster']:.2f} s starting the local cluster's worker "
        f"process), {parts['tasks']:.2f} s of tasks ({parts['inside']:.2f} s inside them: the library calls, "
        f"their inputs and Parquet files), {parts['statistics']:.2f} s of statistics (Dask tasks over the "
        f"partitions), {parts['writing']:.2f} s writing the plot and sweep.json. With a serial fraction s, "
        f"Amdahl's law allows 1 / (s + (1 - s) / 16) = {amdahl:.1f}x on 16 workers at this size. The C core's "
        f"CPU per impact: {1e6 / core_cpu_rate:.2f} µs; in the worker's tasks, the library calls' "
        f"{1e6 * library_cpu:.2f} µs and the whole tasks' {1e6 * task_cpu:.2f} µs (the inputs, the batch, the "
        f"Parquet file, the moments: {100 * (task_cpu / library_cpu - 1):.1f} % more); the whole one-worker "
        f"command's CPU (client and worker processes): {1e6 * cpu_one / IMPACTS:.2f} µs an impact.", "",
        "Bit for bit: the Parquet partitions ({} files) of the one-worker run are the same bytes as those of "
        "{}.".format(runs["partitions"], ", ".join(f"{name} ({'identical' if same else '**different**'})"
                                                     for name, same in runs["identical"].items()))
        + f" The remote cluster: `dask scheduler` and `dask worker --nworkers {REMOTE_WORKERS} --nthreads 1` "
        "started as processes on the loopback address.", "",
        f"Not measured: 4, 8 and 16 workers' throughput, this machine having {os.cpu_count()} cores (4 workers "
        "ran above for the bit-for-bit check only, sharing them)."]


def main(argv=None, prog=None):
    parser = reports.parser(prog, __doc__)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="sweep_scaling.") as work:
        with LoadWatch() as load:
            runs = measure(pathlib.Path(work))
    text = lines(runs, load.samples, git(pathlib.Path.cwd(), "rev-parse", "--short", "HEAD"),
                 (time.perf_counter() - started) / 60)
    atomic.write_text(args.out / "sweep_scaling.md", "\n".join(text) + "\n")
    say(f"wrote {args.out / 'sweep_scaling.md'}")
    return 0
