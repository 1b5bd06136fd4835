"""Co-simulation of the drop test as two FMUs: the striker (a rigid body)
and the contact element in its driven scene, coupled through fmpy's FMU API
as a master would couple them.

Couplings:
  zoh         the contact holds the striker's velocity over a step (m = 0)
              and the striker holds the contact force F of the last point;
  mass-aware  the contact runs a proxy striker of the same mass inside the
              step (m > 0) and the striker receives F_avg, the step's
              impulse divided by its length;
  predictive  the proxy striker as above, and the striker receives
              F_avg_next, the average force the contact predicts for the
              next step (coupling = 2): for Jacobi masters only.
Orders:
  jacobi        both FMUs step from the values of the last point;
  gauss-seidel  the contact steps first, the striker then takes its force.

An external force on the striker: gravity g (the striker FMU's parameter),
which the contact FMU's proxy knows only when given g_contact = g, or a
spring k_s, which it knows when the master feeds its acceleration as the
contact's input a at every step (feed_a, --feed-a).

Two moving bodies: a second striker FMU instance of mass m2 and initial
velocity v2 (along the striker's axis) takes +F where the striker takes -F;
the contact gets v2 and m2 (docs/two_bodies.md).

Used by the cosim_study report and tests/test_cosim.py; also a command:
  fraccontact cosim --step 1e-4 --coupling mass-aware --order gauss-seidel
  fraccontact cosim --step 1e-4 --coupling predictive --order libcosim
  fraccontact cosim --step 1e-4 --k-s 1e5 --feed-a
  fraccontact cosim --step 1e-4 --m 4.5 --v 2 --m2 2
"""

import argparse
import json
import pathlib
import sys

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException

from . import model
from .shipped import fmu_path
from .fmu import Slave, description, unpacked
from .options import OneLineParser, finite, positive
from .scipy_contact import solve_drop

M, V0 = model.defaults()["m"], model.defaults()["v"]  # the h20 drop test's striker
COUPLINGS = ("zoh", "mass-aware", "predictive")
ORDERS = ("jacobi", "gauss-seidel")
# What each coupling connects to the striker's force, and the contact's
# settings for it: its proxy striker's mass and its parameter coupling.
FORCE = {"zoh": "F", "mass-aware": "F_avg", "predictive": "F_avg_next"}
T_END = 3e-3  # a run's end: the h20 impact (1.3 ms) and its rebound
MONOLITHIC_STEP = 1e-5  # the reference's communication step (its internal steps are dt_max's whatever it is)
# The communication steps a run may take (the command's, and its reference's): fmpy's calls cost some
# microseconds each, so this bounds a run to minutes.
MAX_STEPS = 1_000_000
# The variables this module reads and sets in each FMU.
CONTACT_VARIABLES = ("law", "scene", "v", "m", "v2", "m2", "a", "g", "coupling", "F", "F_avg", "F_avg_next",
                     "F_peak", "E_diss", "eps", "v_striker", "x")
STRIKER_VARIABLES = ("m", "v0", "g", "k_s", "F", "v", "x")


class Refused(Exception):
    """An FMU refused a value or a step: its own message, and who refused."""


def contact_values(coupling, g_contact=0.0, m=M, v=V0, m2=0.0, v2=0.0):
    """The contact FMU's values for a coupling: driven, closed-form Hertz,
    the striker's mass (not with zoh), a second body's (m2 > 0) and, for
    F_avg_next, coupling = 2."""
    values = {"law": 2, "scene": 2, "v": v, "m": 0.0 if coupling == "zoh" else m, "g": g_contact}
    if m2 > 0:
        values.update(m2=m2, v2=v2)
    if coupling == "predictive":
        values["coupling"] = 2
    return values


def striker_values(g=0.0, k_s=0.0, m=M, v=V0):
    """The striker FMU's values: the h20 striker (or one of mass m at v) under gravity g, held by a spring k_s."""
    return {"m": m, "v0": v, "g": g, "k_s": k_s}


def other_acceleration(x, g_unknown, k_s, m=M):
    """What the striker's forces other than the contact give it at its
    position x, less the gravity the contact knows: the contact's input a."""
    return g_unknown - k_s * x / m


