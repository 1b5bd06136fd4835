"""The README's figures, measured (issue 23, items 27 to 30). Each test finds
its sentence in README.md, reads the figure as written there, and measures it
on this build: a figure that drifts, or a sentence reworded without its test,
fails here. Figures are compared at the precision they are stated with:
"within X" and "up to X" are bounds, held within a decade (a bound ten times
too loose is a stale figure too); a bare "X" is a measurement, equal to the
measured value rounded to X's digits."""

import math
import os
import pathlib
import re

import numpy as np
import pytest
from fmpy import simulate_fmu

import fraccontact

ROOT = pathlib.Path(__file__).resolve().parent.parent
README = " ".join((ROOT / "README.md").read_text().split())  # sentences as one line each
FMU = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))
FIGURES = ("F_peak", "eps", "x2", "E_diss")


def claim(pattern):
    """The README's match of pattern (whitespace as one space): its groups."""
    m = re.search(pattern, README)
    assert m, f"README.md no longer says {pattern!r}: update the sentence's test with it"
    return m.groups()


def number(text):
    return float(text.rstrip(".,;:"))


def assert_bound(measured, stated, what):
    """A stated bound 'within X' / 'up to X': it holds, and not ten times over."""
    assert measured <= stated, f"{what}: measured {measured:.3g}, README says at most {stated:g}"
    assert measured > stated / 10, f"{what}: measured {measured:.3g}, the README's bound {stated:g} is stale"


def assert_figure(measured, stated, what):
    """A stated measurement: the measured value rounded to the README's digits."""
    mantissa = re.sub(r"e.*", "", f"{stated:g}").replace(".", "").lstrip("0")
    digits = max(1, len(mantissa))
    assert float(f"{measured:.{digits - 1}e}") == stated, f"{what}: measured {measured:.3g}, README says {stated:g}"


# --- item 27: the FMU state's size -----------------------------------------------

def test_the_readme_state_sizes_are_the_fmus(slave):
    """fmi2SerializedFMUstateSize through fmpy, at the defaults (the
    springpot's compressed memory) and for the dashpot."""
    springpot, dashpot = map(int, claim(r"fixed size \((\d+) bytes at the defaults, against (\d+) for the dashpot\)"))

    def size(**values):
        s = slave(**values)
        return len(s.fmu.serializeFMUstate(s.fmu.getFMUstate()))

    assert (size(damper=2), size()) == (springpot, dashpot)


# --- item 28: alpha = 1 against the dashpot ----------------------------------------

def drop(stop, **start):
    """Every output of the FMU's drop test at every 10 us."""
    return simulate_fmu(str(FMU), stop_time=stop, output_interval=1e-5, start_values=start)


def relative_difference(a, b, name):
    """Largest difference of an output over the run, relative to its largest value."""
    return float(np.max(np.abs(a[name] - b[name])) / np.max(np.abs(a[name])))


@pytest.mark.parametrize("law", [1, 2])
def test_alpha_1_is_the_dashpot_as_the_readme_says(law):
    """With c_alpha = c: F, v_striker, x1 (and so F_peak, eps) bit for bit at
    every communication point of the impact; x2, E_diss within the README's
    rounding bound; over nine bounces under gravity eps, x2, E_diss within
    its second bound. Independent of either damper's code: the two runs are
    different arithmetic of one model, and MODEL.md §7's springpot at
    alpha = 1 is the dashpot."""
    (first,) = claim(r"`x2` and `E_diss` differ by rounding, within (\S+) over an impact")
    stop, impacts, later = claim(r"bouncing under gravity \((\S+) s, (\w+) impacts\), eps, x2 and E_diss stay within (\S+) of")
    springpot = dict(damper=2, damper_order=1.0, c_alpha=6080.0, memory=2)
    dashpot, alpha_1 = drop(3e-3, law=law), drop(3e-3, law=law, **springpot)
    for name in ("F", "F_avg", "F_peak", "x1", "v_striker", "eps", "semi_integral"):
        assert np.array_equal(dashpot[name], alpha_1[name]), name
    assert_bound(max(relative_difference(dashpot, alpha_1, n) for n in ("x2", "E_diss")), number(first),
                 "x2, E_diss over an impact")
    dashpot, alpha_1 = drop(number(stop), law=law, g=9.81), drop(number(stop), law=law, g=9.81, **springpot)
    eps = [r["eps"][np.r_[True, np.diff(r["eps"]) != 0]][1:] for r in (dashpot, alpha_1)]  # each impact's
    assert len(eps[0]) == len(eps[1]) == {"nine": 9}[impacts]
    worst = max([float(np.max(np.abs(eps[1] / eps[0] - 1)))]
                + [relative_difference(dashpot, alpha_1, n) for n in ("x2", "E_diss")])
    assert_bound(worst, number(later), "eps, x2, E_diss over the bounces")


