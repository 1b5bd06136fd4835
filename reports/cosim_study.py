"""Co-simulation study: the h20 drop test as striker FMU + contact FMU, for
communication steps from 1e-6 s to 1e-3 s, in both coupling orders with a
zero-order hold, with the mass-aware coupling (F_avg) and, for Jacobi
masters, with the predictive coupling (F_avg_next), against the monolithic
drop test; the Jacobi runs repeated in libcosim, an independent importer; an
external force on the striker (gravity the contact knows or not, a spring it
does not know, against scipy's solution of the same ODE); the scene
as SSP (build/drop_test.ssp) run by fmpy's and libcosim's SSP masters.
Writes docs/cosimulation.md and docs/cosimulation.png.

Regenerate: scripts/report cosim_study   (about half a minute)
"""


import pathlib
import sys

import numpy as np
from tqdm import tqdm

from fraccontact import atomic, hertz, impact, model, output
from fraccontact.cosim import (COUPLINGS, M, ORDERS, V0, add_fmu_options, cosimulate, cosimulate_libcosim,
                               fmu_paths, monolithic, spring_reference)
from fraccontact.ssp import run_fmpy, run_libcosim, ssp_path

from . import BAR

plt = output.pyplot()

STEPS = [float(f"{h:.3g}") for h in np.logspace(-6, -3, 31)]
DECADES = (1e-6, 1e-5, 1e-4, 1e-3)
K = model.defaults()["k"]
GRAVITY = 9.81  # the external force on the striker: gravity, in the striker FMU
# A spring holding the striker where the contact begins, which the contact
# FMU does not know: its period (17 ms) far beyond the contact's 1.3 ms, its
# force at the peak about 2 % of the contact's.
SPRING = 1e5  # N/m
ROUNDING = 1e-12  # of the impact's energy: the energies' rounding over a run, below which none is created
SPRING_RUNS = (("predictive", "jacobi"), ("predictive", "libcosim"), ("mass-aware", "gauss-seidel"))
SSP_STEPS = (1e-3, 1e-4, 1e-5)
# The SSP table's sources: the two SSP masters, then our driver in both orders.
SSP_SOURCES = ("fmpy SSP", "libcosim SSP", "our Jacobi", "our Gauss-Seidel")
# Every (coupling, order) run over the ladder: F_avg_next is for Jacobi masters only.
RUNS = ([(c, o) for c in COUPLINGS for o in ORDERS if (c, o) != ("predictive", "gauss-seidel")]
        + [(c, "libcosim") for c in COUPLINGS])
# The external force: (label, coupling, order, the contact knows gravity).
FORCED = (("predictive, jacobi, g unknown to the contact", "predictive", "jacobi", False),
          ("predictive, jacobi, g given to the contact", "predictive", "jacobi", True),
          ("predictive, libcosim, g unknown to the contact", "predictive", "libcosim", False),
          ("mass-aware, gauss-seidel, g unknown to the contact", "mass-aware", "gauss-seidel", False),
          ("mass-aware, gauss-seidel, g given to the contact", "mass-aware", "gauss-seidel", True))


def largest_step_within(rows, key, bound):
    """The largest step from which on every smaller one keeps |key| within bound."""
    best = None
    for r in sorted(rows, key=lambda r: r["H"]):
        if not abs(r[key]) <= bound:
            break
        best = r["H"]
    return best


def first_unstable(rows):
    """The smallest step at which the coupling creates energy (> 1 % of the
    impact energy): the sign of an unstable exchange."""
    for r in sorted(rows, key=lambda r: r["H"]):
        if r["energy_error"] > 0.01:
            return r["H"]
    return None


def run(contact, striker, H, coupling, order, **forces):
    return (cosimulate_libcosim(contact, striker, H, coupling, **forces) if order == "libcosim"
            else cosimulate(contact, striker, H, coupling, order, **forces))


def gravity_reference(H, t_end=3e-3):
    """The library's drop test under GRAVITY at the time a co-simulation of
    step H ends (the first multiple of H from t_end on: with gravity the
    striker's velocity keeps changing after the rebound)."""
    T = H * next(n for n in range(1, 10 ** 7) if n * H >= t_end - 1e-15)
    r = impact(law=2, g=GRAVITY, impacts=2, t_end=T)
    return dict(F_peak=r.per_impact[0].F_peak, v_end=r.end.v)