def check_order(coupling, order):
    """F_avg_next is the force of the next step: a Gauss-Seidel master, which
    applies the force of the step just taken, connects F_avg instead."""
    if coupling == "predictive" and order == "gauss-seidel":
        raise ValueError("the predictive coupling (F_avg_next) is for Jacobi masters: "
                         "a Gauss-Seidel master connects F_avg (mass-aware)")


def energy_error(v_end, E_diss, x_end=0.0, g=0.0, k_s=0.0, m=M, v=V0, m2=0.0, v2=0.0, v2_end=0.0):
    """(kinetic energy at the end + the work dissipated - gravity's work on
    the striker + the energy in its spring) over the energy at the start
    (the striker's m at v, and a second body's m2 at v2), less 1: > 0 is
    energy created."""
    start = 0.5 * m * v ** 2 + 0.5 * m2 * v2 ** 2
    end = 0.5 * m * v_end ** 2 + 0.5 * m2 * v2_end ** 2 + E_diss - m * g * x_end + 0.5 * k_s * x_end ** 2
    return end / start - 1


class Unit(Slave):
    """One FMU instance of a co-simulation, named, its values set in
    initialization mode; get() reads several reals at once. A call the FMU
    refuses raises Refused with the FMU's message."""

    def __init__(self, path, name, values):
        md, folder = unpacked(str(pathlib.Path(path).resolve()))
        super().__init__(md, folder, start=False, instance_name=name)
        self.name = name
        self.enter()
        self.set(**values)
        try:
            self.fmu.exitInitializationMode()
        except FMICallException as e:
            raise self.refused("its start values", e) from None

    def refused(self, what, error):
        return Refused(f"the {self.name} FMU refused {what}: {self.recent_error() or error}")

    def set(self, **values):
        try:
            super().set(**values)
        except FMICallException as e:
            raise self.refused(", ".join(f"{name} = {value:g}" for name, value in values.items()), e) from None

    def do_step(self, t, H):
        try:
            self.fmu.doStep(t, H)
        except FMICallException as e:
            raise self.refused(f"the step of {H:g} s at t = {t:g} s", e) from None

    def get(self, *names):
        values = self.fmu.getReal([self.variables[n].valueReference for n in names])
        return values[0] if len(names) == 1 else values


def finished(eps_contact):
    """Whether an impact has ended: the contact FMU's eps is that of the last
    finished impact, 0 before one ends."""
    return eps_contact > 0


def monolithic(contact_fmu, t_end=T_END, H=MONOLITHIC_STEP, law=2, g=0.0, m=M, v=V0):
    """The reference: the contact FMU's own drop test, same model and dt_max
    (the closed-form Hertz law unless law says otherwise), its striker of
    mass m at v under the acceleration g; v_end is its velocity at t_end,
    eps None before an impact has ended."""
    c = Unit(contact_fmu, "monolithic", {"law": law, "v": v, "m": m, "g": g})
    t = 0.0
    while t < t_end - 1e-15:
        c.do_step(t, H)
        t += H
    F_peak, eps, E_diss, v_end, x = c.get("F_peak", "eps", "E_diss", "v_striker", "x")
    c.free()
    return dict(F_peak=F_peak, eps=eps if finished(eps) else None, E_diss=E_diss, v_end=v_end,
                energy_error=energy_error(v_end, E_diss, x, g, m=m, v=v))


def result(F_peak, E_diss, eps_contact, v_end, x_end, g, k_s, m=M, v=V0, m2=0.0, v2=0.0, v2_end=0.0):
    """A co-simulation's figures; eps (from the bodies' final approach
    speed) and eps_contact are None while no impact has ended: a striker
    still in contact has no restitution to report. With a second body
    (m2 > 0), its final velocity v2_end and the momentum error: the change
    of the total momentum over the sum of the momenta's sizes at the start."""
    ended = finished(eps_contact)
    figures = dict(F_peak=F_peak, eps=-(v_end - v2_end) / (v - v2) if ended else None,
                   eps_contact=eps_contact if ended else None, impact_ended=ended, E_diss=E_diss, v_end=v_end,
                   energy_error=energy_error(v_end, E_diss, x_end, g, k_s, m, v, m2, v2, v2_end))
    if m2 > 0:
        figures.update(v2_end=v2_end,
                       momentum_error=(m * v_end + m2 * v2_end - (m * v + m2 * v2)) / (abs(m * v) + abs(m2 * v2)))
    return figures


