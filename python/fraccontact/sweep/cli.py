"""fraccontact sweep: the options checked, a Dask cluster, the tasks given a
window at a time and their summaries folded on the workers (the
statistics' among them), then the CSV when asked, the plot and
sweep.json."""

import contextlib
import importlib
import json
import math
import os
import signal
import sys
import threading
import time

from tqdm import tqdm

from .. import atomic
from . import cases, options, outputs, stats, tasks

# Results folded together on a worker at a time: a tree of summaries
# rather than a list on the client.
FAN_IN = 8
# The local cluster's settings. Dask's profiler samples every thread's stack
# every few milliseconds, for a profile nobody reads here; its event loop's
# tick, its system monitor and its memory monitor wake many times a second:
# CPU beside the tasks, taken from them when they occupy every core, and
# growing with the campaign. A few wakes a second suffice here.
QUIET = {"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "1s",
         "distributed.admin.system-monitor.interval": "5s", "distributed.worker.memory.monitor-interval": "1s"}
# Tasks given to the cluster at once, for each of its threads: enough to
# keep every thread busy while the client hears of a finished one.
WINDOW = 2


def connect(args):
    """(client, cluster): a Dask client of the scheduler at --scheduler
    (cluster None), refused in one line when none answers there within
    CONNECT_TIMEOUT, or of a local cluster: one worker of --workers threads
    in the process that runs the sweep (the library's calls and pyarrow's
    writes release the GIL, and nothing is copied between processes), or
    --workers processes of one thread with --processes (workers.py)."""
    import dask
    from dask.distributed import Client, LocalCluster
    if not args.scheduler:
        count = args.workers or options.cpus()
        # No dashboard; the scheduler's HTTP server (its metrics) on a free
        # port of the loopback, not on 8787, which another cluster may hold.
        quiet = dict(dashboard_address=None, scheduler_kwargs=dict(dashboard_address="127.0.0.1:0"))
        from . import workers
        with dask.config.set(QUIET):
            if args.processes:
                with dask.config.set(workers.environment()):
                    cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True, **quiet)
            else:
                cluster = LocalCluster(n_workers=1, threads_per_worker=count, processes=False, **quiet)
            client = Client(cluster)
        client.register_plugin(workers.QuietClose())
        return client, cluster
    try:
        return Client(args.scheduler, timeout=options.CONNECT_TIMEOUT), None
    except ValueError as e:  # an address Dask cannot parse
        raise ValueError(f"--scheduler {args.scheduler}: {e}") from None
    except OSError:
        raise ValueError(f"--scheduler {args.scheduler}: no Dask scheduler answered there within "
                         f"{options.CONNECT_TIMEOUT:g} s") from None


def fold(client, calls, combine, window, done=None):
    """Runs calls ((weight, function, *args) each) on the cluster, at most
    window() of them at once (asked again as each ends: workers may come
    and go), and folds their results with combine, FAN_IN at a time, on the
    workers; returns the future of the whole fold. done(weight) is told of
    each call finished. A call that failed (after Dask's retries, where its
    worker died) raises here."""
    from dask.distributed import as_completed
    calls = iter(calls)
    running = as_completed()
    weights = {}  # the running futures' weights, None for a fold

    def submit(function, *args, weight=None):
        future = client.submit(function, *args, pure=False)
        weights[future.key] = weight
        running.add(future)

    def fill():
        while sum(w is not None for w in weights.values()) < window():
            call = next(calls, None)
            if call is None:
                return
            submit(*call[1:], weight=call[0])

    fill()
    finished = []
    for future in running:
        if future.status == "error":
            future.result()
        weight = weights.pop(future.key)
        if weight is not None:
            if done:
                done(weight)
            fill()
        finished.append(future)
        if len(finished) >= FAN_IN or (running.count() == 0 and len(finished) > 1):
            submit(combine, *finished)
            finished = []
    return finished[0]


