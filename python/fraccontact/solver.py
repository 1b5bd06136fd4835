"""The C programs of a build, for what the library does not do in-process:
fraccontact-solve's GSL reference (--reference), its CSV and its own timing
(--repeat, cpu_seconds), and fraccontact-bench. The reports call them here;
$FRACCONTACT_SOLVE names the solver (scripts/report sets it to the build's),
the benchmark program is its neighbour."""

import json
import os
import pathlib
import shutil
import subprocess


class Failed(RuntimeError):
    """A program exited with an error or printed no JSON; the message says
    the command and what it wrote on stderr."""


def solve_path():
    """$FRACCONTACT_SOLVE, else fraccontact-solve on PATH."""
    path = os.environ.get("FRACCONTACT_SOLVE") or shutil.which("fraccontact-solve")
    if not path:
        raise Failed("fraccontact-solve not found: set FRACCONTACT_SOLVE to a build's (scripts/report does)")
    return pathlib.Path(path)


def bench_path(solve=None):
    """fraccontact-bench, beside the solver."""
    return pathlib.Path(solve or solve_path()).with_name("fraccontact-bench")


def run_json(program, *args, timeout=None):
    """program's JSON output, run with args (numbers as Python writes them)."""
    command = [str(program), *map(str, args)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        raise Failed(f"{' '.join(command)} failed: {done.stderr.strip()}")
    try:
        return json.loads(done.stdout)
    except json.JSONDecodeError:
        raise Failed(f"{' '.join(command)}: not JSON (a non-finite number?): {done.stdout[:200]}") from None


def solve(*args, program=None, timeout=None):
    """fraccontact-solve --json --quiet with args: its JSON object."""
    return run_json(program or solve_path(), *args, "--json", "--quiet", timeout=timeout)
