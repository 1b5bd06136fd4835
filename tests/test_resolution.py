"""Whether fixed steps resolve an impact (model/resolution.c): a
striker too small for the fixed step of 1e-7 s has its steps refined in
contact (against GSL's reference, with no energy created, the same in the
library, the solver and the FMU), and a uniform grid that cannot shorten
its step is refused."""

import json

import pytest
from fmpy.fmi1 import FMICallException

import fraccontact
from closed_forms import EPS
from test_fmu_features import reference
from test_solver import solve

V0 = 0.626418  # the h20 striker's speed, the library's and the FMU's default


# A fixed step that does not resolve the impact is refined to 4000 in the
# time the spring takes to stop the striker, about 1/11 800 of the elastic
# contact time t_c: h/t_c = 8.5e-5. SDIRK2's errors there, from the
# constants the stability study measures (docs/stability.md, C2 and D1,
# twice the largest measured): the Hertz law 0.62 (h/t_c)^2 in eps, 0.3
# (h/t_c)^2 relative in F_peak; the G1 law with N = steps since onset
# 1.2 h/t_c in eps, 0.55 h/t_c in F_peak (first order).
H_OVER_TC = 8.5e-5


@pytest.mark.parametrize("m", [1e-12, 1e-9])
@pytest.mark.parametrize("law", ["g1", "hertz"])
def test_a_tiny_striker_against_the_reference(law, m):
    """impact(m=1e-12, law=2) gave eps 0.7071 (a 22 ns contact under 100 ns
    steps; GSL: 0.99999996): the contact is now resolved, eps within the
    scheme's error of GSL's."""
    r = fraccontact.impact(m=m, law=law)
    ref = reference("--m", m)
    first = law == "g1"
    eps_error = 1.2 * H_OVER_TC if first else 0.62 * H_OVER_TC ** 2
    force_error = 0.55 * H_OVER_TC if first else 0.3 * H_OVER_TC ** 2
    assert r.eps == pytest.approx(ref["eps"], abs=eps_error, rel=0)
    assert r.F_peak == pytest.approx(ref["F_peak"], rel=force_error, abs=0)
    assert r.eps <= 1.0


@pytest.mark.parametrize("m", [1e-100, 1e-50])
def test_a_vanishing_striker_creates_no_energy(m):
    """m = 1e-100 gave eps = sqrt(2), 1e-50 1.298: the whole impact inside
    one step of 1e-7 s. The default law (G1, dissipative) now stays below 1
    by its first-order error at most, and the rebound's kinetic energy
    plus what the dashpot took never exceeds the impact energy; the Hertz
    law comes within SDIRK2's documented gain in nearly elastic impacts,
    0.42 (h/t_c)^2.5 (tests/test_contact.c, test_elastic_limit)."""
    g1 = fraccontact.impact(m=m)
    assert 1.0 - 1.2 * H_OVER_TC <= g1.eps <= 1.0
    assert 0.5 * m * (g1.eps * V0) ** 2 + g1.E_diss <= 0.5 * m * V0 ** 2 * (1 + 4 * EPS)
    hertz = fraccontact.impact(m=m, law="hertz")
    assert hertz.eps - 1.0 <= 0.42 * H_OVER_TC ** 2.5


def test_the_solver_and_the_fmu_resolve_a_vanishing_striker(slave):
    """The same run in the solver (which warns, naming dt_max, that its
    steps were refined) and in the FMU (the same model: the same eps to
    rounding over the contact's steps)."""
    done = solve("--m", 1e-100, "--json")
    assert done.returncode == 0
    assert json.loads(done.stdout)["eps"] <= 1.0
    assert "warning" in done.stderr and "dt_max" in done.stderr and "m = 1e-100" in done.stderr
    library = fraccontact.impact(m=1e-100)
    s = slave(m=1e-100)
    while s.get("eps") == 0.0 and s.t < 1e-3:
        s.step(1e-5)
    assert s.get("eps") == pytest.approx(library.eps, rel=4 * EPS * library.steps, abs=0)
    assert any(status == 1 and "dt_max" in message for status, _, message in s.log)


def test_a_uniform_grid_that_cannot_resolve_the_impact_is_refused(slave):
    """The central scheme and the full G1 history step on a grid of dt_max
    that cannot shorten: the central scheme gave eps = 1097 at m = 1e-12.
    Refused with the step, the mass and the rule, in the library and in the
    FMU's initialization."""
    with pytest.raises(ValueError, match=r"dt_max = 0 \(fixed steps of 1e-07 s\) is invalid with m = 1e-12"):
        fraccontact.impact(m=1e-12, scheme="central")
    s = slave(start=False, damper=2, memory=1, m=1e-9)
    s.fmu.enterInitializationMode()
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    assert "m = 1e-09" in s.last_error() and "dt_max" in s.last_error()