def spring_reference(k_s):
    """The h20 drop with the striker held by a spring k_s where the contact
    begins, which no contact FMU parameter describes: scipy's solution of
    the same ODE (the FMU's Hertz law, k and c its defaults), to its
    separation: F_peak, eps, and the rest of solve_drop's figures."""
    d = model.defaults()
    return solve_drop(d["k"], d["c"], M, V0, method="DOP853", rtol=1e-12, k_s=k_s)


def cosimulate(contact_fmu, striker_fmu, H, coupling, order, t_end=T_END, trace=False, g=0.0, g_contact=0.0,
               k_s=0.0, feed_a=False, m=M, v=V0, m2=0.0, v2=0.0):
    """One co-simulation of the h20 drop (or of a striker of mass m at v),
    the striker under gravity g (which the contact's proxy striker knows as
    g_contact) and held by a spring k_s at its start (which the contact
    knows when feed_a: the acceleration of both, less g_contact, as its
    input a at each step's start); with m2 > 0 against a second free body
    of mass m2 at v2 (a striker FMU instance taking +F). Returns F_peak, eps
    (from the final approach speed), eps_contact (the contact's own, at the
    separation; both None before an impact has ended), the energy error,
    with a second body its final velocity and the momentum error, and with
    trace the series."""
    check_order(coupling, order)
    contact = Unit(contact_fmu, "contact", contact_values(coupling, g_contact, m, v, m2, v2))
    striker = Unit(striker_fmu, "striker", striker_values(g, k_s, m, v))
    bodies = [(striker, -1.0)]  # each body and the sign of the contact force on it
    if m2 > 0:
        bodies.append((Unit(striker_fmu, "body2", striker_values(m=m2, v=v2)), 1.0))
    force = FORCE[coupling]
    F_held = contact.get(force)  # before the first step: F_avg_next is F, 0 at the start
    series = []
    t, n = 0.0, 0
    while t < t_end - 1e-15:
        inputs = dict(v=striker.get("v"))
        if m2 > 0:
            inputs["v2"] = bodies[1][0].get("v")
        if feed_a:
            inputs["a"] = other_acceleration(striker.get("x"), g - g_contact, k_s, m)
        contact.set(**inputs)
        if order == "jacobi":
            for body, sign in bodies:
                body.set(F=-sign * F_held)  # the striker FMU's F pushes it back
                body.do_step(t, H)
            contact.do_step(t, H)
            F_held = contact.get(force)
        else:
            contact.do_step(t, H)
            for body, sign in bodies:
                body.set(F=-sign * contact.get(force))
                body.do_step(t, H)
        n += 1
        t = n * H
        if trace:
            series.append((t, contact.get("F"), contact.get("F_avg"), striker.get("v"), striker.get("x")))
    v_end, x_end = striker.get("v", "x")
    v2_end = bodies[1][0].get("v") if m2 > 0 else 0.0
    F_peak, E_diss, eps_contact = contact.get("F_peak", "E_diss", "eps")
    contact.free()
    for body, _ in bodies:
        body.free()
    figures = result(F_peak, E_diss, eps_contact, v_end, x_end, g, k_s, m, v, m2, v2, v2_end)
    if trace:
        figures["series"] = series
    return figures


