"""The scenes' SSPs (build/headform.ssp, build/bumper.ssp) run in three
masters, and their monolithic reference sampled on the same grid, each as a
trace: t (the communication points n H from 0) and the recorded variables
("head.v", "skin.F", ...: systems.RECORDED) at them. The crash figures of a
trace (figures) are computed alike for every master and the reference.

    trace = run("headform", "fmpy", H=1e-5, options={"gap0": 0.06})
    figures(trace, "headform", options)   # HIC15, peak_g, panel_deflection, ...

Masters (each but container-gs steps every FMU from the last communication point: Jacobi):
  fmpy       fmpy.ssp.simulate_ssp, the SSP as it is. It starts every
             connector at 0, so the contacts see no motion in the first step
             and the scene starts one step late: its trace is shifted back
             by H (the first step is free flight, the head's x by v0 H).
  libcosim   libcosim's SSP loader (libcosimpy), which applies the SSV
             bindings and passes the outputs' initial values to the inputs.
  container  a container FMU built from the SSP by fmu-manipulation-toolbox
             (container.py), run by fmpy.
  container-gs  the same container in the toolbox's sequential mode: the
             contacts step first, the bodies then with their force
             (Gauss-Seidel, coupling = 1, F_avg).
  omsimulator  OMSimulator's fixed-step master (fraccontact.omsimulator), where
             it is installed; it applies the SSV bindings and passes the
             outputs' initial values to the inputs.
  reference  the scene's Chain (scenes.chain) solved monolithically by scipy.
"""

import pathlib

import numpy as np

from .. import crash, fmu_path
from ..ssp import bound_parameters, exposed_values, grid
from . import bumper as bumper_reference
from . import headform as headform_reference
from .chain import Contact
from .parameters import ADULT, CHILD, SPEEDS, Bonnet, Bumper
from .systems import CLEARANCE, RECORDED, STEP, T_END, VALUES

MASTERS = ("fmpy", "libcosim", "container", "container-gs", "omsimulator", "reference")
HEADFORMS = {"adult": ADULT, "child": CHILD}
# The reference's tolerance: far below the co-simulations' errors.
RTOL = 1e-10
# The contacts' spring: Hertz's (law 2), the exponent the references take.
HERTZ_N = Contact.n


def ssp_path(scene):
    """build/<scene>.ssp, next to the contact FMU of the build."""
    path = fmu_path().parent / f"{scene}.ssp"
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: build it (scripts/build makes build/{scene}.ssp)")
    return path


def scene_arguments(scene, options):
    """The keyword arguments of systems.VALUES[scene] and of the reference's
    scene() from a run's options: headform (adult | child), gap0, k_p, c_p,
    m_p; or v, k_box, zeta_box, M, m_b."""
    options = dict(options or {})
    if scene == "headform":
        bonnet = Bonnet(**{k: options[k] for k in ("m_p", "k_p", "c_p") if k in options})
        gap0 = options.get("gap0")
        return dict(headform=HEADFORMS[options.get("headform", "adult")], bonnet=bonnet,
                    **({} if gap0 is None else {"gap0": gap0}))
    bumper = Bumper(**{k: options[k] for k in ("M", "m_b", "k_box", "zeta_box") if k in options})
    return dict(v=options.get("v", SPEEDS["49 CFR 581"]), bumper=bumper)


def values(scene, options=None):
    """{component: {variable: value}} of a run."""
    return VALUES[scene](**scene_arguments(scene, options))


def run(scene, master, H=None, t_end=None, options=None, ssp=None):
    """A trace of the scene in master at step H [s] until t_end [s]; ssp: the path of another SSP of the
    scene (its contacts exported FMUs, docs/export.md) instead of ssp_path(scene)."""
    H = STEP[scene] if H is None else H
    t_end = T_END[scene] if t_end is None else t_end
    if master == "reference":
        return reference(scene, H, t_end, options)
    runner = {"fmpy": run_fmpy, "libcosim": run_libcosim, "container": run_container,
              "container-gs": run_container_gs, "omsimulator": run_omsimulator}[master]
    path = ssp_path(scene) if ssp is None else pathlib.Path(ssp)
    return runner(scene, H, t_end, exposed_values(path, values(scene, options)), path)


def run_fmpy(scene, H, t_end, start, path):
    from fmpy.ssp.simulation import simulate_ssp
    parameters = bound_parameters(path)
    overridden = {f"{c}.{name}" for c, vs in start.items() for name in vs}
    parameters.parameters = [p for p in parameters.parameters if p.name not in overridden]
    from fmpy.ssp.ssd import Parameter
    for component, vs in start.items():
        for name, value in vs.items():
            parameters.parameters.append(Parameter(name=f"{component}.{name}", type="Integer" if isinstance(value, int)
                                                   else "Real", value=value))
    t = grid(H, t_end)
    # simulate_ssp steps while its time (a sum of steps) < stop_time: half a step short of the last point.
    rows = simulate_ssp(str(path), stop_time=t[-1] + 0.5 * H, step_size=H, parameter_set=parameters)
    trace = {name: np.asarray(rows[name][:len(t)], dtype=float) for name in RECORDED[scene]}
    for name in trace:
        if name.split(".")[1] in ("x", "x_a"):
            trace[name] = trace[name] - trace[name][0]  # the first step's free flight
    return dict(trace, t=t[:len(rows)])


