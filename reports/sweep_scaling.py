"""The sweep at scale: `fraccontact sweep` against the C core on
the same cases, at the error-controlled setting of a calibration campaign
(law 2, tolerance 3e-8, dt_max 1e-3; k and c scattered 5 % and 10 %):
  - one worker, end to end (from the command's first statement, Python's own
    start excluded, to its written output), against the C core's
    single-thread throughput: fc_run_batch timed around each call, in this
    process, on the same cases in the same tasks, in the same run; in wall
    time and in CPU time (the command's, its children's included);
  - two workers against one; the local cluster's threads (the default)
    against its processes (--processes); and the C core itself on two
    threads against one, this machine's ceiling for two workers;
  - the serial fraction: the one-worker time outside its tasks over the
    one-worker time, and where it goes;
  - the client's peak RSS (its process, the worker threads in it) for 10^5
    and 10^7 impacts;
  - the partitions and the statistics, bit for bit, on 1 and 2 local
    workers, threads and processes, and on 4 workers of a `dask scheduler`
    + `dask worker` started as processes.
The sweeps run as processes, interleaved with the C core's timing, REPEATS
times; medians. Writes docs/sweep_scaling.md, and the sweep's targets in
their section of docs/benchmarks.md.

Regenerate: scripts/report sweep_scaling   (about 5 minutes on 2 cores)
"""

import json
import os
import pathlib
import platform
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from fraccontact import _lib, atomic, output
from fraccontact.sweep import cases, options, tasks

from .benchmarks import SWEEP_BEGIN, SWEEP_END, LoadWatch, git, replace_section, say

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


def campaign(impacts, folder):
    """The sweep's plan of the campaign and its task size, as the command makes them."""
    args = options.arguments(["--monte-carlo", str(impacts), *SETTING, "--out", str(folder / "core")], "")[1]
    plan, size, _ = options.prepared(args)
    return plan, size


def core(impacts, folder):
    """The C core alone on the sweep's cases and tasks: wall and CPU
    seconds inside fc_run_batch (this thread), around each call."""
    plan, size = campaign(impacts, folder)
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


def core_threads(impacts, folder):
    """The C core's own scaling on this machine, the ceiling of the
    workers': the sweep's tasks with their inputs drawn beforehand, run by
    the library in one thread, then in two at once (each every other task;
    the library calls release the GIL); wall seconds of each."""
    plan, size = campaign(impacts, folder)
    work = [(plan.cases.inputs(start, stop)[1], stop - start) for _, start, stop in cases.ranges(plan.cases.n, size)]

    def run(part):
        for given, n in part:
            tasks.library_results(plan.fixed, given, n)

    began = time.perf_counter()
    run(work)
    one = time.perf_counter() - began
    with ThreadPoolExecutor(2) as pool:
        began = time.perf_counter()
        list(pool.map(run, (work[0::2], work[1::2])))
        two = time.perf_counter() - began
    return dict(one=one, two=two)


def partitions(out):
    """The partitions' bytes and sweep.json's statistics."""
    return [(f.name, f.read_bytes()) for f in sorted((out / "sweep.parquet").iterdir())], \
        json.loads((out / "sweep.json").read_text())["statistics"]


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
    runs = dict(core=[], core_threads=[], one=[], two=[], one_processes=[], two_processes=[])
    for r in range(REPEATS):
        say(f"  round {r + 1} of {REPEATS}: the C core, then 1 and 2 workers, threads and processes, {IMPACTS:,} "
            "impacts ...")
        runs["core"].append(core(IMPACTS, folder))
        runs["core_threads"].append(core_threads(IMPACTS, folder))
        runs["one"].append(sweep(folder, f"one{r}", IMPACTS, "--workers", "1"))
        runs["two"].append(sweep(folder, f"two{r}", IMPACTS, "--workers", "2"))
        runs["one_processes"].append(sweep(folder, f"one_processes{r}", IMPACTS, "--workers", "1", "--processes"))
        runs["two_processes"].append(sweep(folder, f"two_processes{r}", IMPACTS, "--workers", "2", "--processes"))
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
                         for name, run in (("two workers", runs["two"][0]),
                                           ("two worker processes", runs["two_processes"][0]),
                                           ("remote", runs["remote"]), ("one worker again", runs["one"][-1]))}
    runs["partitions"] = len(reference[0])
    return runs


def median(values):
    return float(np.median(list(values)))


def met(ok):
    return "yes" if ok else "**no**"


