"""Results are written whole or not at all: the reports' helper and the
solver's CSV, interrupted, leave no complete-looking file."""

import os
import signal
import subprocess
import time

import pytest

import atomic
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


def test_a_killed_solver_leaves_no_csv(tmp_path):
    """A run that would take minutes, killed after a moment."""
    target = tmp_path / "long.csv"
    run = subprocess.Popen([SOLVE, "--law", "hertz", "--c", "0.01", "--dt", "1e-9", "--t-end", "10",
                            "--csv", str(target), "--output-interval", "1e-4", "--quiet"])
    time.sleep(0.5)
    run.send_signal(signal.SIGTERM)
    run.wait(timeout=30)
    assert run.returncode != 0
    assert not target.exists()
    assert [p.name for p in tmp_path.iterdir() if not p.name.endswith(".tmp")] == []