def window(client):
    """Tasks given to the cluster at once: WINDOW for each of its threads
    (asked of the scheduler at most once a second), and one while it has
    none (it waits for its workers)."""
    known = dict(at=-math.inf, size=1)

    def size():
        if time.monotonic() - known["at"] > 1:
            known.update(at=time.monotonic(), size=WINDOW * max(1, sum(client.nthreads().values())))
        return known["size"]
    return size


def unseen(client, folder):
    """The workers that cannot see the folder (a cluster of machines needs
    --out on a file system they share)."""
    return [w for w, seen in client.run(os.path.isdir, str(folder)).items() if not seen]


def title_of(args, n):
    varied = {name for name, _ in args.vary} | {name for name, _ in args.scatter}
    parts = [f"{n} impacts"] + [f"{k} = {outputs.shown(v)}" for k, v in args.fixed.items() if k not in varied]
    parts += [f"{name} log-normal, CV {100 * cv:g} %" for name, cv in args.scatter]
    return ", ".join(parts)


def simulate(args, client, plan, size, folder):
    """Every task, a window at a time, with Dask's results folded; returns
    the folded summary and the wall time from the first task given to the
    last summary folded."""
    n = plan.cases.n
    calls = ((stop - start, tasks.run, plan, i, start, stop, folder, args.csv)
             for i, start, stop in cases.ranges(n, size))
    with tqdm(total=n, unit=" impacts", unit_scale=True, file=sys.stderr, disable=None, smoothing=0.1) as bar:
        start = time.perf_counter()
        plot_import = PlotImport(args, len(range(0, n, size)))

        def done(weight):
            bar.update(weight)
            plot_import.task_ended()
        summary = fold(client, calls, tasks.merged, window(client), done).result()
        return summary, time.perf_counter() - start


class PlotImport:
    """Imports the plot's library in the background (outputs.preload), once,
    as soon as a CPU of this machine has no task: at once where the workers
    leave one free (a remote cluster, fewer local workers than CPUs), else
    when fewer tasks are left than CPUs. The import keeps a CPU and Python's
    GIL busy: beside tasks on every CPU, it would slow them."""

    def __init__(self, args, count):
        self.cpus = options.cpus()
        self.left = 0 if args.scheduler or (args.workers or self.cpus) < self.cpus else count
        self.started = False
        self.start_if_free()

    def task_ended(self):
        self.left -= 1
        self.start_if_free()

    def start_if_free(self):
        if not self.started and self.left < self.cpus:
            self.started = True
            outputs.preload()


def run(args, client, cluster, plan, size, prog):
    """The sweep on the cluster, its outputs written; its exit status. On
    any error, the cluster is closed, its tasks stopped, before what they
    wrote is removed."""
    staging = outputs.Staging(args.out)
    try:
        blind = unseen(client, staging.folder)
        if blind:
            print(f"{prog}: --out {args.out}: the workers {', '.join(blind)} do not see it (a cluster of machines "
                  "needs --out on a file system they share)", file=sys.stderr)
            staging.discard()
            return 2
        try:
            client.run(importlib.import_module, tasks.__name__)  # every worker loads the library before the clock
        except ImportError as e:
            print(f"{prog}: the workers cannot import the sweep ({e}): install the package where they run (pip "
                  "install '.[sweep]')", file=sys.stderr)
            staging.discard()
            return 2
        summary, wall = simulate(args, client, plan, size, staging.folder)
        count = len(range(0, plan.cases.n, size))
        began = time.perf_counter()
        statistics = stats.statistics(summary["statistics"])
        bins = outputs.histogram_bins(summary["impacts"] - summary["failed"])
        counted = {key: stats.histogram(summary["statistics"][key], bins) for key, *_ in outputs.PLOTTED
                   if key in summary["statistics"]}
        statistics_seconds = time.perf_counter() - began
        written = write(args, plan, staging, count, summary, statistics, counted)
        result = dict(impacts=summary["impacts"], failed=summary["failed"], wall_seconds=wall,
                      impacts_per_second=summary["impacts"] / wall,
                      workers=None if args.scheduler else args.workers or options.cpus(), tasks=count,
                      task_seconds=summary["seconds"], task_cpu_seconds=summary["cpu_seconds"],
                      library_cpu_seconds=summary["library_cpu_seconds"],
                      statistics_seconds=statistics_seconds)
        atomic.write_text(staging.folder / "sweep.json",
                          json.dumps(dict(result, statistics=statistics) if statistics else result) + "\n")
        staging.commit(written | {"sweep.json"})
    except BaseException:
        stop(client, cluster)
        staging.discard()
        raise
    if statistics:
        outputs.print_statistics(statistics)
    print(json.dumps(result))
    for i, inputs, why in summary["errors"]:
        print(f"failed: case {i} ({', '.join(f'{k} = {v}' for k, v in inputs.items())}): {why}", file=sys.stderr)
    return 1 if summary["failed"] else 0


