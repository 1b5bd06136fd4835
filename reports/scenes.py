"""The crash scenes as co-simulations: build/headform.ssp and
build/bumper.ssp in fmpy's SSP master, libcosim and a container FMU
(fmu-manipulation-toolbox, in its parallel and its sequential mode), and
OMSimulator where it is installed (its column names the build), against
their monolithic reference
(fraccontact.scenes.chain, scipy), the convergence in H, the HIC15 against
the clearance, and the figures beside the published ones. Writes
docs/scenes.md, docs/scenes_hic_clearance.png and docs/scenes_head.png
(docs/scenes_reference.md holds the references, the crash metrics' checks
and the parameters' sources).

Regenerate: scripts/report scenes   (a few minutes)
"""

import numpy as np
from scipy.optimize import brentq
from tqdm import tqdm

from fraccontact import atomic, crash, omsimulator, output
from fraccontact.scenes import headform, masters, systems
from fraccontact.scenes.parameters import ADULT, CHILD, HIC_LIMITS, SPEEDS

MASTERS = ("fmpy", "libcosim", "container", "container-gs") + (("omsimulator",) if omsimulator.available() else ())
STEPS = (4e-5, 2e-5, 1e-5, 5e-6)
CLEARANCES = np.arange(0.040, 0.0801, 0.0025)
# Brent's tolerance on gap0 [m]: a tenth of a micrometre, far under the 0.01 mm the clearances are quoted to.
XTOL = 1e-7
ENERGY_FIGURES = (("energy_error", "{:.2e}"), ("energy_first", "{:.2e}"), ("energy_max", "{:.2e}"))
HEADFORM_FIGURES = (("HIC15", "{:.1f}"), ("peak_g", "{:.2f}"), ("clip3ms_g", "{:.2f}"),
                    ("panel_deflection", "{:.5f}"), ("duration", "{:.5f}"), ("restitution", "{:.5f}"),
                    *ENERGY_FIGURES)
BUMPER_FIGURES = (("F_peak", "{:.1f}"), ("crush", "{:.6f}"), ("peak_g", "{:.4f}"), ("duration", "{:.5f}"),
                  ("restitution", "{:.6f}"), *ENERGY_FIGURES, ("momentum_error", "{:.2e}"))


def side_by_side(scene, rows, options=None):
    """The masters' figures beside the reference's, and each one's relative error."""
    ref = masters.figures(masters.run(scene, "reference", options=options), scene, options)
    runs = {m: masters.figures(masters.run(scene, m, options=options), scene, options) for m in MASTERS}
    out = ["| figure | reference | " + " | ".join(map(label, MASTERS)) + " |", "|---|---|" + "---|" * len(MASTERS)]
    for name, fmt in rows:
        cells = []
        for m in MASTERS:
            value = runs[m][name]
            error = "" if name.startswith("energy") or name.endswith("_error") else f" ({value / ref[name] - 1:+.1e})"
            cells.append(fmt.format(value) + error)
        out.append(f"| {name} | {fmt.format(ref[name])} | " + " | ".join(cells) + " |")
    return out, ref, runs


def label(master):
    """A master's column: its name, and OMSimulator's the build that ran."""
    return f"omsimulator ({omsimulator.version()})" if master == "omsimulator" else master


def convergence(scene, names, bar):
    """Rows of the errors against H (every master, against the reference on each grid)."""
    out = ["| H [s] | master | " + " | ".join(f"{n} error" for n in names) + " | energy_error | energy_max |",
           "|---|---|" + "---|" * (len(names) + 2)]
    for H in STEPS:
        ref = masters.figures(masters.run(scene, "reference", H=H), scene)
        for m in MASTERS:
            f = masters.figures(masters.run(scene, m, H=H), scene)
            out.append(f"| {H:g} | {m} | " + " | ".join(f"{f[n] / ref[n] - 1:+.2e}" for n in names)
                       + f" | {f['energy_error']:+.2e} | {f['energy_max']:+.2e} |")
            bar.update()
    return out


