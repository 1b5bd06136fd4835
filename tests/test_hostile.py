"""Hostile and degenerate input (reports/hostile.py, whose report is
docs/reliability_hostile.md), in-process: every case reaches the verdict it
states, refused (when set, at initialization or by the step: fmi2Error, a
message naming the variable and value, the old value or state kept, the
instance usable) or run (finite outputs, F >= 0, agreeing with the GSL
reference, scipy, a closed form or the physical identities, at the
tolerances derived in reports/hostile.py)."""

import copy

import pytest

from reports import hostile
from test_solver import SOLVE

CASES = list(hostile.cases())
RUNS = [(name, case) for name, case in CASES if hostile.verdict_of(case) == hostile.RUNS]
REFUSED = [(name, case) for name, case in CASES if hostile.verdict_of(case) != hostile.RUNS]


@pytest.mark.parametrize("name, case", CASES, ids=[name for name, _ in CASES])
def test_hostile_case(slave, name, case):
    r = hostile.run_case_in(slave(start=False), case)
    j = hostile.judge(name, case, r, SOLVE)
    assert not j.failures, (j.failures, r["observed"], r["message"])


def test_every_case_states_a_verdict_and_how_it_is_checked():
    assert len(CASES) == 92
    for name, case in CASES:
        assert case["expect"] in (hostile.REFUSED_SET, hostile.REFUSED_INIT, hostile.REFUSED_STEP) \
            or case["expect"] in hostile.CHECKS, name
        assert ("names" in case) == (hostile.verdict_of(case) != hostile.RUNS), name


@pytest.mark.parametrize("name, case", RUNS, ids=[name for name, _ in RUNS])
def test_a_wrong_run_fails_its_check(slave, name, case):
    """The checks can fail: the same run with every output at its last
    communication point 5 % off (beyond the loosest tolerance, 3.1 %) and
    every 0 made 1e-30 is rejected."""
    r = hostile.run_case_in(slave(start=False), case)
    wrong = copy.deepcopy(r)
    if wrong["trace"]:
        last = wrong["trace"][-1]
        for key in hostile.OUTPUTS:
            last[key] = last[key] * 1.05 + 1e-30
    assert hostile.judge(name, case, wrong, SOLVE).failures


@pytest.mark.parametrize("name, case", REFUSED, ids=[name for name, _ in REFUSED])
def test_a_wrong_refusal_fails_its_check(name, case):
    """A refusal must name the value, keep the old one and leave the
    instance usable: an observation lacking any one of them is rejected."""
    var, value = case["names"]
    right = dict(observed=hostile.verdict_of(case), message=f"{var} = {value:g} is invalid", kept=True,
                 usable=True, trace=[], warnings=[])
    assert not hostile.judge(name, case, right, SOLVE).failures
    for wrong in (dict(message=f"{var} is invalid"), dict(message=f"{var} = 42 is invalid"), dict(kept=False),
                  dict(usable=False), dict(observed=hostile.RUNS)):
        assert hostile.judge(name, case, {**right, **wrong}, SOLVE).failures, wrong