# --- item 29: the communication step ------------------------------------------------

def figures_at(H, law, stop=4e-3, **start):
    """F_peak, eps, x2, E_diss after the impact, as `fmpy simulate
    --output-interval H` gives them (its steps t_k+1 - t_k included)."""
    r = simulate_fmu(str(FMU), stop_time=stop, output_interval=H, start_values=dict(start, law=law),
                     output=list(FIGURES))
    return np.array([r[name][-1] for name in FIGURES])


def library(law, **start):
    r = fraccontact.impact(law=law, **start)
    return np.array([r.F_peak, r.eps, r.x2_end, r.E_diss])


def spread(rows):
    """The largest relative difference between any two rows, over the figures."""
    rows = np.array(rows)
    return float(np.max((rows.max(axis=0) - rows.min(axis=0)) / np.abs(rows).min(axis=0)))


INTERVALS = (1e-7, 1e-6, 1e-5, 3e-5, 1e-4, 1e-3)  # whole multiples of dt_max = 1e-7 s


def test_the_intervals_are_the_readmes():
    low, high = claim(r"agree to rounding: within \S+ for intervals from (\S+) s to (\S+) ms")
    assert (min(INTERVALS), max(INTERVALS)) == (number(low), number(high) * 1e-3)
    assert claim(r"move with the interval \((\S+) s to (\S+) ms\)") == (low, high)


@pytest.mark.parametrize("law", [1, 2])
def test_contact_on_a_communication_point_gives_the_same_figures_at_every_interval(law):
    (bound,) = claim(r"agree to rounding: within (\S+) for intervals from")
    assert_bound(spread([figures_at(H, law) for H in INTERVALS]), number(bound), f"law {law}, gap0 = 0")


def test_with_a_gap_the_figures_move_within_the_laws_error():
    """The onset falls inside a communication step, and its first internal
    steps end on the next communication point: law 2 moves at its O(h^2)
    error, law 1 at the O(1/N) of its step count, and so far from the
    library, which steps dt_max from the onset."""
    (hertz,) = claim(r"by up to (\S+) with the closed-form Hertz law")
    (g1,) = claim(r"by up to (\S+) with the G1 law \(`law = 1`\)")
    assert "they differ from the library's as much" in README
    for law, stated in ((2, hertz), (1, g1)):
        at = [figures_at(H, law, gap0=1e-3) for H in INTERVALS]
        assert_bound(spread(at), number(stated), f"law {law}, gap0 = 1e-3, across intervals")
        lib = library(law, gap0=1e-3)
        assert max(spread([lib, fmu]) for fmu in at) <= number(stated), f"law {law}: the library"


def test_an_interval_off_the_grid_of_dt_max_moves_the_figures_by_the_laws_error():
    H, hertz, g1 = claim(r"at (\S+) s \(steps of \S+ s\) the figures of the drop test above move from those at "
                         r"1e-5 s by (\S+) with law 2, and by (\S+) with law 1")
    for law, stated in ((2, hertz), (1, g1)):
        moved = spread([figures_at(number(H), law), figures_at(1e-5, law)])
        assert_figure(moved, number(stated), f"law {law} at H = {H}")


def test_a_masters_step_computed_from_its_clock_cuts_no_extra_internal_step(slave):
    """fmpy steps by t_k+1 - t_k, which errs by an ulp of t: past t ~ 1e4 H
    that exceeds a whole multiple of dt_max by more than a relative 1e-12,
    and the FMU cut such a step into two (law 1 then moved by 6e-6 at
    H = 1e-7 s). Steps of exactly H and steps from the clock must give the
    same internal steps: the figures to rounding (a few ulp per step over
    some 2.4e4 steps, 1e-12 leaves room)."""
    H = 1e-7
    exact, clock = slave(law=1, gap0=1e-3), slave(law=1, gap0=1e-3)
    for k in range(round(4e-3 / H)):
        exact.fmu.doStep(currentCommunicationPoint=k * H, communicationStepSize=H)
        clock.fmu.doStep(currentCommunicationPoint=k * H, communicationStepSize=(k + 1) * H - k * H)
    for name in FIGURES:
        assert clock.get(name) == pytest.approx(exact.get(name), rel=1e-12, abs=0), name
