"""The CPU time a child process uses: what tests that bound how long a
process works measure, the same whatever else the machine runs."""

import os
import time


def cpu_seconds(pid):
    """The CPU time a running process has used so far: /proc's utime and stime (fields 14 and 15)."""
    with open(f"/proc/{pid}/stat") as f:
        return sum(int(x) for x in f.read().rsplit(")", 1)[1].split()[11:13]) / os.sysconf("SC_CLK_TCK")


def reaped(p, timeout):
    """Waits up to timeout [s] (the clock's) for the subprocess.Popen p to end;
    its total CPU time [s] (user and system), or None if it still runs."""
    deadline = time.monotonic() + timeout
    while True:
        pid, status, usage = os.wait4(p.pid, os.WNOHANG)
        if pid:
            p.returncode = os.waitstatus_to_exitcode(status)
            return usage.ru_utime + usage.ru_stime
        if time.monotonic() > deadline:
            return None
        time.sleep(0.01)