def spring_runs(contact, striker):
    """The spring SPRING on the striker, unknown to the contact, at the
    decades of H: errors against scipy's solution of the same ODE, eps the
    contact's own at the separation (the spring keeps acting after it)."""
    ref = spring_reference(SPRING)
    rows = {}
    for coupling, order in SPRING_RUNS:
        rows[(coupling, order)] = []
        for H in DECADES:
            r = run(contact, striker, H, coupling, order, k_s=SPRING)
            rows[(coupling, order)].append(dict(H=H, F_peak_error=r["F_peak"] / ref["F_peak"] - 1,
                                                eps_error=r["eps_contact"] - ref["eps"],
                                                energy_error=r["energy_error"]))
    return dict(ref=ref, rows=rows)


def errors(r, ref, H):
    """A run's errors against the monolithic drop test: F_peak relative; eps
    from the striker's velocity at the end (which is the rebound's without
    gravity), absolute; the energy balance (> 0: energy created)."""
    return dict(H=H, F_peak_error=r["F_peak"] / ref["F_peak"] - 1, eps_error=(ref["v_end"] - r["v_end"]) / V0,
                energy_error=r["energy_error"])


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    add_fmu_options(parser)
    parser.add_argument("--ssp", type=pathlib.Path,
                        help="the scene as SSP (default: $DROP_TEST_SSP, else drop_test.ssp beside the contact FMU)")
    args = output.parse(parser, argv)
    contact, striker = fmu_paths(parser, args)
    try:
        ssp = args.ssp or ssp_path()
    except FileNotFoundError as e:
        parser.error(str(e))
    ref = monolithic(contact)
    ref_g = monolithic(contact, g=GRAVITY)
    refs_g = {H: gravity_reference(H) for H in STEPS}
    bar = tqdm(total=(len(RUNS) + len(FORCED)) * len(STEPS) + 3, file=sys.stderr, disable=None, bar_format=BAR)
    results, forced = {}, {}
    for coupling, order in RUNS:
        rows = []
        for H in STEPS:
            bar.set_description(f"{coupling}, {order}, H = {H:g}")
            rows.append(errors(run(contact, striker, H, coupling, order), ref, H))
            bar.update()
        results[(coupling, order)] = rows
    for label, coupling, order, knows in FORCED:
        rows = []
        for H in STEPS:
            bar.set_description(f"{label}, H = {H:g}")
            r = run(contact, striker, H, coupling, order, g=GRAVITY, g_contact=GRAVITY if knows else 0.0)
            rows.append(errors(r, refs_g[H], H))
            bar.update()
        forced[label] = rows
    bar.set_description(f"a spring of {SPRING:g} N/m on the striker")
    spring = spring_runs(contact, striker)
    traces = {(c, o): cosimulate(contact, striker, 1e-4, c, o, trace=True)["series"]
              for c, o in RUNS if o != "libcosim"}
    bar.update()
    bar.set_description("the scene as SSP")
    scene = ssp_runs(ssp, contact, striker)
    bar.update()
    g1 = monolithic(contact, law=1)
    bar.update()
    bar.close()
    plot(args.out / "cosimulation.png", results, forced, traces)
    write(args.out / "cosimulation.md", results, forced, ref, ref_g, scene, g1, spring)
    print((args.out / "cosimulation.md").read_text())


STYLE = {"zoh": ":", "mass-aware": "--", "predictive": "-"}


def loglog_errors(ax, rows, key, *args, **kwargs):
    ax.loglog([r["H"] for r in rows], [max(abs(r[key]), 1e-16) for r in rows], *args, **kwargs)


