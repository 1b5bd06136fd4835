"""The local cluster's workers, the sweep's own: the settings its worker
processes (--processes) start with, and what a worker logs as it closes.
Nothing of it stays in the process that runs the sweep, which may be any
program."""

import logging

from distributed import WorkerPlugin
from distributed.core import Status

# glibc's malloc settings in the worker processes: arrays below
# MALLOC_MMAP_THRESHOLD_ from its heap, and up to MALLOC_TRIM_THRESHOLD_ of
# freed memory kept there. Otherwise a task's arrays, freed, go back to the
# system and the next task's come in fresh pages, each a fault: system time
# in every task. Set in the environment a worker process starts with (in
# place of the MALLOC_TRIM_THRESHOLD_ Dask's nanny would set), never by
# mallopt in the sweep's process: a program that calls the sweep keeps its
# own malloc.
MALLOC = {"MALLOC_MMAP_THRESHOLD_": 32 << 20, "MALLOC_TRIM_THRESHOLD_": 64 << 20}
# The workers' log, and what it says when a heartbeat fails.
LOG = logging.getLogger("distributed.worker")
HEARTBEAT_FAILED = "Failed to communicate with scheduler during heartbeat."


def environment():
    """Dask's configuration that starts each worker process with MALLOC."""
    return {f"distributed.nanny.pre-spawn-environ.{name}": value for name, value in MALLOC.items()}


class ClosingHeartbeat(logging.Filter):
    """Drops the error a worker logs when it closes with a heartbeat under
    way: its close stops the heartbeats, then closes its connections, the
    one a heartbeat already sent waits on among them, and that heartbeat
    fails (CommClosedError: Stream is closed) after the sweep's results.
    A heartbeat that fails while the worker runs is logged as before."""

    def __init__(self, worker):
        super().__init__()
        self.worker = worker

    def filter(self, record):
        return not (record.msg == HEARTBEAT_FAILED and self.worker.status in (Status.closing, Status.closed))


class QuietClose(WorkerPlugin):
    """A ClosingHeartbeat on the log of each worker."""

    name = "fraccontact-quiet-close"

    def setup(self, worker):
        LOG.addFilter(ClosingHeartbeat(worker))


def forget():
    """Takes the ClosingHeartbeats off this process's log, once its
    workers (a local cluster of threads) have closed."""
    for kept in [f for f in LOG.filters if isinstance(f, ClosingHeartbeat)]:
        LOG.removeFilter(kept)
