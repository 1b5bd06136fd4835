"""What the dashpot and the springpot studies share: the paper's h20 test
they start from, what rounding alone allows, when a step resolves a time
scale, how long a run lasts, how a run's failures are judged against the
findings listed for it, and how a matrix is worked through."""

import math
import sys

from tqdm import tqdm

from fraccontact import model

from .. import BAR

H20 = model.defaults()
MAX_STEPS = 4e7  # per run: keeps the matrix to minutes
ULP = sys.float_info.epsilon
# Rounding: a step rounds each of v, x1, x2 and E_diss once or twice, at most
# half an ulp of the value each time, and an energy (1/2 m v^2) doubles v's
# relative error, so 4 ulp per step bounds what rounding alone can
# accumulate in any figure relative to its scale, in the worst case where
# every rounding goes the same way.
ROUNDING_ULPS = 4
# A time scale T is resolved when dt <= T / RESOLVED: then the error
# expansion C (dt/T)^2 holds (the convergence studies start there).
RESOLVED = 20
ENERGY = "no energy created"
EPS = "0 <= eps <= 1"


def rounding(steps):
    """What rounding alone may accumulate over that many steps, relative to
    a figure's scale (ROUNDING_ULPS per step)."""
    return ROUNDING_ULPS * ULP * (steps + 4)


def t_end_of(case, t_c, capped=True):
    """Long enough for the impacts (flights under gravity included), short
    enough for MAX_STEPS (unless not capped), and at least a few steps."""
    t = 20 * t_c
    if case["g"] > 0:
        t = max(t, 4 * (case["v0"] + math.sqrt(2 * case["g"] * case["gap0"])) / case["g"] * case["impacts"] + 1.0)
    return max(min(t, MAX_STEPS * case["dt"]), 5 * case["dt"]) if capped else t


def judge(row, known, stale):
    """row['failures'] from row['checks'] (check -> '' pass, failure text,
    or None: not applicable); given the checks known to fail for the run
    (None: no run name, nothing listed), row['known'] the failures listed
    and row['unexpected'] the others and the listed ones that no longer
    fail, each with stale, what to do about it."""
    row["failures"] = [f"{c}: {t}" for c, t in row["checks"].items() if t]
    if known is None:
        return
    failed = {c for c, t in row["checks"].items() if t}
    row["known"] = sorted(failed & known)
    row["unexpected"] = [f"{c}: {row['checks'][c]}" for c in sorted(failed - known)]
    row["unexpected"] += [f"{stale[0]}: {c} {stale[1]}" for c in sorted(known - failed)]


def over(items, fast, chosen, what, each):
    """each(name, case), a list, for the (name, case) items (with fast only
    those named in chosen), with a progress bar saying what and the name;
    the lists joined."""
    items = [(n, c) for n, c in items if not fast or n in chosen]
    out = []
    with tqdm(items, file=sys.stderr, disable=None, bar_format=BAR) as bar:
        for name, case in bar:
            bar.set_description(what + name)
            out += each(name, case)
    return out


def check_table(rows, checks):
    """The summary's table: for each check, the runs it applied to, passed and failed."""
    lines = ["| check | runs checked | pass | fail |", "|---|---|---|---|"]
    for c in checks:
        checked = [o for o in (r["checks"].get(c) for *_, r in rows) if o is not None]
        lines.append(f"| {c} | {len(checked)} | {sum(1 for o in checked if not o)} | {sum(1 for o in checked if o)} |")
    return lines