def plot(path, results, forced, traces):
    fig, axes = plt.subplots(2, 3, figsize=(18, 10))
    keys = ("F_peak_error", "eps_error", "energy_error")
    for (coupling, order), rows in results.items():
        if order != "libcosim":
            for ax, key in zip(axes.flat[:3], keys):
                loglog_errors(ax, rows, key, STYLE[coupling], marker=".", label=f"{coupling}, {order}")
    for (coupling, order), rows in results.items():
        if order == "libcosim":
            loglog_errors(axes.flat[0], rows, "F_peak_error", "kx", ms=4, label=f"{coupling}, libcosim (Jacobi)")
    titles = ("|F_peak error| (relative)", "|eps error| (absolute)", "|energy error| (of the impact energy)")
    for ax, title in zip(axes.flat[:3], titles):
        ax.axhline(1e-3, color="gray", lw=0.8)
        ax.set(xlabel="communication step H [s]", title=title + "; 1e-16 stands for 0")
        ax.grid(alpha=0.3, which="both")
    axes.flat[0].legend(fontsize=8)
    ax = axes.flat[3]
    for (coupling, order), series in traces.items():
        t, F = np.array([s[0] for s in series]), np.array([s[1] for s in series])
        ax.step(t * 1e3, F, where="post", ls=STYLE[coupling], label=f"{coupling}, {order}")
    ax.set(xlabel="time [ms]", ylabel="contact force F [N]", title="Force at H = 0.1 ms")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    for ax, key, title in ((axes.flat[4], "F_peak_error", "|F_peak error|"),
                           (axes.flat[5], "eps_error", "|error in the striker's final velocity| / v0")):
        for label, rows in forced.items():
            loglog_errors(ax, rows, key, "-" if "predictive" in label else "--", marker=".", label=label)
        ax.set(xlabel="communication step H [s]", title=f"Gravity ({GRAVITY} m/s²) on the striker: {title}")
        ax.axhline(1e-3, color="gray", lw=0.8)
        ax.grid(alpha=0.3, which="both")
    axes.flat[4].legend(fontsize=8)
    fig.suptitle("Striker FMU + contact FMU against the monolithic drop test (h20)")
    output.save(fig, path)


def ssp_runs(ssp, contact, striker):
    """{(source, H): run} for the SSP table: the scene in both SSP masters and
    the same scene in our driver, Jacobi (predictive) and Gauss-Seidel
    (mass-aware)."""
    runs = {}
    for H in SSP_STEPS:
        runs["fmpy SSP", H] = run_fmpy(ssp, H)
        runs["libcosim SSP", H] = run_libcosim(ssp, H)
        runs["our Jacobi", H] = cosimulate(contact, striker, H, "predictive", "jacobi")
        runs["our Gauss-Seidel", H] = cosimulate(contact, striker, H, "mass-aware", "gauss-seidel")
    return runs


def fmt_step(H):
    return f"{H:g} s" if H is not None else "none in the ladder"


def at(rows, H):
    return next(r for r in rows if r["H"] == H)