def cosimulate_libcosim(contact_fmu, striker_fmu, H, coupling, t_end=T_END, g=0.0, g_contact=0.0, k_s=0.0):
    """The same scene in libcosim (Open Simulation Platform, via libcosimpy):
    an independent FMI 2.0 importer. Its fixed-step algorithm steps every
    FMU from the last exchanged values: the Jacobi order."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    # libcosim ends the process on an FMU's error in its initialization: the values are tried in fmpy first.
    Unit(contact_fmu, "contact", contact_values(coupling, g_contact)).free()
    Unit(striker_fmu, "striker", striker_values(g, k_s)).free()
    log_output_level(CosimLogLevel.ERROR)
    cvr = {v.name: v.valueReference for v in read_model_description(str(contact_fmu)).modelVariables}
    svr = {v.name: v.valueReference for v in read_model_description(str(striker_fmu)).modelVariables}
    ex = CosimExecution.from_step_size(step_size=round(H * 1e9))  # libcosim counts nanoseconds
    c = ex.add_local_slave(CosimLocalSlave(fmu_path=str(contact_fmu), instance_name="contact"))
    s = ex.add_local_slave(CosimLocalSlave(fmu_path=str(striker_fmu), instance_name="striker"))
    for name, value in contact_values(coupling, g_contact).items():
        if isinstance(value, int):
            ex.integer_initial_value(c, cvr[name], value)
        else:
            ex.real_initial_value(c, cvr[name], value)
    for name, value in striker_values(g, k_s).items():
        ex.real_initial_value(s, svr[name], value)
    ex.connect_real_variables(s, svr["v"], c, cvr["v"])
    ex.connect_real_variables(c, cvr[FORCE[coupling]], s, svr["F"])
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    if not ex.simulate_until(target_time=round(t_end * 1e9)):
        raise Refused(f"libcosim stopped the run before t = {t_end:g} s: an FMU refused a value or a step")
    F_peak, E_diss, eps_contact = observer.last_real_values(c, [cvr["F_peak"], cvr["E_diss"], cvr["eps"]])
    v_end, x_end = observer.last_real_values(s, [svr["v"], svr["x"]])
    return result(F_peak, E_diss, eps_contact, v_end, x_end, g, k_s)


def add_fmu_options(parser):
    """--contact and --striker: the FMUs, by default the package's (or
    $FRACCONTACT_FMU, $STRIKER_FMU)."""
    parser.add_argument("--contact", type=pathlib.Path, help="the contact FMU (default: fraccontact.fmu_path())")
    parser.add_argument("--striker", type=pathlib.Path,
                        help="the striker FMU (default: fraccontact.fmu_path('striker'))")


def fmu_paths(parser, args):
    """args.contact and args.striker, the defaults filled in; a missing FMU,
    or one that is not the contact or the striker FMU, is a usage error."""
    try:
        contact, striker = args.contact or fmu_path(), args.striker or fmu_path("striker")
    except FileNotFoundError as e:
        parser.error(str(e))
    for option, path, names, what in (("--contact", contact, CONTACT_VARIABLES, "the contact FMU (fraccontact.fmu)"),
                                      ("--striker", striker, STRIKER_VARIABLES, "the striker FMU (striker.fmu)")):
        try:
            description(path, names, fmi2=True)
        except ValueError as e:
            parser.error(f"{option} {path}: {e}; expected {what}")
    return contact, striker


def check_times(parser, args):
    """--step and --t-end together: a step within the run, and at most
    MAX_STEPS communication steps for the run and its monolithic reference."""
    if args.step > args.t_end:
        parser.error(f"--step {args.step:g} s is longer than --t-end {args.t_end:g} s")
    steps = args.t_end / min(args.step, MONOLITHIC_STEP)
    if steps > MAX_STEPS:
        parser.error(f"--t-end {args.t_end:g} s in steps of {min(args.step, MONOLITHIC_STEP):g} s (--step, or the "
                     f"reference's {MONOLITHIC_STEP:g} s) is {steps:.3g} steps; at most {MAX_STEPS:.0e}")


def main(argv=None, prog=None):
    parser = OneLineParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_fmu_options(parser)
    parser.add_argument("--step", type=positive, default=1e-5, help="communication step [s] (default 1e-5)")
    parser.add_argument("--coupling", choices=COUPLINGS, default="mass-aware")
    parser.add_argument("--order", choices=ORDERS + ("libcosim",), default="gauss-seidel",
                        help="master order, or libcosim to run the scene in libcosim (Jacobi)")
    parser.add_argument("--t-end", type=positive, default=3e-3,
                        help=f"simulated time [s] (default 3e-3; at most {MAX_STEPS:.0e} steps of --step, and of "
                             f"{MONOLITHIC_STEP:g} s for the reference)")
    parser.add_argument("--gravity", type=finite, default=0.0,
                        help="the striker's gravity [m/s^2] (default 0), an external force on it")
    parser.add_argument("--contact-knows-gravity", action="store_true",
                        help="give the contact FMU's proxy striker the same gravity (its parameter g)")
    parser.add_argument("--k-s", type=finite, default=0.0,
                        help="stiffness of a spring holding the striker where the contact begins [N/m] (default 0), "
                             "an external force the contact does not know; judged against scipy's solution")
    parser.add_argument("--feed-a", action="store_true",
                        help="feed the contact FMU the striker's acceleration from its spring (and from the gravity "
                             "it does not know) as its input a at each step's start")
    parser.add_argument("--m", type=positive, default=M, help=f"the striker's mass [kg] (default {M:g})")
    parser.add_argument("--v", type=finite, default=V0, help=f"the striker's velocity at the start [m/s] (default {V0:g})")
    parser.add_argument("--m2", type=finite, default=0.0,
                        help="a second free body's mass [kg] (default 0: none, the specimen held), which takes +F; "
                             "judged against the drop test of the reduced mass m m2/(m + m2) at v - v2")
    parser.add_argument("--v2", type=finite, default=0.0, help="the second body's velocity at the start [m/s] (default 0)")
    args = parser.parse_args(argv)
    check_times(parser, args)
    if not args.k_s >= 0:
        parser.error(f"--k-s must be 0 or positive, not {args.k_s:g}")
    if not args.m2 >= 0:
        parser.error(f"--m2 must be 0 or positive, not {args.m2:g}")
    if not args.v - args.v2 > 0:
        parser.error(f"--v {args.v:g} and --v2 {args.v2:g}: the bodies must approach (v - v2 > 0)")
    if (args.m2 > 0 or args.v2 != 0 or args.m != M or args.v != V0) and (args.k_s > 0 or args.gravity != 0):
        parser.error("--m, --v, --m2, --v2 with --k-s or --gravity: there is no reference for both")
    if args.v2 != 0 and args.m2 == 0:
        parser.error(f"--v2 {args.v2:g} needs a second body: --m2 > 0")
    if args.k_s > 0 and args.gravity != 0:
        parser.error("--k-s with --gravity: there is no reference for both")
    if args.coupling == "predictive" and args.order == "gauss-seidel":
        parser.error("--coupling predictive (F_avg_next) is for Jacobi masters: --order jacobi or libcosim")
    args.contact, args.striker = fmu_paths(parser, args)
    forces = dict(g=args.gravity, g_contact=args.gravity if args.contact_knows_gravity else 0.0, k_s=args.k_s)
    bodies = dict(m=args.m, v=args.v, m2=args.m2, v2=args.v2)
    if args.order == "libcosim" and (args.feed_a or args.m2 > 0 or args.m != M or args.v != V0):
        parser.error("--order libcosim runs the h20 striker alone, without --feed-a: use --order jacobi")
    try:
        if args.order == "libcosim":
            r = cosimulate_libcosim(args.contact, args.striker, args.step, args.coupling, args.t_end, **forces)
        else:
            r = cosimulate(args.contact, args.striker, args.step, args.coupling, args.order, args.t_end,
                           feed_a=args.feed_a, **forces, **bodies)
        if args.k_s > 0:  # the spring keeps acting after the separation: eps is the contact's, at the separation
            ref = spring_reference(args.k_s)
            figures = dict(r, F_peak_error=r["F_peak"] / ref["F_peak"] - 1,
                           eps_error=None if r["eps"] is None else r["eps_contact"] - ref["eps"], reference=ref)
        else:
            mass = args.m * args.m2 / (args.m + args.m2) if args.m2 > 0 else args.m
            ref = monolithic(args.contact, t_end=args.t_end, g=args.gravity, m=mass, v=args.v - args.v2)
            # eps of both from the approach speed at t_end (the same as at the separation without gravity)
            figures = dict(r, F_peak_error=r["F_peak"] / ref["F_peak"] - 1,
                           eps_error=None if r["eps"] is None else r["eps"] + ref["v_end"] / (args.v - args.v2),
                           monolithic=ref)
    except Refused as e:
        parser.error(str(e))
    if not r["impact_ended"]:
        print(f"{parser.prog}: the impact has not ended by --t-end {args.t_end:g} s: eps is null", file=sys.stderr)
    print(json.dumps(figures))

