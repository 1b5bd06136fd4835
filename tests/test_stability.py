"""The fast subset of the stability matrix (scripts/stability.py; the full
matrix is docs/stability.md): extreme dashpots, foam and steel, 0.1 mm/s to
30 m/s, 1 g to 1 t, steps from 1 ns to longer than the contact, N = 1e6,
rest under gravity, a gap, repeated impacts."""

import os
import pathlib

import pytest

import stability

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVER = pathlib.Path(os.environ.get("FRACCONTACT_SOLVE", ROOT / "build" / "fraccontact-solve"))
CASES = [(name, case) for name, case in stability.matrix() if name in stability.FAST]


def test_the_fast_subset_is_all_there():
    assert len(CASES) == len(stability.FAST)


@pytest.mark.parametrize("law", ["g1", "hertz"])
@pytest.mark.parametrize("name, case", CASES, ids=[name for name, _ in CASES])
def test_case_passes_every_check(name, case, law):
    row = stability.check(SOLVER, case, law)
    assert not row["failures"], row["failures"]
