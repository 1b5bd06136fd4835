"""A test's work run in a child Python process under a time limit, for work
that must return within seconds and would otherwise hang the suite: the
child calls module.child(argument) from this folder and prints its results
as JSON on its last line."""

import json
import pathlib
import subprocess
import sys

import pytest

TESTS = pathlib.Path(__file__).resolve().parent


def child_results(module, argument, limit_s, late):
    """module.child(argument)'s results from a child process; the test fails
    with `late` if the child runs past limit_s seconds."""
    code = f"import sys; sys.path.insert(0, {str(TESTS)!r}); import {module}; {module}.child({argument!r})"
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=limit_s)
    except subprocess.TimeoutExpired:
        pytest.fail(late)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])