def write(args, plan, staging, count, summary, statistics, counted):
    """sweep.csv (asked for) and sweep.png (a histogram of each plotted result
    for Monte Carlo, or the results against the first varied name for a grid
    of at most PLOT_LIMIT cases); the names written."""
    written = set()
    if args.csv:
        outputs.join_csv((plan.path(staging.folder, i, "csv") for i in range(count)), staging.folder / "sweep.csv")
        written.add("sweep.csv")
    title = title_of(args, summary["impacts"])
    if counted:
        outputs.histograms(staging.folder / "sweep.png", counted, statistics, title)
        written.add("sweep.png")
    elif args.monte_carlo is None and plan.cases.n <= outputs.PLOT_LIMIT:
        outputs.plot(staging.folder / "sweep.png", [plan.path(staging.folder, i, "parquet") for i in range(count)],
                     [name for name, _ in args.vary], title)
        written.add("sweep.png")
    return written


def close(client, cluster):
    client.close()
    if cluster:
        from . import workers
        cluster.close()
        workers.forget()


def stop(client, cluster):
    """Closes the client and the cluster, with a local cluster's threads'
    tasks stopped at their next library call."""
    tasks.STATE["stop"] = True
    try:
        close(client, cluster)
    finally:
        tasks.STATE["stop"] = False


class Terminated(KeyboardInterrupt):
    """SIGTERM (what timeout and batch systems send), raised where the
    signal finds the sweep: the way out Ctrl-C takes."""


def raise_terminated(signum, frame):
    raise Terminated()


@contextlib.contextmanager
def terminated_raises():
    """SIGTERM raises Terminated inside, where a handler can be set (the
    main thread); the program's own handler is restored after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)


def main(argv=None, prog=None):
    parser, args = options.arguments(argv, prog)
    try:
        plan, size, unused = options.prepared(args)
    except ValueError as e:
        parser.error(str(e))
    for why in unused:
        print(f"{parser.prog}: warning: {why}", file=sys.stderr)
    with terminated_raises():
        try:
            return connected(parser, args, plan, size)
        except Terminated:
            print(f"{parser.prog}: terminated (SIGTERM); nothing written", file=sys.stderr)
            return 128 + signal.SIGTERM
        except KeyboardInterrupt:
            print(f"{parser.prog}: interrupted; nothing written", file=sys.stderr)
            return 130


def connected(parser, args, plan, size):
    """The sweep on the cluster connect() gives, closed at the end; its exit
    status."""
    try:
        client, cluster = connect(args)
    except ValueError as e:
        parser.error(str(e))
    from distributed import KilledWorker
    try:
        return run(args, client, cluster, plan, size, parser.prog)
    except OSError as e:
        print(f"{parser.prog}: --out {args.out}: cannot write the results: {e.strerror or e}", file=sys.stderr)
        return 2
    except KilledWorker as e:
        print(f"{parser.prog}: a task's workers died, each in turn ({e}); nothing written", file=sys.stderr)
        return 1
    finally:
        close(client, cluster)