def hic15(master, head, gap0):
    """The HIC15 of the headform scene in master with the clearance gap0 [m]."""
    options = {"headform": head.name, "gap0": float(gap0)}
    return masters.figures(masters.run("headform", master, options=options), "headform", options)["HIC15"]


def hic_against_clearance(bar):
    """HIC15 over the clearance, adult and child: the reference and libcosim."""
    curves = {}
    for head in (ADULT, CHILD):
        ref, cosim = [], []
        for gap0 in CLEARANCES:
            ref.append(hic15("reference", head, gap0))
            cosim.append(hic15("libcosim", head, gap0))
            bar.update()
        curves[head.name] = (np.array(ref), np.array(cosim))
    return curves


def clearance(master, head, limit, hic):
    """The clearance [mm] at which master's HIC15 falls through limit: Brent's
    method on gap0 to XTOL, a run of the scene per evaluation, between the
    CLEARANCES where the sampled curve hic crosses it."""
    i = next(i for i in range(len(CLEARANCES) - 1) if hic[i] >= limit > hic[i + 1])
    return 1e3 * brentq(lambda gap0: hic15(master, head, gap0) - limit, CLEARANCES[i], CLEARANCES[i + 1],
                        xtol=XTOL)


def clearances(curves):
    """{(head, limit): (libcosim's, the reference's clearance [mm])} for every HIC limit."""
    out = {}
    for head in (ADULT, CHILD):
        ref, cosim = curves[head.name]
        for limit in HIC_LIMITS:
            out[head.name, limit] = (clearance("libcosim", head, limit, cosim),
                                     clearance("reference", head, limit, ref))
    return out


def plot_hic(curves, path):
    plt = output.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for name, (ref, cosim) in curves.items():
        line, = ax.semilogy(1e3 * CLEARANCES, ref, label=f"{name}: reference")
        ax.semilogy(1e3 * CLEARANCES, cosim, "o", color=line.get_color(), mfc="none", label=f"{name}: libcosim")
    for limit in HIC_LIMITS:
        ax.axhline(limit, color="grey", lw=0.8, ls="--")
    ax.set_xlabel("clearance gap0 [mm]")
    ax.set_ylabel("HIC15 (CFC 1000)")
    ax.legend()
    output.save(fig, path)


def plot_head(ref, runs, path):
    plt = output.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4))
    t, a = masters.deceleration(ref, "head")
    ax.plot(1e3 * t, crash.in_g(a), "k", lw=2, label="reference (scipy)")
    for m, trace in runs.items():
        t, a = masters.deceleration(trace, "head")
        ax.plot(1e3 * t, crash.in_g(a), lw=1, ls="--", label=m)
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("head deceleration [g], unfiltered")
    ax.set_xlim(0, 30)
    ax.legend()
    output.save(fig, path)


def main(argv=None, prog=None):
    p = output.parser(prog, __doc__)
    args = p.parse_args(argv)
    output.make_folder(p, args.out)
    out = args.out
    with tqdm(total=2 * len(STEPS) * len(MASTERS) + 2 * len(CLEARANCES), desc="scenes", unit="run") as bar:
        head_rows, head_ref, head_runs = side_by_side("headform", HEADFORM_FIGURES)
        traces = {m: masters.run("headform", m) for m in MASTERS}
        plot_head(masters.run("headform", "reference"), traces, out / "scenes_head.png")
        bumper_rows, bumper_ref, bumper_runs = side_by_side("bumper", BUMPER_FIGURES)
        head_conv = convergence("headform", ("HIC15", "peak_g", "panel_deflection"), bar)
        bumper_conv = convergence("bumper", ("F_peak", "crush", "restitution"), bar)
        curves = hic_against_clearance(bar)
    crossings = clearances(curves)
    plot_hic(curves, out / "scenes_hic_clearance.png")
    text = document(head_rows, head_ref, head_runs, bumper_rows, bumper_ref, bumper_runs, head_conv, bumper_conv,
                    crossings)
    atomic.write_text(out / "scenes.md", "\n".join(text) + "\n")
    print(f"wrote {out / 'scenes.md'}")
    return 0


