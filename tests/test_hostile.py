"""Hostile and degenerate input (scripts/hostile.py, whose report is
docs/reliability_hostile.md), in-process: every case ends in an error with
a message or in a correct run (finite outputs, F >= 0)."""

import pytest

import hostile

CASES = list(hostile.cases())


@pytest.mark.parametrize("name, case", CASES, ids=[name for name, _ in CASES])
def test_hostile_case(slave, name, case):
    r = hostile.run_case_in(slave(start=False), case)
    assert hostile.acceptable(r), r