def write(path, results, forced, ref, ref_g, scene, g1, spring):
    omega = np.sqrt(1.5 * K * hertz.indentation(K, M, V0) ** 0.5 / M)
    ours, theirs = results[("predictive", "jacobi")], results[("predictive", "libcosim")]
    created = max(r["energy_error"] for r in ours + theirs)
    out = ["# Co-simulation: striker FMU + contact FMU", "",
           "Regenerate: `scripts/report cosim_study` (about half a minute; writes this file and `cosimulation.png`). "
           "The driver is `fraccontact/cosim.py` (fmpy's FMU API; also a command, "
           "`fraccontact cosim`).", "",
           f"The paper's h20 drop test split in two FMUs: `striker.fmu` (a rigid body, m = {M:g} kg, v0 = {V0:g} m/s, "
           "no gravity unless said) and `fraccontact.fmu` in its driven scene (Hertz law, dt_max = 1e-7 s), the "
           "striker's velocity into the contact, the contact's force into the striker, for 3 ms. Against the "
           f"monolithic drop test (the contact FMU alone: F_peak = {ref['F_peak']:.6g} N, eps = {ref['eps']:.6g}), "
           "for communication steps H from 1e-6 s to 1e-3 s (31 steps, log-spaced). eps is taken from the "
           "striker's velocity at 3 ms (the rebound's, without gravity).", "",
           "- **zoh**: the contact holds the striker's velocity over the step (m = 0) and the striker holds the "
           "contact force F of the last communication point;",
           f"- **mass-aware**: the contact runs a proxy striker of the same mass inside the step (m = {M:g}) and "
           "the striker receives `F_avg`, the step's impulse divided by its length;",
           "- **predictive** (Jacobi masters only): the proxy striker as above, `coupling = 2`, and the striker "
           "receives `F_avg_next`, the average force the contact predicts for the next step;",
           "- **jacobi**: both FMUs step from the values of the last point; **gauss-seidel**: the contact steps "
           "first and the striker takes its force of the same step.", "",
           "The Jacobi runs were repeated in **libcosim** (Open Simulation Platform, `libcosimpy` from PyPI), whose "
           "fixed-step algorithm is the Jacobi order: " + agreement(results) + ".", "",
           "![co-simulation study](cosimulation.png)", "",
           "## Which coupling for which master", "",
           "| master | connect to the striker | contact FMU settings | error at any H in 1e-6 .. 1e-3 s |",
           "|---|---|---|---|",
           "| Gauss-Seidel (contact first) | `F_avg` | `scene = 2`, `m` = striker's mass, `coupling = 1` "
           f"(default) | {worst(results[('mass-aware', 'gauss-seidel')])} |",
           "| Jacobi (libcosim, SSP masters, parallel) | `F_avg_next` | `scene = 2`, `m` = striker's mass, "
           f"`coupling = 2` | {worst(ours)} (our driver), {worst(theirs)} (libcosim) |",
           f"| Jacobi, `F_avg` (the lag) | `F_avg` | as Gauss-Seidel | "
           f"{worst(results[('mass-aware', 'jacobi')])} |", "",
           "(The largest |F_peak error| and |eps error| over the ladder.) Give the contact FMU the striker's gravity "
           "`g` too, and any other force it knows of; forces it does not know cost what the section on external "
           "forces shows.", "",
           "## Largest communication step within 1 % of the monolithic F_peak", "",
           "| coupling | order | largest H, F_peak within 1 % | within 1e-3 | energy created (> 1 %) from |",
           "|---|---|---|---|---|"]
    for (coupling, order), rows in results.items():
        out.append(f"| {coupling} | {order} | {fmt_step(largest_step_within(rows, 'F_peak_error', 0.01))} | "
                   f"{fmt_step(largest_step_within(rows, 'F_peak_error', 1e-3))} | {fmt_step(first_unstable(rows))} |")
    out += ["", "## The Jacobi coupling: `F_avg_next`", "",
            "A Jacobi master reads the striker's `v` and the contact's `F_avg_next` at a communication point, sets "
            "them, and steps both. `F_avg_next` is what the contact predicts from the end of its last step for a "
            "step as long as the last: its proxy striker (mass `m`, gravity `g`) advanced by H, the impulse divided "
            "by H, plus `owed`, the impulse the contact exerted so far that `F_avg_next` has not yet announced. "
            "Before the first step no step length is known (neither FMI 2.0 nor 3.0 tells it), so `F_avg_next` is "
            "`F`, 0 at the start: the limit of a vanishing step. The first step's impulse is then owed, and "
            "delivered in the second step's `F_avg_next`. With `coupling = 2` the proxy starts each step from the "
            "master's `v` less `owed/m`: the velocity the striker has once it has received every impulse, which is "
            "the proxy's own end velocity when no other force acts on the striker. Then the step is the predicted "
            "one, and the FMU takes it as computed (a memo: each step costs one computation, not two; the FMU "
            "counts both kinds in its `logEvents` message at the end of each impact; a step whose inputs differ "
            "costs two). In the drop test (scene 1) `F_avg_next` is the FMU's own striker's average force over "
            "its next step; in the driven scene without a striker mass (m = 0), the average force of the next "
            "step with `v` held, or continued with the slope the master gave (`fmi2SetRealInputDerivatives`).",
            "",
            "Errors against the monolithic drop test, F_avg_next connected:", "",
            "| H [s] | our driver: F_peak error | eps error | energy error | libcosim: F_peak error | eps error "
            "| energy error |", "|---|---|---|---|---|---|---|"]
    for H in DECADES:
        a, b = at(ours, H), at(theirs, H)
        out.append(f"| {H:g} | {a['F_peak_error']:.1e} | {a['eps_error']:.1e} | {a['energy_error']:.2e} | "
                   f"{b['F_peak_error']:.1e} | {b['eps_error']:.1e} | {b['energy_error']:.2e} |")
    out += ["", f"- **Exact at every step**: the target is 1e-3 in F_peak and eps at H = 1e-4 s; the "
            f"coupling meets it at every H of the ladder up to 1e-3 s, where the impact spans two steps, with "
            f"errors of {worst(ours)} (our driver) and {worst(theirs)} (libcosim): rounding where H is a multiple of "
            "dt_max, and the scheme's O(dt^2) difference of internal steps elsewhere (the contact splits H into "
            "equal steps of at most dt_max). The proxy striker is the striker, and `F_avg_next` hands it its "
            "impulse in the step in which it acts; only the first step's impulse arrives a step late, which "
            "shifts the striker's position by that impulse times H over m, and the contact does not use the "
            "striker's position.",
            f"- **No energy created**: the energy error (the striker's kinetic energy after the impact plus E_diss, "
            f"over the impact energy, less 1) is at most {created:.2e} over the ladder in both masters: the "
            f"monolithic run's own {ref['energy_error']:.2e} (the scheme counts a step's dissipation from its mean "
            "force, which overshoots by O(dt^2)), scaled by (h/dt_max)^2 where H splits into steps h < dt_max. "
            "Nothing is created, to rounding.",
            "- **F_avg with a Jacobi master** is the old coupling: the striker receives last step's impulse, and "
            "the lag pumps energy into the contact (the table above).", ""]
    out += forced_section(forced, ref_g)
    out += spring_section(spring)
    out += ["## Why", "",
            "- **Jacobi with F_avg or F** applies to the striker the force of the previous point: the force lags the "
            "motion by one step, which pumps energy into the contact (a delayed spring force does positive work "
            "over a cycle). The error is first order in H: about 0.2 % of F_peak at H = 1e-6 s, 2 % at 1e-5 s. "
            "The mass-aware proxy cannot help there, because the striker still receives last step's impulse; "
            "`F_avg_next` does, because it is the impulse of the step the master is about to take.",
            "- **Gauss-Seidel with a zero-order hold** is consistent (no lag in the force) but the contact is fed "
            "a velocity held over the step while the striker decelerates: it over-indents, and the explicit "
            "exchange of a stiff spring becomes unstable once H approaches the contact's own time scale: with the "
            f"Hertz stiffness at peak indentation, 1/omega = {1 / omega:.2e} s.",
            "- **Mass-aware Gauss-Seidel** is exact: the proxy striker inside the contact FMU is the striker (same "
            "mass, no other force), and F_avg carries exactly the impulse the proxy exchanged, so the striker "
            "ends the step with the proxy's velocity. The result equals the monolithic drop test at every H up "
            "to 1e-3 s: to rounding (1e-14) where H is a multiple of dt_max, and to 1e-10 elsewhere, where the "
            "contact splits H into equal internal steps that differ from the monolithic run's, a difference of "
            "the scheme's own O(dt^2) size (`tests/test_cosim.py` holds it to 1e-9).", "",
            "## Recommendations", "",
            "- Give the contact FMU the striker's mass (`m`) and gravity (`g`). With a master that steps the contact "
            "before the striker (Gauss-Seidel), connect `F_avg` (not `F`) and leave `coupling = 1`. With a master "
            "that steps both from the last values (Jacobi: libcosim's fixed-step algorithm, SSP masters, parallel "
            "masters), connect `F_avg_next` and set `coupling = 2`. Either way the communication step is free: "
            "choose it for the rest of the system; the contact FMU resolves the impact inside with `dt_max`.",
            "- Connect one of the two, with the matching `coupling`: with `coupling = 2` the proxy takes the "
            "master's `v` as a striker that has not yet received the impulse owed, which with `F_avg` connected "
            "counts it twice.",
            "- Forces on the striker that the contact FMU does not know (a spring, a damper, gravity it was not "
            "given) reach the proxy through `v` only, one step late: an error of order (force/m) H / v0, first "
            "order in H (the section above), unless the master feeds them as the input `a` (two_bodies.md).", ""]
    out += ssp_section(scene, ref, g1)
    out += ["## Every run", "",
            "| coupling | order | H [s] | F_peak error | eps error | energy error |", "|---|---|---|---|---|---|"]
    for (coupling, order), rows in results.items():
        for r in rows:
            out.append(f"| {coupling} | {order} | {r['H']:g} | {r['F_peak_error']:.2e} | {r['eps_error']:.2e} | "
                       f"{r['energy_error']:.2e} |")
    for label, rows in forced.items():
        coupling, order, knows = label.split(", ", 2)
        for r in rows:
            out.append(f"| {coupling} | {order}, gravity {GRAVITY} m/s² ({knows}) | {r['H']:g} | "
                       f"{r['F_peak_error']:.2e} | {r['eps_error']:.2e} | {r['energy_error']:.2e} |")
    atomic.write_text(path, "\n".join(out) + "\n")