def run_libcosim(scene, H, t_end, start, path):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(str(path), step_size=round(H * 1e9))  # libcosim counts ns
    index = {}
    refs = {}
    for component, vs in start.items():
        index[component] = ex.slave_index_from_instance_name(component)
        refs[component] = {v.name.decode(): v.reference for v in ex.slave_variables(index[component])}
        for name, value in vs.items():
            if isinstance(value, int):
                ex.integer_initial_value(index[component], refs[component][name], value)
            else:
                ex.real_initial_value(index[component], refs[component][name], value)
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    t = grid(H, t_end)
    names = RECORDED[scene]
    trace = {name: np.empty(len(t)) for name in names}
    by_component = {}
    for name in names:
        component, variable = name.split(".")
        by_component.setdefault(component, []).append((name, refs[component][variable]))

    def record(i):
        for component, pairs in by_component.items():
            got = observer.last_real_values(index[component], [vr for _, vr in pairs])
            for (name, _), value in zip(pairs, got):
                trace[name][i] = value

    ex.step()  # the initialization and the first step
    record(1)
    for name in names:  # t = 0: the start values
        trace[name][0] = initial(name, start)
    for i in range(2, len(t)):
        ex.step()
        record(i)
    return dict(trace, t=t)


def initial(name, start):
    """A recorded variable's value at t = 0: a body's v0 (and its anchor's, if free), else 0."""
    component, variable = name.split(".")
    values = start[component]
    moves = variable == "v" or (variable == "v_a" and values.get("m_a", 0.0) > 0)
    return float(values.get("v0", 0.0)) if moves else 0.0


def run_container(scene, H, t_end, start, path, sequential=False):
    from .container import simulate
    t = grid(H, t_end)
    series = simulate(path, H, t[-1], start, RECORDED[scene], sequential)
    return dict(series, t=t[:len(series[RECORDED[scene][0]])])


def run_container_gs(scene, H, t_end, start, path):
    return run_container(scene, H, t_end, start, path, sequential=True)


def run_omsimulator(scene, H, t_end, start, path):
    from ..omsimulator import simulate
    return simulate(path, H, grid(H, t_end), start, RECORDED[scene])


def reference(scene, H, t_end, options=None):
    """The scene's Chain solved by scipy, sampled on the grid of H: the same
    names as the co-simulations record (the bumper's vehicle body as the
    beam's anchor, vehicle.v_a; E_diss: each dashpot's, and the links'
    dissipation given to the body that holds them)."""
    args = scene_arguments(scene, options)
    if scene == "headform":
        gap0 = args.get("gap0", CLEARANCE)
        chain = headform_reference.scene(args["headform"], gap0, args["bonnet"])
        run_ = chain.solve(t_end, length=0.01, rtol=RTOL, max_step=headform_reference.MAX_STEP)
        bodies, contacts, link_holder = ("head.{}", "panel.{}"), ("skin", "hard"), "panel"
    else:
        chain = bumper_reference.scene(args["v"], args["bumper"])
        run_ = chain.solve(t_end, length=0.05, rtol=RTOL, max_step=bumper_reference.MAX_STEP)
        bodies, contacts, link_holder = ("vehicle.{}_a", "vehicle.{}"), ("fascia",), "vehicle"
    t = grid(H, t_end)
    y = run_.y(t)
    s = run_.series(t)
    trace = {"t": t}
    for i, body in enumerate(bodies):
        trace[body.format("v")], trace[body.format("x")] = s["v"][i], s["u"][i]
    for i, contact in enumerate(contacts):
        trace[f"{contact}.F"], trace[f"{contact}.x1"], trace[f"{contact}.E_diss"] = (s["F"][i], s["x1"][i],
                                                                                     y[chain.E_CONTACTS][i])
    trace[f"{link_holder}.E_diss"] = y[chain.E_LINKS]
    trace["events"] = run_.events
    return trace


def deceleration(trace, body, velocity="v"):
    """(times, the body's deceleration [m/s^2]): the velocity's change over
    each step / H, at the step's middle (what a held force gives); velocity
    v_a: of the body's anchor."""
    t, v = trace["t"], trace[f"{body}.{velocity}"]
    H = t[1] - t[0]
    return t[:-1] + 0.5 * H, -np.diff(v) / H


