"""Results are written whole or not at all: the reports' helper
(fraccontact/atomic.py) and the solver's CSV, killed in the middle of writing,
leave neither a temporary file nor a half-written result."""

import signal
import subprocess
import sys
import time

import pytest

from fraccontact import atomic
from test_solver import SOLVE


def test_an_interrupted_write_leaves_nothing(tmp_path):
    target = tmp_path / "report.csv"
    with pytest.raises(RuntimeError):
        with atomic.replacing(target) as f:
            f.write("time,F\n0,0\n")
            raise RuntimeError("interrupted")
    assert list(tmp_path.iterdir()) == []


def test_a_finished_write_replaces_the_old_file(tmp_path):
    target = tmp_path / "report.md"
    target.write_text("old")
    atomic.write_text(target, "new")
    assert target.read_text() == "new" and list(tmp_path.iterdir()) == [target]
    assert oct(target.stat().st_mode & 0o777) == "0o644"


def leftovers(directory, target, complete):
    """What a killed writer must not leave: anything beside the target (a
    temporary file), or a target that is not complete."""
    problems = [f"left {p.name}" for p in directory.iterdir() if p != target]
    if target.exists() and not complete(target.read_bytes()):
        problems.append(f"{target.name} is incomplete ({target.stat().st_size} bytes)")
    return problems


# A writer of the reports' kind: it writes its first part, says so on stdout
# and waits for a line on stdin (that never comes) before the rest; the test
# kills it while it waits, inside the write, without sleeping or racing.
WRITER = r'''
import sys
from fraccontact import atomic
target, how = sys.argv[1], sys.argv[2]
with (atomic.replacing(target) if how == "atomic" else open(target, "w")) as f:
    f.write("row\n" * 100000)
    f.flush()
    print("written", flush=True)
    sys.stdin.readline()
    f.write("end\n")
'''


def kill_writer_inside_its_write(tmp_path, how):
    target = tmp_path / "report.txt"
    writer = subprocess.Popen([sys.executable, "-c", WRITER, str(target), how], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    assert writer.stdout.readline() == "written\n"      # the first part is on disk
    writer.send_signal(signal.SIGTERM)
    writer.wait(timeout=30)
    writer.stdin.close()
    writer.stdout.close()
    assert writer.returncode != 0                        # it did not get to finish
    return leftovers(tmp_path, target, lambda text: text.endswith(b"end\n"))


def test_a_report_killed_while_writing_leaves_nothing(tmp_path):
    assert kill_writer_inside_its_write(tmp_path, "atomic") == []
    assert list(tmp_path.iterdir()) == []


def test_the_check_catches_a_writer_that_writes_in_place(tmp_path):
    """The same kill, a writer that writes straight to its target: the
    half-written file is found, so the test above can fail."""
    assert kill_writer_inside_its_write(tmp_path, "in place") == ["report.txt is incomplete (400000 bytes)"]


def wait_for_first_write(directory, process, timeout=300):
    """Polls until some file in directory holds bytes: the writer has begun
    (stdio flushes its first 4 KiB)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for p in directory.iterdir():
            try:
                if p.stat().st_size > 0:
                    return p
            except FileNotFoundError:                    # renamed meanwhile
                pass
        assert process.poll() is None, f"the writer ended (exit {process.returncode}) before writing was seen"
        time.sleep(1e-3)
    pytest.fail(f"nothing written within {timeout} s")


def csv_is_complete(text):
    """The solve stops at the separation: a whole CSV ends with its row,
    F = 0 and x1 = 0, and a newline."""
    if not text.endswith(b"\n"):
        return False
    fields = text.rstrip(b"\n").rsplit(b"\n", 1)[-1].split(b",")
    return len(fields) == 7 and float(fields[1]) == 0.0 and float(fields[3]) == 0.0


def test_a_solver_killed_while_writing_its_csv_leaves_nothing(tmp_path):
    """1.3 million rows (one per internal step of 1 ns; 150 MB, about 2 s
    to write after a 0.2 s solve): the signal goes as soon as the first
    bytes are seen, with seconds of writing left."""
    target = tmp_path / "h20.csv"
    run = subprocess.Popen([SOLVE, "--law", "hertz", "--dt-max", "1e-9", "--output-interval", "0", "--csv", str(target),
                            "--quiet"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    first = wait_for_first_write(tmp_path, run)
    assert first != target                               # written aside first
    run.send_signal(signal.SIGTERM)
    run.wait(timeout=30)
    run.stderr.close()
    assert run.returncode != 0                           # killed before it finished
    assert leftovers(tmp_path, target, csv_is_complete) == []