def worst(rows):
    """The largest |F_peak error| and |eps error| of a ladder, as text."""
    return f"{max(max(abs(r['F_peak_error']), abs(r['eps_error'])) for r in rows):.1e}"


def forced_section(forced, ref_g):
    """An external force on the striker: gravity, known to the contact or not."""
    unknown = forced["predictive, jacobi, g unknown to the contact"]
    known = forced["predictive, jacobi, g given to the contact"]
    held = forced["mass-aware, gauss-seidel, g given to the contact"]
    H = 1e-4
    out = [f"## An external force on the striker: gravity ({GRAVITY} m/s²)", "",
           f"The striker FMU's gravity `g = {GRAVITY}` m/s² pulls it towards the specimen (against the monolithic "
           f"drop test with the same gravity, the library's at the time each run ends: F_peak = {ref_g['F_peak']:.6g} "
           f"N, v at 3 ms = {ref_g['v_end']:.6g} m/s; eps error is the error in the striker's velocity at the end "
           "over v0). The contact FMU knows of it when "
           "its own `g` is set to the same value: its proxy then feels it. When it does not, the master's `v` "
           "differs from the proxy's prediction by the velocity gravity added over the step: the FMU takes the "
           "master's `v` (less the impulse owed) and computes the step afresh (no step is then taken from the "
           "prediction), and `owed` carries the difference between the impulse it announced and the one it "
           "exerted to the next step.", "",
           "| H [s] | " + " | ".join(f"{label}: F_peak error | eps error" for label in forced) + " |",
           "|---|" + "---|---|" * len(forced)]
    for h in DECADES:
        out.append(f"| {h:g} | " + " | ".join(f"{at(rows, h)['F_peak_error']:.1e} | {at(rows, h)['eps_error']:.1e}"
                                            for rows in forced.values()) + " |")
    out += ["", f"- **Gravity the contact knows costs nothing**: the Jacobi coupling is again exact "
            f"({worst(known)} at most over the ladder). Under Gauss-Seidel the striker taking `F_avg` held over "
            "each step ends the contact a little higher than the proxy did (about the 3.5th power of H), and the "
            "contact's energy account (docs/model.md §17) takes that potential energy back from its velocity at "
            f"the separation: eps moves by {abs(at(held, H)['eps_error']):.1e} at H = {H:g} s and "
            f"{abs(at(held, DECADES[-1])['eps_error']):.1e} at {DECADES[-1]:g} s, and no energy is created.",
            f"- **Gravity it does not know costs one step of it**: the proxy learns of gravity's impulse through "
            f"`v` a step late, an error of order g H / v0 ({GRAVITY * H / V0:.1e} at H = {H:g} s; measured "
            f"{abs(at(unknown, H)['F_peak_error']):.1e} in F_peak and {abs(at(unknown, H)['eps_error']):.1e} in eps), "
            "first order in H, the same in libcosim, and of the same size as Gauss-Seidel's with F_avg, whose "
            "proxy too starts each step from the master's `v`. Any force the contact does not know (a spring, a "
            "damper on the striker) enters the same way, its impulse over a step reaching the proxy a step late, "
            "so its cost grows with the force (a spring: the next section).",
            "- **Energy with gravity** includes gravity's work on the striker, m g x, and so the striker's "
            "position, which the master integrates with each step's force held (the striker FMU moves on a "
            "parabola per step): it follows the proxy's within O(H^2) of the force's change over a step, and with "
            "`F_avg_next` it is off by the first step's impulse times H/m besides. So the balance no longer "
            "measures the coupling alone; the largest energy error over the ladder (> 0: created) is "
            + ", ".join(f"{max(r['energy_error'] for r in rows):.1e} ({label})" for label, rows in forced.items())
            + f"; up to H = 1e-4 s at most {max(r['energy_error'] for rows in forced.values() for r in rows if r['H'] <= 1e-4):.1e}.",
            ""]
    return out