def contact_duration(trace, contact):
    """How long the contact lasts [s], from the communication point before
    its first with F > 0 to its last with F > 0 and the next (to within H;
    the head may leave the panel and strike it again meanwhile)."""
    t, F = trace["t"], trace[f"{contact}.F"]
    on = np.flatnonzero(F > 0)
    if not len(on):
        return 0.0
    return float(t[min(on[-1] + 1, len(t) - 1)] - t[max(on[0] - 1, 0)])


def ended(trace, contact):
    """Whether the contact has been on and is off (F = 0) at the trace's end."""
    F = trace[f"{contact}.F"]
    return bool(np.any(F > 0) and F[-1] <= 0)


def stored(trace, contact, k):
    """The energy in a contact's Hertz spring, k x1^(n+1)/(n+1) [J]."""
    return k * np.maximum(trace[f"{contact}.x1"], 0.0) ** (HERTZ_N + 1) / (HERTZ_N + 1)


def balance(trace, scene, start):
    """The energy over the run, kinetic + springs (the bodies' and the
    contacts') + dissipated, over the impact energy, less 1 (> 0: energy
    created)."""
    if scene == "headform":
        head, panel = start["head"], start["panel"]
        E0 = 0.5 * head["m"] * head["v0"] ** 2
        energy = (0.5 * head["m"] * trace["head.v"] ** 2 + 0.5 * panel["m"] * trace["panel.v"] ** 2
                  + 0.5 * panel["k_s"] * trace["panel.x"] ** 2 + stored(trace, "skin", start["skin"]["k"])
                  + stored(trace, "hard", start["hard"]["k"])
                  + trace["skin.E_diss"] + trace["hard.E_diss"] + trace["panel.E_diss"])
        return energy / E0 - 1
    vehicle = start["vehicle"]
    M, m, v = vehicle["m_a"], vehicle["m"], vehicle["v0"]
    energy = (0.5 * M * trace["vehicle.v_a"] ** 2 + 0.5 * m * trace["vehicle.v"] ** 2
              + 0.5 * vehicle["k_s"] * (trace["vehicle.x_a"] - trace["vehicle.x"]) ** 2
              + stored(trace, "fascia", start["fascia"]["k"]) + trace["fascia.E_diss"] + trace["vehicle.E_diss"])
    return energy / (0.5 * (M + m) * v * v) - 1


def figures(trace, scene, options=None):
    """The crash figures of a trace. headform: the head's HIC15 (CFC 1000,
    crash.figures) with its window, peak g, 3 ms clip, the panel's
    deflection, the head's travel, the skin contact's duration, the head's
    restitution (-v_end/v0). bumper: F_peak, crush (the vehicle's travel),
    the vehicle's peak g, the fascia's duration, the system's restitution
    (-momentum at the end / (M + m_b) v), momentum_error (the momentum lost
    against the barrier's impulse). Both: energy_error, the balance at the
    end; energy_first, after the first step; energy_max, its largest from the
    second step on; not_ended, the contact (skin, fascia) when it has not
    ended by the trace's end: its duration and restitution are then None,
    and HIC15_lower_bound says that the head's pulse was cut short."""
    start = values(scene, options)
    energy = balance(trace, scene, start)
    energies = dict(energy_error=float(energy[-1]), energy_first=float(energy[1]), energy_max=float(energy[2:].max()))
    if scene == "headform":
        head = start["head"]
        f = crash.figures(*deceleration(trace, "head"))
        over = ended(trace, "skin")
        return dict(HIC15=f["HIC15"], HIC15_lower_bound=not over, HIC15_window=f["HIC15_window"],
                    peak_g=f["peak_g"], clip3ms_g=f["clip3ms_g"],
                    panel_deflection=float(trace["panel.x"].max()), head_travel=float(trace["head.x"].max()),
                    duration=contact_duration(trace, "skin") if over else None,
                    restitution=float(-trace["head.v"][-1] / head["v0"]) if over else None,
                    not_ended=[] if over else ["skin"], **energies)
    vehicle = start["vehicle"]
    M, m, v = vehicle["m_a"], vehicle["m"], vehicle["v0"]
    _, a = deceleration(trace, "vehicle", "v_a")
    t, F = trace["t"], trace["fascia.F"]
    p = M * trace["vehicle.v_a"] + m * trace["vehicle.v"]
    impulse = np.concatenate([[0.0], np.cumsum(0.5 * (F[1:] + F[:-1]) * np.diff(t))])
    over = ended(trace, "fascia")
    return dict(F_peak=float(F.max()), crush=float(trace["vehicle.x_a"].max()),
                peak_g=float(np.max(np.abs(a)) / crash.STANDARD_GRAVITY),
                duration=contact_duration(trace, "fascia") if over else None,
                restitution=float(-p[-1] / ((M + m) * v)) if over else None,
                momentum_error=float((p[-1] - p[0] + impulse[-1]) / ((M + m) * v)),
                not_ended=[] if over else ["fascia"], **energies)
