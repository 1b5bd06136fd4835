"""The sweep and the process that runs it: a
program that calls sweep.main keeps its malloc settings, its SIGTERM
handler and its log, and the local workers close without an error in the
log. Each runs in a process of its own: malloc's settings are the
process's, and the workers' log is its stderr."""

import json
import os
import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                                reason="Dask workers under a preloaded sanitizer runtime")

GRID = ["--vary", "c=3000,6080", "--set", "law=hertz"]

# glibc's malloc serves a request of at least its mmap threshold with a
# mapping of its own (mallinfo2's hblks counts them). The threshold starts
# at 128 KiB and rises to the size of each mapped chunk freed, up to 32 MiB;
# mallopt(M_MMAP_THRESHOLD, 32 MiB), the sweep's setting, fixes it there.
# So a program left alone maps a 24 MiB request (nothing in a small sweep
# frees so large a chunk), and one the sweep's setting reached does not; the
# probe checks that it tells the two apart, by setting it afterwards.
CALLER = textwrap.dedent("""
    import ctypes, json, logging, signal, sys
    from fraccontact import sweep

    class Mallinfo2(ctypes.Structure):
        _fields_ = [(name, ctypes.c_size_t) for name in ("arena", "ordblks", "smblks", "hblks", "hblkhd",
                                                         "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost")]

    libc = ctypes.CDLL(None)
    libc.mallinfo2.restype = Mallinfo2
    libc.malloc.restype = ctypes.c_void_p
    libc.malloc.argtypes = [ctypes.c_size_t]
    libc.free.argtypes = [ctypes.c_void_p]

    def mapped(size):
        before = libc.mallinfo2().hblks
        block = libc.malloc(size)
        after = libc.mallinfo2().hblks
        libc.free(block)
        return after == before + 1

    def handler(signum, frame):
        pass

    signal.signal(signal.SIGTERM, handler)
    log = logging.getLogger("distributed.worker")
    filters = list(log.filters)
    status = sweep.main(sys.argv[1:])
    seen = dict(status=status, handler_kept=signal.getsignal(signal.SIGTERM) is handler,
                log_kept=log.filters == filters, mapped=mapped(24 << 20))
    libc.mallopt(-3, 32 << 20)  # M_MMAP_THRESHOLD, as the sweep of 26f430c set it in this process
    seen["mapped_after_mallopt"] = mapped(28 << 20)
    print(json.dumps(seen))
""")


def test_a_program_that_calls_the_sweep_keeps_its_malloc_and_its_sigterm_handler(tmp_path):
    """The local cluster of threads runs in the caller's process: the sweep
    sets neither malloc's thresholds there (26f430c did, with mallopt, for
    the rest of the program) nor, once it returns, SIGTERM's handler or a
    filter on Dask's log."""
    done = subprocess.run([sys.executable, "-c", CALLER, *GRID, "--workers", "1", "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    seen = json.loads(done.stdout.splitlines()[-1])
    # mapped_after_mallopt: the probe sees the sweep's setting where it is made
    assert seen == dict(status=0, handler_kept=True, log_kept=True, mapped=True, mapped_after_mallopt=False)


# The scheduler (in the sweep's process) answers each heartbeat 3 s late, so
# that a heartbeat is under way whenever a worker closes: the close that, in
# one run in five, logged "Failed to communicate with scheduler during
# heartbeat" and CommClosedError after the results, every time.
LATE_HEARTBEATS = textwrap.dedent("""
    import asyncio, sys
    from fraccontact.sweep import cli

    connect = cli.connect

    def late_heartbeats(args):
        client, cluster = connect(args)
        handlers = cluster.scheduler.handlers
        answer = handlers["heartbeat_worker"]

        async def late(**message):
            reply = answer(**message)
            await asyncio.sleep(3)
            return reply
        handlers["heartbeat_worker"] = late
        return client, cluster

    if __name__ == "__main__":  # the worker processes import this file
        cli.connect = late_heartbeats
        sys.exit(cli.main(sys.argv[1:]))
""")


@pytest.mark.parametrize("local", [["--processes", "--workers", "2"], ["--workers", "2"]],
                         ids=["processes", "threads"])
def test_workers_close_without_an_error_during_a_heartbeat(local, tmp_path):
    script = tmp_path / "late_heartbeats.py"
    script.write_text(LATE_HEARTBEATS)
    done = subprocess.run([sys.executable, str(script), *GRID, *local, "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    assert json.loads(done.stdout.splitlines()[-1])["impacts"] == 2
    for word in ("Traceback", "CommClosedError", "ERROR"):
        assert word not in done.stderr, done.stderr[-3000:]