def spring_section(spring):
    """An external force the contact cannot know: a spring on the striker."""
    ref, rows = spring["ref"], spring["rows"]
    # the spring's pull at the striker's deepest point over the contact force's scale, one step late
    x_deep = hertz.indentation(K, M, V0) + ref["x2"]
    pull = SPRING * x_deep / M
    H = 1e-4
    jacobi = rows[("predictive", "jacobi")]
    out = [f"## An external force on the striker: a spring ({SPRING:g} N/m)", "",
           f"The striker FMU's spring `k_s = {SPRING:g}` N/m holds it where the contact begins (its force "
           f"-k_s x; period {2 * np.pi * np.sqrt(M / SPRING) * 1e3:.0f} ms, far beyond the contact; about "
           f"{SPRING * x_deep:.0f} N at the deepest point, {SPRING * x_deep / ref['F_peak'] * 100:.1f} % of the "
           "peak force). No parameter of the contact FMU describes it, so its proxy striker never knows it. "
           "The reference is scipy's solution of the same ODE (`solve_ivp` DOP853 at rtol 1e-12: F_peak = "
           f"{ref['F_peak']:.6g} N, eps = {ref['eps']:.6g} at the separation); eps error is the contact's own "
           "eps (`eps`, at the separation) less the reference's, since the spring keeps acting on the striker "
           "after it.", "",
           "| H [s] | " + " | ".join(f"{c}, {o}: F_peak error | eps error | energy error" for c, o in rows) + " |",
           "|---|" + "---|---|---|" * len(rows)]
    for i, h in enumerate(DECADES):
        out.append(f"| {h:g} | " + " | ".join(
            f"{r[i]['F_peak_error']:.1e} | {r[i]['eps_error']:.1e} | {r[i]['energy_error']:.1e}"
            for r in rows.values()) + " |")
    out += ["", f"- **A force the contact does not know costs one step of it**, as gravity did: the spring's "
            f"impulse reaches the proxy through `v` a step late, an error of order (k_s x / m) H / v0 "
            f"({pull * H / V0:.1e} at H = {H:g} s, x the striker's deepest point; measured "
            f"{abs(at(jacobi, H)['F_peak_error']):.1e} in F_peak and {abs(at(jacobi, H)['eps_error']):.1e} in eps), "
            "first order in H, the same in libcosim and with Gauss-Seidel and `F_avg`.",
            energy_sentence(rows) + " Fed as the input `a` (the spring's acceleration at each step's start), "
            "the error falls to second order in H: [two_bodies.md](two_bodies.md) measures it against H. "
            "Otherwise choose H so that (k_s x / m) H / v0 is below the accuracy needed.", ""]
    return out