def omsimulator_note():
    """The OMSimulator column's bullet, where it ran."""
    if "omsimulator" not in MASTERS:
        return []
    return [f"- omsimulator: {omsimulator.version()}, built from its sources (docs/ssp.md), through its C API "
            "(fraccontact.omsimulator). Its fixed-step master oms-ma, which the SSDs' OpenModelica annotation "
            "names, applies the SSV bindings itself and steps every FMU from the last communication point, from the "
            "outputs' initial values, as libcosim does, but sets the inputs in the order of the FMUs' declared "
            "dependencies: the panel's a, which depends on its input F2 (the skin's force), reaches the hard "
            "contact after F2 is set, holding the skin's force of the step to come where libcosim's holds the "
            "last step's. The bumper, without such a chain, is libcosim's trace to rounding; the headform is "
            "until the panel reaches the hard point (tests/test_omsimulator.py)."]


def document(head_rows, head_ref, head_runs, bumper_rows, bumper_ref, bumper_runs, head_conv, bumper_conv,
             crossings):
    k = systems.CLEARANCE
    loan = bumper_runs["libcosim"]["energy_first"]
    second = "(UN GTR 9's second limit)"
    published_clearance = {("adult", 1000.0): "about 70 mm (BASt bonnet study)", ("child", 1000.0): "about 50 mm (BASt)",
                           ("adult", 1700.0): second, ("child", 1700.0): second}
    published = [
        "| figure | this model | published |", "|---|---|---|",
        *(f"| clearance for HIC15 = {limit:.0f}, {head} (libcosim; reference) | {cosim:.2f} mm; {ref:.2f} mm | "
          f"{published_clearance[head, limit]} |" for (head, limit), (cosim, ref) in crossings.items()),
        f"| square-pulse stopping distance for HIC15 = 1000 at 11.1; 9.7 m/s | "
        f"{1e3 * crash.stopping_distance(1000, ADULT.v):.1f}; {1e3 * crash.stopping_distance(1000, CHILD.v):.1f} mm "
        "(crash.stopping_distance) | about 68; 48 mm |",
        f"| head travel at gap0 = {1e3 * k:.0f} mm, adult (HIC15 {head_ref['HIC15']:.0f}) | "
        f"{1e3 * head_ref['head_travel']:.1f} mm | the least stop for that HIC: "
        f"{1e3 * crash.least_stopping_distance(head_ref['HIC15'], ADULT.v):.1f} mm |",
        "| elastic-limit HIC ~ m^p v^q | p = -0.5999995, q = 2.7999998 (docs/scenes_reference.md, "
        "tests/test_scene_reference.py) | -0.6, 2.8 (Hutchinson 2013) |",
        f"| bumper restitution at {SPEEDS['49 CFR 581']:.4f} m/s (reference) | {bumper_ref['restitution']:.3f} | "
        "0.2-0.4 vehicle to vehicle at 2-5 mph (SAE 931842); the material alone 0.59 |",
    ]
    return [
        "# Crash scenes as co-simulations",
        "",
        "Generated by `scripts/report scenes` (reports/scenes.py). The scenes' monolithic references, "
        "the crash metrics' checks and every parameter's source: [scenes_reference.md](scenes_reference.md).",
        "",
        "## The scenes as SSPs",
        "",
        "`build/headform.ssp` (ssp/headform.ssd): the headform and the bonnet panel are `body.fmu` (bodies/: "
        "a mass m held by a spring k_s and a damper c_s to an anchor, the ground or a free mass m_a inside the "
        "same FMU, two contact forces in), the skin and the hard point two instances of `fraccontact.fmu`. "
        "`build/bumper.ssp` (ssp/bumper.ssd): the vehicle is one `body.fmu`, its bumper beam the body (m) and "
        "the vehicle's body its free anchor (m_a) behind the crash box (k_s, c_s), both integrated together "
        "exactly; the fascia is a `fraccontact.fmu` against the rigid barrier (its m2 = 0, v2 = 0). No spring "
        "or damper is split across FMUs: the contacts are the only coupling between them. The SSV files are "
        "written at build time from "
        "fraccontact/scenes/parameters.py. Each contact takes v, v2 (the bodies' v) and a, a2 (the bodies' "
        "outputs a, every force but the one of the contact they strike, and a2, every force but the one of "
        "the contact that strikes them) and returns F_avg_next (coupling = 2, for the Jacobi masters), -F on "
        "its striker's input F and +F on its second body's F2.",
        "",
        "Run one: `fraccontact scene headform --master fmpy|libcosim|container|container-gs|omsimulator|reference "
        "[--H ...] [--headform child] [--gap0 ...]`, `fraccontact scene bumper [--v ...]`. A run takes 3 steps of H at "
        "least (the deceleration is the velocity's change over each step, and the CFC filter takes 3 samples). "
        "A run whose `--t-end` comes before its contact (the skin, the fascia) has ended reports that contact in "
        "`not_ended`, with a warning, and no duration or restitution (null); the head's HIC15 is then of a pulse "
        "cut short, `HIC15_lower_bound`. HIC15 is searched on a grid no finer than 1e-5 s (`crash.HIC_STEP`): "
        "at a finer H the filtered deceleration is interpolated onto it (docs/scenes_reference.md).",
        "",
        "In fmpy from Python: its `simulate_ssp` applies no SSV binding, and would run the FMUs' defaults (the "
        "head at rest, the contact the drop test's); `fraccontact.ssp.bound_parameters(ssp)` gathers the SSP's "
        "bindings into the parameter set it takes:",
        "",
        "```python",
        "from fmpy.ssp.simulation import simulate_ssp",
        "from fraccontact.ssp import bound_parameters",
        "",
        'headform = "build/headform.ssp"',
        "rows = simulate_ssp(headform, stop_time=0.035, step_size=1e-5, parameter_set=bound_parameters(headform))",
        f'print(-rows["head.v"][-1] / {ADULT.v})   # the restitution, {head_runs["fmpy"]["restitution"]:.4f}',
        'bumper = "build/bumper.ssp"',
        "rows = simulate_ssp(bumper, stop_time=0.2, step_size=1e-5, parameter_set=bound_parameters(bumper))",
        f'print(rows["fascia.F"].max())          # F_peak, {bumper_runs["fmpy"]["F_peak"]:.1f} N',
        "```",
        "",
        "**Recommended step: H = 1e-5 s** (the SSDs' step). The masters run the SSPs as they are, with "
        "these differences:",
        "",
        "- fmpy's `simulate_ssp` (its module fmpy.ssp.simulation) starts every connector at 0, sets every input from "
        "its connector before each step (a start value, even one of its parameter set, does not outlive the "
        "first step) and reads no SSV binding (fraccontact.ssp passes the bindings as its parameter set): the "
        "contacts see no motion in the first step, in which every body flies free. With every spring and damper "
        "inside one FMU that step is exact free flight: the scene starts one step late, and its trace shifted "
        "back by H is libcosim's to rounding (tests/test_scenes.py::test_jacobi_masters_give_one_trace).",
        "- fmu-manipulation-toolbox 2.0 reads the SSD's components and connections but not its SSV bindings, "
        "and exposes nothing the SSD does not connect to the system's boundary: the runner gives the container "
        "the SSV values as start values and the recorded variables as outputs (fraccontact.scenes.container). "
        "By default its container steps the FMUs from the last internal step (parallel mode), as libcosim "
        "does: the two give one trace.",
        "- container-gs: the toolbox's sequential mode (`Assembly(sequential=True)`, `-sequential` on its "
        "command line), in which, its source says, the FMUs \"step one after the other in the order of the "
        "configuration, each one with the outputs just computed by the previous ones\" "
        "(fmu_manipulation_toolbox.container.builder, check_sequential_order): Gauss-Seidel. The runner puts "
        "the contacts first, sets their coupling = 1 and feeds the bodies F_avg in place of the SSD's F_avg_next "
        "(fraccontact.scenes.container.gauss_seidel; docs/coupling.md).",
        *omsimulator_note(),
        "",
        "## Headform on a bonnet: masters side by side",
        "",
        f"Adult headform (4.5 kg at 11.1 m/s), clearance gap0 = {1e3 * k:.0f} mm, H = 1e-5 s; figures of the "
        "head's deceleration on the communication grid (the velocity's change over each step / H), CFC 1000 "
        "filtered; the reference sampled on the same grid. In brackets: the relative error against it.",
        "",
        *head_rows,
        "",
        "![head deceleration](scenes_head.png)",
        "",
        "## Low-speed bumper: masters side by side",
        "",
        f"49 CFR 581, {SPEEDS['49 CFR 581']:.4f} m/s, H = 1e-5 s, 0.2 s (the fascia has left the barrier). "
        "The energy balance (masters.balance): kinetic + springs (the crash box's or the panel's, and the "
        "contacts' Hertz springs) + dissipated, over the impact energy, less 1 (> 0: energy created); "
        "energy_error its value at the end, energy_first after the first step, energy_max its largest from the "
        "second step on; momentum_error: the momentum lost less the barrier's impulse (trapezoidal on the grid).",
        "",
        *bumper_rows,
        "",
        "## Convergence in H",
        "",
        "Errors against the reference on each H's grid.",
        "",
        *head_conv,
        "",
        *bumper_conv,
        "",
        "**No energy is created**, in any master at any H: the balance at the end is negative (the coupling "
        "dissipates, second order in H), and from the second step on it never rises above rounding "
        "(energy_max). The one positive value is the first step's (energy_first, "
        f"{loan:.1e} of the bumper's impact energy at H = 1e-5 in libcosim, growing as H^2.5): the energy the "
        "contact's spring takes in that step, k (v0 H)^2.5/2.5, which the bodies have not yet paid. A Jacobi "
        "master cannot step the contact first: its F_avg_next is 0 before its first step and announces that "
        "step's impulse in the second (docs/coupling.md), which repays it; container-gs steps the contacts "
        f"first and has none ({bumper_runs['container-gs']['energy_first']:.0e}). (Before the crash box lay inside "
        "one FMU, each body held it with the other as its anchor, extrapolated over a step: that created "
        "energy, second order in H, and fmpy's zero first exchange pulled each body towards an anchor at "
        "rest.)",
        "",
        "## HIC15 against the clearance",
        "",
        "![HIC15 against clearance](scenes_hic_clearance.png)",
        "",
        "The clearances below are where HIC15 crosses its limit: Brent's method (scipy.optimize.brentq) on gap0, "
        f"each evaluation a run of the scene, to {XTOL:g} m, between the plotted clearances where the curve "
        "crosses; quoted to 0.01 mm (tests/test_scenes.py::test_quoted_clearances_are_where_hic15_crosses_its_limit "
        "runs the scene a hundredth of a millimetre either side).",
        "",
        "## Beside the published figures",
        "",
        *published,
        "",
        "The clearances agree with BASt's because the assumed panel stiffness and damping give about the "
        "deflection BASt found needed, not because the model was validated (docs/scenes_reference.md: the "
        "panel's parameters move them by tens of millimetres). The bumper's system restitution lies inside the "
        "published vehicle-to-vehicle range, far below the material's 0.59: the vehicle pushes on the fascia "
        "for about a hundred times the element's own contact time, and the dashpot in series with the Hertz "
        "spring flows under that push (docs/scenes_reference.md, Low-speed bumper).",
    ]