def serial(run):
    """Where one run's time goes: seconds from its start, to its output;
    and its CPU seconds, in all and outside its tasks."""
    m, s = run, run["summary"]
    cpu = m["client_cpu"] + m["workers_cpu"]
    return dict(total=m["output_ends"], start=m["tasks_begins"], cluster=m["connect_ends"] - m["connect_begins"],
                tasks=m["tasks_ends"] - m["tasks_begins"], inside=s["task_seconds"],
                statistics=s["statistics_seconds"],
                writing=m["output_ends"] - m["tasks_ends"] - s["statistics_seconds"],
                cpu=cpu, cpu_outside=cpu - s["task_cpu_seconds"])


def figures(runs):
    """The measured figures, by name: medians over the rounds."""
    f = {}
    f["core"] = IMPACTS / median(c["wall"] for c in runs["core"])
    f["core_cpu"] = IMPACTS / median(c["cpu"] for c in runs["core"])
    f["core_one"] = IMPACTS / median(c["one"] for c in runs["core_threads"])
    f["core_two"] = IMPACTS / median(c["two"] for c in runs["core_threads"])
    for name in ("one", "two", "one_processes", "two_processes"):
        f[name] = {key: median(serial(r)[key] for r in runs[name]) for key in serial(runs[name][0])}
    for name in ("large_one", "large_two"):
        f[name] = serial(runs[name])
    f["one_rate"], f["two_rate"] = IMPACTS / f["one"]["total"], IMPACTS / f["two"]["total"]
    f["large_rate"], f["large_two_rate"] = LARGE / f["large_one"]["total"], LARGE / f["large_two"]["total"]
    f["ratio"], f["large_ratio"] = f["one_rate"] / f["core"], f["large_rate"] / f["core"]
    f["cpu_ratio"] = IMPACTS / f["one"]["cpu"] / f["core_cpu"]
    f["large_cpu_ratio"] = LARGE / f["large_one"]["cpu"] / f["core_cpu"]
    f["speedup"], f["large_speedup"] = f["one"]["total"] / f["two"]["total"], \
        f["large_one"]["total"] / f["large_two"]["total"]
    f["fraction"] = 1 - f["one"]["inside"] / f["one"]["total"]
    f["large_fraction"] = 1 - f["large_one"]["inside"] / f["large_one"]["total"]
    f["cpu_fraction"] = f["one"]["cpu_outside"] / f["one"]["cpu"]
    f["large_cpu_fraction"] = f["large_one"]["cpu_outside"] / f["large_one"]["cpu"]
    f["rss_small"], f["rss_large"] = runs["small_two"]["rss"], runs["large_two"]["rss"]
    f["library_cpu"] = median(r["summary"]["library_cpu_seconds"] for r in runs["one"]) / IMPACTS
    f["task_cpu"] = median(r["summary"]["task_cpu_seconds"] for r in runs["one"]) / IMPACTS
    f["identical"] = all(runs["identical"].values())
    return f


def load_text(load):
    return f"1-minute load average {min(load):.2f} to {max(load):.2f}, median {np.median(load):.2f}, sampled every 10 s"