def energy_sentence(rows):
    """What the energy errors above say (they include the spring's energy
    k_s x^2 / 2 at the end; > 0 is energy created)."""
    created = [(r["H"], r["energy_error"], f"{c}, {o}") for (c, o), runs in rows.items() for r in runs
               if r["energy_error"] > ROUNDING]
    why = ("the proxy's force misses the spring's share of each step, so the exchanged force and the striker's "
           "motion would not do equal work, but the contact's energy account (docs/model.md §17) takes back from "
           "its output force what the coupling would create")
    if not created:
        return f"- **It creates no energy**: {why}; the energy errors above are dissipation."
    H, worst, run = max(created, key=lambda c: c[1])
    passive = [h for h in DECADES if h < min(c[0] for c in created)]
    return (f"- **It creates no energy** at H up to {max(passive):g} s: {why}. At longer steps it does, up to "
            f"{worst:.1e} of the impact's energy ({run}, H = {H:g} s) at the run's end: a step that long holds "
            "most of the impact, and a Jacobi master fixes each step's force before the inputs that end the step "
            "before it, so what the spring did in the impact's last step is taken back by the pulls of the steps "
            "after it ([two_bodies.md](two_bodies.md) follows such a run on).")



def agreement(results):
    worst_difference = 0.0
    for coupling in COUPLINGS:
        for a, b in zip(results[(coupling, "jacobi")], results[(coupling, "libcosim")]):
            for key in ("F_peak_error", "eps_error", "energy_error"):
                worst_difference = max(worst_difference, abs(a[key] - b[key]))
    return (f"at every step and for every coupling its results match this driver's Jacobi runs within "
            f"{worst_difference:.1e}")


