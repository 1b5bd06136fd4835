"""The scenes' monolithic references (fraccontact.scenes) against what they
must satisfy whatever their parameters: the energy and momentum balances,
the reduced-mass identity of two free bodies (against the in-process
library's single-body impact), the elastic Hertz limit's HIC ~ m^-0.6 v^2.8
(Hutchinson 2013), the least stopping distance for a given HIC; and their
parameters against the table their module states."""

import math

import numpy as np
import pytest

import fraccontact
from fraccontact import crash, hertz
from fraccontact.scenes import bumper, headform, parameters
from fraccontact.scenes.chain import GROUND, Chain, Contact, Link

K, C = 329.9e6, 6080.0          # the paper's h20 polypropylene (docs/model.md §1)


def two_free_bodies(m1, m2, v):
    """m1 at v strikes m2 at rest through the contact: F_peak, eps (of the
    approach speed), t_contact, x2_end; and the run's balances."""
    m = m1 * m2 / (m1 + m2)
    body = Chain([m1, m2], [v, 0.0], contacts=[Contact(0, 1, K, C)])
    run = body.solve(3 * hertz.contact_time(K, m, v), length=hertz.indentation(K, m, v), rtol=1e-12)
    end = next(t for t, _, kind in run.events if kind == "separation")
    t = np.linspace(0.0, end, 200001)
    y = run.y([end])
    return dict(F_peak=float(run.series(t)["F"][0].max()),
                eps=float(-(y[body.V][0, 0] - y[body.V][1, 0]) / v), t_contact=end,
                x2_end=float(y[body.X2][0, 0])), run.balances(t)


@pytest.mark.parametrize("m1, m2, v", [(4.5, 2.0, 2.0), (0.7437, 0.7437, 0.626418)])
def test_two_free_bodies_are_the_single_body_impact_of_the_reduced_mass(m1, m2, v):
    two, (energy, momentum) = two_free_bodies(m1, m2, v)
    one = fraccontact.impact(m=m1 * m2 / (m1 + m2), v=v, k=K, c=C, law="hertz", tolerance=1e-12)
    for name, value in two.items():
        # scipy at rtol 1e-12 and the library's error control at its finest
        # tolerance, 1e-12, whose figures come within about 15 tolerances
        # (docs/numerics.md, "Error-controlled steps"); the peak is taken from 200001
        # samples of the contact (1e-11).
        assert value == pytest.approx(getattr(one, name), rel=1e-9, abs=0), name
    # Equal and opposite forces: the momentum is the integrator's linear
    # invariant, kept to rounding (6e-16 seen); energy to rtol (3e-11 seen).
    assert np.max(np.abs(momentum)) < 1e-13
    assert np.max(np.abs(energy)) < 1e-10


@pytest.mark.parametrize("gap0", [headform.NO_HARD_POINT, 0.05])
def test_headform_reference_keeps_its_energy_and_momentum(gap0):
    r = headform.solve(parameters.ADULT, gap0)
    energy, momentum = r["balances"]
    # kinetic + stored + dissipated = the impact energy to the solver's rtol
    # of 1e-10 (6.5e-10 free, 1e-9 bouncing on the hard point seen); the
    # ground's impulse accounts for the momentum to rounding (3e-15 seen).
    assert energy < 1e-8
    assert momentum < 1e-13
    assert r["head_travel"] > r["panel_deflection"] > 0
    if math.isfinite(gap0):
        assert r["panel_deflection"] == pytest.approx(gap0, rel=0.05, abs=0)   # stopped by the hard point
        assert r["F_hard"].max() > r["F_skin"].max()


def test_bumper_reference_keeps_its_energy_and_momentum():
    r = bumper.solve()
    energy, momentum = r["balances"]
    assert energy < 1e-8            # 1.2e-11 seen at rtol 1e-10
    assert momentum < 1e-13         # 2e-15 seen
    assert r["crush"] > r["fascia_indentation"] >= r["x2_end"] > 0
    assert 0 < r["restitution"] < 1


