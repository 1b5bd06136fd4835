"""What a co-simulation master relies on: input derivatives (the velocity
follows the given slope inside a step), output derivatives against closed
forms and finite differences, and the mass-aware driven scene."""

import math
import struct

import pytest
from fmpy.fmi1 import FMICallException

from fmu_driver import K, M

VR = {"v": 1, "m": 2, "F": 13, "F_avg": 14, "F_peak": 15, "x": 16, "x1": 17, "x2": 18, "v_striker": 19,
      "E_diss": 20, "eps": 21, "semi_integral": 22}
GAMMA_5_2 = 0.75 * math.sqrt(math.pi)
RIGID = 1e20  # a dashpot that does not move: x1 = x


def test_the_velocity_follows_the_slope_inside_a_step(slave):
    """Driven, no inertia, v = a t given as v(t_k) and dv/dt = a at each
    communication point: x1 = a t^2 / 2 exactly (the step integrates a
    parabola exactly), so F = k (a t^2 / 2)^(3/2) at every point."""
    a, H = 200.0, 2e-6
    s = slave(scene=2, m=0.0, v=0.0, c=RIGID, law=2)
    for n in range(1, 51):
        s.fmu.setRealInputDerivatives([VR["v"]], [1], [a])
        s.step(H)
        t = n * H
        # rounding over up to 1000 steps of x1 += ...: 1e-12
        assert s.get("x1") == pytest.approx(0.5 * a * t * t, rel=1e-12)
        assert s.get("F") == pytest.approx(K * (0.5 * a * t * t) ** 1.5, rel=1e-11)
        s.set(v=a * t)
    # Without the slope the same master's zero-order hold lags by a t H / 2:
    z = slave(scene=2, m=0.0, v=0.0, c=RIGID, law=2)
    for n in range(1, 51):
        z.step(H)
        z.set(v=a * n * H)
    assert z.get("x1") == pytest.approx(0.5 * a * (50 * H) ** 2 - 0.5 * a * 50 * H * H, rel=1e-9)


def test_a_new_value_of_v_drops_the_old_slope(slave):
    s = slave(scene=2, m=0.0, v=0.1, c=RIGID, law=2)
    s.fmu.setRealInputDerivatives([VR["v"]], [1], [1000.0])
    s.set(v=0.1)              # the slope lapses with the new value
    s.step(1e-5)
    assert s.get("x1") == pytest.approx(0.1 * 1e-5, rel=1e-12)


@pytest.mark.parametrize("vr, order, says", [(VR["m"], 1, "only v"), (VR["v"], 2, "only order 1"),
                                             (99, 1, "only v")])
def test_input_derivatives_that_are_not_provided_are_errors(slave, vr, order, says):
    s = slave(scene=2, m=0.0)
    with pytest.raises(FMICallException):
        s.fmu.setRealInputDerivatives([vr], [order], [1.0])
    assert says in s.last_error()


def test_output_derivatives_in_the_driven_scene_are_the_closed_forms(slave):
    v, H = 0.5, 1e-6
    s = slave(scene=2, m=0.0, v=v, c=RIGID, law=2)
    for n in range(1, 21):
        s.step(H)
        t = n * H
        d = dict(zip(["F", "x", "x1", "x2", "semi_integral"],
                     s.fmu.getRealOutputDerivatives([VR[k] for k in ("F", "x", "x1", "x2", "semi_integral")],
                                                    [1] * 5)))
        assert d["F"] == pytest.approx(1.5 * K * math.sqrt(v * t) * v, rel=1e-11)
        assert d["x"] == v and d["x1"] == pytest.approx(v, rel=1e-12)
        assert d["x2"] == pytest.approx(K * (v * t) ** 1.5 / RIGID, rel=1e-11)
        assert d["semi_integral"] == pytest.approx(d["F"] / (GAMMA_5_2 * K), rel=1e-14)


def test_output_derivatives_in_the_drop_test_match_finite_differences(slave):
    """Central differences of the outputs over 1e-7 s err by ~(1e-7/t_c)^2,
    except within a few microseconds of onset and separation, where
    F ~ (distance in time)^(3/2) has no bounded second derivative."""
    names = ["F", "x", "x1", "x2", "v_striker", "E_diss"]
    s = slave(law=2, dt_max=1e-8)
    H = 1e-7
    values, rates = [], []
    for _ in range(9000):
        s.step(H)
        values.append([s.get(n) for n in names])
        rates.append(s.fmu.getRealOutputDerivatives([VR[n] for n in names], [1] * len(names)))
        if s.get("eps") > 0:
            break
    checked = 0
    for i in range(50, len(values) - 50, 250):
        for j, name in enumerate(names):
            fd = (values[i + 1][j] - values[i - 1][j]) / (2 * H)
            scale = max(abs(r[j]) for r in rates)
            assert rates[i][j] == pytest.approx(fd, abs=1e-5 * scale), (name, i)
        checked += 1
    assert checked > 20


@pytest.mark.parametrize("name", ["F_avg", "F_peak", "eps"])
def test_outputs_without_a_rate_say_so(slave, name):
    s = slave()
    s.step(1e-5)
    with pytest.raises(FMICallException):
        s.fmu.getRealOutputDerivatives([VR[name]], [1])
    assert "no time derivative" in s.last_error()


def exact_bits(s, names=("F", "F_peak", "x", "x2", "v_striker", "E_diss", "eps")):
    return [struct.pack("<d", s.get(n)) for n in names]


def test_mass_aware_coupling_with_an_exact_master_is_the_drop_test(slave):
    """Driven with m > 0, a master that sends back the proxy's own end
    velocity each step (a striker with no other force) reproduces the
    monolithic drop test bit for bit: the proxy is that striker."""
    H = 1e-5
    drop = slave()
    driven = slave(scene=2, m=M, v=drop.get("v"))
    for _ in range(200):
        drop.step(H)
        driven.step(H)
        assert exact_bits(driven) == exact_bits(drop)
        driven.set(v=driven.get("v_striker"))


def test_F_avg_is_the_impulse_that_conserves_momentum(slave):
    """One long communication step with the proxy: F_avg H is what the proxy
    striker lost, m (v_start - v_end), and a master that applies F_avg moves
    its striker exactly as the proxy did."""
    s = slave(scene=2, m=M, v=0.6)
    for H in (2e-4, 3e-4, 5e-4):
        v_start = s.get("v") if s.t == 0 else s.get("v_striker")
        s.set(v=v_start)
        s.step(H)
        assert s.get("F_avg") * H == pytest.approx(M * (v_start - s.get("v_striker")), rel=1e-12)


def test_zero_order_hold_overestimates_the_impulse_at_long_steps(slave):
    """The reason for the proxy: held at the impact velocity over 0.5 ms, the
    striker pushes on as if it did not slow down."""
    held = slave(scene=2, m=0.0, v=0.6)
    proxy = slave(scene=2, m=M, v=0.6)
    held.step(5e-4)
    proxy.step(5e-4)
    assert held.get("F_avg") > 1.05 * proxy.get("F_avg")