def within(relative):
    return "bit for bit" if relative == 0 else f"within {relative:.1e} relative"


def ssp_section(scene, ref, g1):
    """The scene as SSP: how the masters order the FMUs, and their results
    beside our driver's and the monolithic drop test's (g1: the monolithic
    test with the G1 law, which the SSP's parameter set leaves out)."""
    jacobi = {source: max(abs(scene[source, H][key] / scene["our Jacobi", H][key] - 1)
                          for H in SSP_STEPS for key in ("F_peak", "eps", "E_diss"))
              for source in SSP_SOURCES[:2]}
    error = max(abs(scene[source, H]["F_peak"] / ref["F_peak"] - 1) for source in SSP_SOURCES for H in SSP_STEPS)
    out = ["## The scene as SSP", "",
           "`build/drop_test.ssp` (made by CMake from `ssp/`) is this scene for any SSP 1.0 importer: "
           "`SystemStructure.ssd` wires `striker.v` to `contact.v` and `contact.F_avg_next` to `striker.F` (the "
           "predictive coupling, for the Jacobi masters SSP importers are: the contact's input `m` keeps its "
           "default, the striker's mass), `resources/h20.ssv` binds the contact's `scene = 2` (driven), "
           "`coupling = 2` (the master feeds `F_avg_next`) and `law = 2` (closed-form Hertz, as above and in the "
           "monolithic reference, so that only the coupling's error is measured: the FMU's default, the G1 sum, "
           f"moves the monolithic F_peak by {g1['F_peak'] / ref['F_peak'] - 1:.1e}), and `resources/` holds both "
           "FMUs of the build. Every other value is the FMUs' default: the h20 test.", "",
           "How the two SSP masters order the FMUs:", "",
           "- **fmpy** (`fmpy.ssp.simulation.simulate_ssp`): at each step it sets every component's inputs, "
           "steps the components in document order (striker, then contact), and only then copies outputs to "
           "inputs: Jacobi, whatever the order in the file. Every connector starts at 0, so the contact's first "
           "step sees v = 0 and the impact begins one step late; the run is the Jacobi run shifted by one step, "
           "with the same results once the rebound is over. Its result rows carry the step's start time. It "
           "applies only a parameter set passed to it (names with the component's path, `contact.scene`), not "
           "the SSD's bindings, nor the SSD's stop time and step.",
           "- **libcosim** (`CosimExecution.from_ssp_file`): applies the SSD's parameter bindings and runs its "
           "fixed-step algorithm (the step from the SSD's OSP annotation, or given): every FMU steps, in "
           "parallel, from the values exchanged at the last point: Jacobi. In initialization mode it passes the "
           "outputs' initial values on, so the contact starts from the striker's v0, as our driver's does.", "",
           "| H [s] | source | F_peak [N] | eps | E_diss [mJ] | F_peak error |",
           "|---|---|---|---|---|---|",
           f"| | monolithic drop test | {ref['F_peak']:.6f} | {ref['eps']:.6f} | {ref['E_diss'] * 1e3:.6f} | |"]
    for H in SSP_STEPS:
        for source in SSP_SOURCES:
            r = scene[source, H]
            out.append(f"| {H:g} | {source} | {r['F_peak']:.6f} | {r['eps']:.6f} | {r['E_diss'] * 1e3:.6f} | "
                       f"{r['F_peak'] / ref['F_peak'] - 1:.2e} |")
    out += ["", "(eps from the striker's final velocity; the contact time is not an output of the FMUs, so the "
            "dissipated energy stands beside F_peak and eps.)", "",
            "- Both SSP masters give our Jacobi driver's results: at every step, F_peak, eps and E_diss "
            f"{within(jacobi['fmpy SSP'])} (fmpy) and {within(jacobi['libcosim SSP'])} (libcosim): the same "
            "arithmetic (the contact FMU's results do not depend on how a master rounds its time), but libcosim "
            "counts time in integer nanoseconds, so its step sizes may round differently.",
            f"- With `F_avg_next` every source is the monolithic drop test at every step up to 1 ms, F_peak "
            f"{within(error)}: the Jacobi order costs nothing. (With `F_avg` connected, as this file did before, the "
            "striker received the force a step late and F_peak was off by 2 % at 1e-5 s, first order in H.)", ""]
    return out