def lines(runs, f, load, head, minutes):
    one, large = f["one"], f["large_one"]
    amdahl = 1 / (f["fraction"] + (1 - f["fraction"]) / 16)
    large_amdahl = 1 / (f["large_fraction"] + (1 - f["large_fraction"]) / 16)
    return [
        "# The sweep at scale", "",
        "Regenerate: `scripts/report sweep_scaling` (this run: "
        f"{minutes:.0f} minutes). Measured side by side in one run on commit {head}, on "
        f"{platform.processor() or platform.machine()} ({platform.system()}, {os.cpu_count()} cores shared with "
        f"other work: {load_text(load)}). Medians of {REPEATS} rounds, each the C core's timing then `fraccontact "
        "sweep` on 1 and 2 local workers, threads (the default) and processes (`--processes`); on this shared "
        "machine a wall time moves with the other work, the CPU times and the ratios within a round less.", "",
        "The campaign: `fraccontact sweep --monte-carlo N " + " ".join(SETTING) + "` (the error-controlled "
        "setting of a calibration campaign: law 2, `tolerance` 3e-8, `dt_max` 1e-3), its statistics and "
        "histograms included, Parquet only. End to end: from the command's first statement (the interpreter "
        "up: Python's own start excluded) to its outputs in place. The C core: `fc_run_batch` timed around "
        "each call, in one thread of the report's process, on the same cases in the same tasks. In CPU: the "
        "impacts per CPU second of the whole command (its process and its children) against the C core's.", "",
        "| what | measured | against | ratio | target | met |", "|---|---|---|---|---|---|",
        f"| one worker, {IMPACTS:,} impacts, end to end: impacts/s | {f['one_rate']:,.0f} | C core: "
        f"{f['core']:,.0f} | {100 * f['ratio']:.0f} % | >= 90 % | {met(f['ratio'] >= 0.9)} |",
        f"| one worker, {IMPACTS:,} impacts, end to end: impacts per CPU second | {IMPACTS / one['cpu']:,.0f} | "
        f"C core: {f['core_cpu']:,.0f} | {100 * f['cpu_ratio']:.0f} % | | |",
        f"| one worker, {IMPACTS:,} impacts, in the tasks (first given to last done): impacts/s | "
        f"{IMPACTS / one['tasks']:,.0f} | C core: {f['core']:,.0f} | {100 * IMPACTS / one['tasks'] / f['core']:.0f} % "
        "| | |",
        f"| one worker, {LARGE:,} impacts, end to end: impacts/s | {f['large_rate']:,.0f} | C core: "
        f"{f['core']:,.0f} | {100 * f['large_ratio']:.0f} % | >= 90 % | {met(f['large_ratio'] >= 0.9)} |",
        f"| one worker, {LARGE:,} impacts, end to end: impacts per CPU second | {LARGE / large['cpu']:,.0f} | "
        f"C core: {f['core_cpu']:,.0f} | {100 * f['large_cpu_ratio']:.0f} % | | |",
        f"| two workers, {IMPACTS:,} impacts, end to end: impacts/s | {f['two_rate']:,.0f} | one worker: "
        f"{f['one_rate']:,.0f} | {f['speedup']:.2f}x | >= 1.9x | {met(f['speedup'] >= 1.9)} |",
        f"| two workers, {IMPACTS:,} impacts, in the tasks: impacts/s | {IMPACTS / f['two']['tasks']:,.0f} | one "
        f"worker: {IMPACTS / one['tasks']:,.0f} | {one['tasks'] / f['two']['tasks']:.2f}x | | |",
        f"| two workers, {LARGE:,} impacts, end to end: impacts/s | {f['large_two_rate']:,.0f} | one worker: "
        f"{f['large_rate']:,.0f} | {f['large_speedup']:.2f}x | >= 1.9x | {met(f['large_speedup'] >= 1.9)} |",
        f"| the C core itself on two threads at once (the tasks' inputs drawn beforehand, no Dask): impacts/s | "
        f"{f['core_two']:,.0f} | one thread: {f['core_one']:,.0f} | {f['core_two'] / f['core_one']:.2f}x | | |",
        f"| serial fraction, one worker, {IMPACTS:,} impacts: time outside the tasks / end to end | "
        f"{one['total'] - one['inside']:.2f} s | {one['total']:.2f} s | {100 * f['fraction']:.1f} % | <= 2 % | "
        f"{met(f['fraction'] <= 0.02)} |",
        f"| serial fraction, one worker, {IMPACTS:,} impacts, in CPU: CPU outside the tasks / the command's CPU | "
        f"{one['cpu_outside']:.2f} s | {one['cpu']:.2f} s | {100 * f['cpu_fraction']:.1f} % | | |",
        f"| serial fraction, one worker, {LARGE:,} impacts | {large['total'] - large['inside']:.2f} s | "
        f"{large['total']:.2f} s | {100 * f['large_fraction']:.1f} % | <= 2 % | {met(f['large_fraction'] <= 0.02)} |",
        f"| serial fraction, one worker, {LARGE:,} impacts, in CPU | {large['cpu_outside']:.2f} s | "
        f"{large['cpu']:.2f} s | {100 * f['large_cpu_fraction']:.1f} % | | |",
        f"| client's peak RSS (its process, the worker threads in it), {LARGE:,} impacts against {SMALL:,} (2 "
        f"workers) | {f['rss_large'] / 1e6:.0f} MB | {f['rss_small'] / 1e6:.0f} MB | "
        f"{f['rss_large'] / f['rss_small']:.2f}x | <= 2x | {met(f['rss_large'] <= 2 * f['rss_small'])} |",
        "", "Threads against processes (`--processes`), end to end, "
        f"{IMPACTS:,} impacts: one worker {one['total']:.2f} s against {f['one_processes']['total']:.2f} s "
        f"(starting the cluster: {one['cluster']:.2f} s against {f['one_processes']['cluster']:.2f} s), two workers "
        f"{f['two']['total']:.2f} s against {f['two_processes']['total']:.2f} s; CPU, one worker: "
        f"{one['cpu']:.2f} s against {f['one_processes']['cpu']:.2f} s.", "",
        f"Where the one-worker time goes ({IMPACTS:,} impacts, medians): {one['start']:.2f} s before the first "
        f"task (imports, the options, {one['cluster']:.2f} s starting the local cluster), {one['tasks']:.2f} s of "
        f"tasks ({one['inside']:.2f} s inside them: their inputs, the library calls, the Parquet files and the "
        f"statistics' summaries), {one['statistics']:.3f} s turning the merged summaries into the statistics, "
        f"{one['writing']:.2f} s writing the plot and sweep.json. With a serial fraction s, Amdahl's law allows "
        f"1 / (s + (1 - s) / 16) = {amdahl:.1f}x on 16 workers at this size, {large_amdahl:.1f}x at "
        f"{LARGE:,} impacts. The C core's CPU per impact: {1e6 / f['core_cpu']:.2f} µs; in the worker's tasks, the "
        f"library calls' {1e6 * f['library_cpu']:.2f} µs and the whole tasks' {1e6 * f['task_cpu']:.2f} µs (the "
        f"inputs, the batches, the Parquet file, the summaries: {100 * (f['task_cpu'] / f['library_cpu'] - 1):.1f} % "
        f"more); the whole one-worker command's CPU: {1e6 * one['cpu'] / IMPACTS:.2f} µs an impact.", "",
        "Bit for bit: the Parquet partitions ({} files) and the statistics of the one-worker run are the same "
        "bytes as those of {}.".format(runs["partitions"], ", ".join(
            f"{name} ({'identical' if same else '**different**'})" for name, same in runs["identical"].items()))
        + f" The remote cluster: `dask scheduler` and `dask worker --nworkers {REMOTE_WORKERS} --nthreads 1` "
        "started as processes on the loopback address.", "",
        f"Not measured: 4, 8 and 16 workers' throughput, no machine with that many cores being at hand (this one "
        f"has {os.cpu_count()}; 4 workers ran above for the bit-for-bit check only, sharing them)."]