def test_elastic_hertz_limit_hic_scales_as_m_to_the_minus_0_6_and_v_to_the_2_8():
    """Hutchinson (J Biomech Eng 135 (2013) 114508): F ~ x^n gives HIC ~
    m^(-1.5/(n+1)) v^((4n+1)/(n+1)); at n = 3/2: m^-0.6 v^2.8."""
    rows = [(m, v, headform.elastic_hic(m, v)) for m in (3.5, 4.5, 5.5) for v in (8.0, 9.7, 11.1)]
    design = np.array([[math.log(m), math.log(v), 1.0] for m, v, _ in rows])
    p, q, _ = np.linalg.lstsq(design, np.log([h for _, _, h in rows]), rcond=None)[0]
    # The criterion is 0.02; sampled every microsecond the fit is
    # within 5e-7 of the exponents.
    assert p == pytest.approx(-0.6, abs=1e-5, rel=0)
    assert q == pytest.approx(2.8, abs=1e-5, rel=0)


@pytest.mark.parametrize("head", [parameters.ADULT, parameters.CHILD])
def test_the_head_travels_at_least_the_least_stopping_distance_for_its_hic(head):
    r = headform.solve(head)
    assert r["head_travel"] >= crash.least_stopping_distance(r["figures"]["HIC15"], head.v)


def test_clearance_for_hic_is_where_hic15_crosses_the_limit():
    limit = parameters.HIC_LIMITS[1]
    gap0 = headform.clearance_for_hic(limit, parameters.ADULT)
    hic_free, reach = headform.hic15(parameters.ADULT, headform.NO_HARD_POINT)
    assert 0 < gap0 < reach and hic_free < limit
    # Brent's method stops within 0.1 mm, where HIC15 falls by about 120 a mm.
    assert headform.hic15(parameters.ADULT, gap0)[0] == pytest.approx(limit, rel=0.02, abs=0)
    assert headform.hic15(parameters.ADULT, gap0 + 1e-3)[0] < limit


def test_clearance_for_hic_refuses_a_limit_the_panel_alone_exceeds():
    with pytest.raises(ValueError, match="without a hard point already gives HIC15"):
        headform.clearance_for_hic(100.0, parameters.CHILD)


def test_parameters_are_the_values_their_table_states():
    k_skin, c_skin = parameters.skin()
    k_fascia, c_fascia = parameters.fascia()
    table = parameters.__doc__
    for value, text in ((k_skin, "4.79e7"), (c_skin, "2.70e4"), (parameters.Bonnet().k_hard, "1.24e10"),
                        (k_fascia, "2.92e9"), (c_fascia, "5.19e4"), (parameters.Bumper().c_box, "7.75e3"),
                        (parameters.Bonnet().m_p, "0.345 kg")):
        assert text in table
        assert value == pytest.approx(float(text.split()[0]), rel=5e-3, abs=0), text
    # The calibrations hit their targets: the certification drop's peak (elastic) and restitutions.
    v = parameters.certification_speed()
    peak = k_skin * hertz.indentation(k_skin, parameters.ADULT.m, v) ** 1.5
    assert peak / (parameters.ADULT.m * crash.STANDARD_GRAVITY) == pytest.approx(250.0, rel=1e-12, abs=0)
    from fraccontact.scenes.chain import restitution
    assert restitution(k_skin, c_skin, parameters.ADULT.m, v) == pytest.approx(0.8, abs=1e-8, rel=0)
    assert restitution(k_fascia, c_fascia, parameters.Bumper().m_b, parameters.SPEEDS["49 CFR 581"]) == \
        pytest.approx(0.59, abs=1e-8, rel=0)


@pytest.mark.parametrize("make, message", [
    (lambda: Chain([1.0, -2.0], [1.0, 0.0]), "every mass > 0"),
    (lambda: Chain([1.0], [1.0], contacts=[Contact(0, 3, K, C)]), "bodies that do not exist"),
    (lambda: Chain([1.0], [1.0], contacts=[Contact(0, GROUND, K, C, gap=-1e-3)]), "gap >= 0"),
    (lambda: Chain([1.0], [1.0], links=[Link(0, 0, 1.0, 0.0)]), "bodies that do not exist"),
    (lambda: headform.scene(gap0=-0.01), "gap0 = -0.01 is invalid"),
    (lambda: bumper.scene(v=0.0), "v = 0.0 is invalid"),
])
def test_bad_scenes_are_refused_with_the_reason(make, message):
    with pytest.raises(ValueError, match=message):
        make()
