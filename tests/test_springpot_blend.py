"""The compressed springpot's fixed step and its blend (docs/model.md §11,
"The springpot's blend"): second order where the springpot is nearly a
spring, against error-controlled Radau IIA steps (a second method), and no
step-to-step ringing of the force where it is nearly a spring or a soft
dashpot."""

import math

import numpy as np
import pytest

from fraccontact import model
from reports.stability import springpot

# alpha 0.05 with c_alpha a hundredth of the h20 damping: nearly a spring,
# softer than the Hertz spring (springpot.matrix's "alpha 0.05, c_alpha x 0.01")
NEARLY_A_SPRING = dict(damper=2, law="hertz", damper_order=0.05, c_alpha=springpot.c_alpha_for(0.05, 1e-2),
                       memory=2, memory_tolerance=1e-10, impacts=1)


def first_impact(**p):
    return model.simulate(output_interval=0, **p)["run"].per_impact[0]


def test_nearly_a_spring_converges_at_the_second_order():
    """eps and E_diss of fixed steps against Radau IIA at tolerance 1e-10,
    within the springpot study's second-order bound K2 h^2 (h = dt/t_c,
    the study's constants; the kernel's lumped moment lambda is below
    1e-9 here), and the order of eps from dt = 4e-6 to 1e-6 at least 1.8.
    A blend that counts the springs' resistance is first order here: its
    eps errs by 1.4e-5 at 1e-6, seventeen times K2 h^2."""
    ref = first_impact(tolerance=1e-10, dt_max=0, **NEARLY_A_SPRING)
    t_c = springpot.scales(dict(springpot.BASE, alpha=0.05, mult=1e-2))["t_c"]
    errors = {}
    for dt in (4e-6, 1e-6):
        i = first_impact(dt_max=dt, **NEARLY_A_SPRING)
        h2 = (dt / t_c) ** 2
        errors[dt] = abs(i.eps - ref.eps)
        assert errors[dt] <= springpot.K2["eps"] * h2, (dt, errors[dt])
        assert abs(i.E_diss / ref.E_diss - 1) <= springpot.K2["E_diss"] * h2, dt
    assert math.log2(errors[4e-6] / errors[1e-6]) / 2 >= 1.8, errors


def force_turns(**p):
    """How often the contact force turns between rising and falling from
    one step to the next over the run."""
    F = np.asarray(model.simulate(output_interval=0, **p)["F"])
    dF = np.diff(F)
    dF = dF[dF != 0.0]
    return int(np.sum(dF[1:] * dF[:-1] < 0.0))


def test_nearly_a_spring_does_not_ring_at_coarse_steps():
    """77 steps per contact: the force rises, turns once and falls. Without
    the first step's weight (onset_weight) the discrete gradient starts the
    split between the spring and the springpot's springs off balance and
    the force alternates from step to step (25 turns)."""
    assert force_turns(dt_max=1e-4, **NEARLY_A_SPRING) == 1


@pytest.mark.parametrize("alpha", [0.95, 1.0])
def test_soft_dashpot_like_springpot_does_not_ring(alpha):
    """A soft springpot, nearly a dashpot, across its relaxation unresolved
    (dt = 1e-5 s, c_alpha a millionth of the h20 damping): the blend keeps
    the force from alternating (without it: 600 to 800 turns)."""
    p = dict(damper=2, law="hertz", damper_order=alpha, c_alpha=springpot.c_alpha_for(alpha, 1e-6), memory=2,
             dt_max=1e-5, t_end=0.024)
    assert force_turns(**p) <= 2