def benchmark_section(f, load, head):
    """The sweep's targets for docs/benchmarks.md, from the same figures."""
    return [
        SWEEP_BEGIN, "## The sweep at scale", "",
        f"From [sweep_scaling.md](sweep_scaling.md) (`scripts/report sweep_scaling`, commit {head}, "
        f"{os.cpu_count()} cores shared with other work: {load_text(load)}): `fraccontact sweep --monte-carlo N "
        + " ".join(SETTING) + "`, end to end (Python's own start excluded), against the C core's single-thread "
        "throughput on the same cases.", "",
        "| target | measured | met |", "|---|---|---|",
        f"| one worker, >= 90 % of the C core's throughput: {IMPACTS:,} impacts; {LARGE:,} | {100 * f['ratio']:.0f} %; "
        f"{100 * f['large_ratio']:.0f} % (in CPU: {100 * f['cpu_ratio']:.0f} %; {100 * f['large_cpu_ratio']:.0f} %) | "
        f"{met(f['ratio'] >= 0.9)}; {met(f['large_ratio'] >= 0.9)} |",
        f"| two workers >= 1.9x one: {IMPACTS:,} impacts; {LARGE:,} | {f['speedup']:.2f}x; "
        f"{f['large_speedup']:.2f}x | {met(f['speedup'] >= 1.9)}; {met(f['large_speedup'] >= 1.9)} |",
        f"| serial fraction <= 2 %: {IMPACTS:,} impacts; {LARGE:,} | {100 * f['fraction']:.1f} %; "
        f"{100 * f['large_fraction']:.1f} % | {met(f['fraction'] <= 0.02)}; {met(f['large_fraction'] <= 0.02)} |",
        f"| client's peak RSS, {LARGE:,} impacts within 2x of {SMALL:,} | {f['rss_large'] / f['rss_small']:.2f}x | "
        f"{met(f['rss_large'] <= 2 * f['rss_small'])} |",
        "| the same partitions and statistics, bit for bit, on 1 and 2 workers (threads, processes) and on "
        f"`dask scheduler` + `dask worker` | {'identical' if f['identical'] else '**different**'} | "
        f"{met(f['identical'])} |",
        "| 4, 8 and 16 workers | not measured: no machine with that many cores at hand | |", "", SWEEP_END]


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="sweep_scaling.") as work:
        with LoadWatch() as load:
            runs = measure(pathlib.Path(work))
    head = git(pathlib.Path.cwd(), "rev-parse", "--short", "HEAD")
    f = figures(runs)
    text = lines(runs, f, load.samples, head, (time.perf_counter() - started) / 60)
    atomic.write_text(args.out / "sweep_scaling.md", "\n".join(text) + "\n")
    replace_section(args.out / "benchmarks.md", benchmark_section(f, load.samples, head), SWEEP_BEGIN, SWEEP_END)
    say(f"wrote {args.out / 'sweep_scaling.md'} and its section of {args.out / 'benchmarks.md'}")
    return 0
