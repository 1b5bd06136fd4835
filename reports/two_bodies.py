"""The contact between two moving bodies: how a
master places the contact FMU between a striker and a second body, both
free and both held by other forces, and what it measures: two free bodies
against the single body of the reduced mass, and a spring k_s on the
striker with and without its acceleration fed as the input a, against
scipy's solution, over communication steps from 1 us to 1 ms, under the
Gauss-Seidel and the Jacobi coupling. Runs the FMUs through cosim.py's
master (FMI 2.0; tests/test_two_bodies.py runs FMI 3.0 too).
Writes docs/two_bodies.md.

Regenerate: scripts/report two_bodies   (about 10 s of CPU)
"""

import math

from fraccontact import atomic, output
from fraccontact.cosim import M, T_END, V0, add_fmu_options, cosimulate, fmu_paths, monolithic, spring_reference

M1, M2, V = 4.5, 2.0, 2.0                 # the case studied: 4.5 kg on a free 2 kg at 2 m/s
ROUNDING = 1e-12                          # an energy error within the energies' rounding over a run
FREE_STEPS = (1e-5, 1e-4, 1e-3)
K_S = 1e5                                 # the striker FMU's spring [N/m]
STEPS = (1e-6, 2e-6, 5e-6, 1e-5, 2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3)
COUPLINGS = (("mass-aware", "gauss-seidel", "Gauss–Seidel, `F_avg`"),
             ("predictive", "jacobi", "Jacobi, `F_avg_next`"))

PLACING = """\
## Placing the element between two bodies

The contact FMU's striker is the **relative motion** of the two bodies along the striker's axis. Its inputs:

| input | unit | what the master feeds at each communication step's start |
|---|---|---|
| `v` | m/s | the striker's velocity, positive towards the second body |
| `m` | kg | the striker's mass (0: the rate `v` − `v2` is prescribed, no proxy) |
| `v2` | m/s | the second body's velocity on the same axis (positive in the direction the striker moves into it) |
| `m2` | kg | the second body's mass; 0 = held fixed (the drop test's specimen) |
| `a` | m/s² | the striker's acceleration from every force but this contact (its springs, dampers, other contacts, gravity the FMU's `g` does not hold), at the step's start |
| `a2` | m/s² | the same for the second body |

The proxy striker inside the step moves at the approach speed `v − v2` with the reduced mass `m m2/(m + m2)` (`m` where `m2` = 0) under `g + a − a2` besides the contact force. The contact force `F ≥ 0` pushes the bodies apart: the master applies **−F to the striker and +F to the second body** (the force output of its coupling, below), so the momentum the bodies exchange cancels exactly. In the drop test (`scene` = 1) `v2` and `m2` are read at initialization as `v` and `m` are; `a`, `a2` have no effect there (a warning says so).

**Gauss–Seidel master** (`coupling` = 1, the default): each step, set `v`, `v2`, `a`, `a2` from the bodies' state at the step's start, step the contact FMU, read `F_avg` (the step's impulse over its length), then step the bodies with −`F_avg` and +`F_avg` held over the step.

**Jacobi master** (`coupling` = 2): each step, read `F_avg_next` before stepping, set `v`, `v2`, `a`, `a2` from the step's start, and step the contact and the bodies side by side, the bodies with −`F_avg_next` and +`F_avg_next`. (The proxy starts from `v − v2` less the impulse `F_avg_next` has not yet announced, over the reduced mass.)

A body touched by several contacts: its `a` for one contact includes the others' forces at the step's start (their `F` over its mass).

`F_avg` and `F_avg_next` include the coupling's energy correction (docs/model.md §17): from `v`, `v2`, `a`, `a2` at both ends of each step the FMU knows the bodies' real displacement, hence the work they did on the contact against the work its proxy absorbed, and it adds to the force it outputs whatever keeps the energy the coupling has created at or below zero. It is zero for two free bodies and for constant accelerations.
"""


def errors(r, F_peak, eps):
    return r["F_peak"] / F_peak - 1, (r["eps_contact"] if r["eps_contact"] is not None else math.nan) - eps


def order(e1, e0, H1, H0):
    """The order between two steps, from the errors' sizes."""
    return math.log(abs(e1) / abs(e0)) / math.log(H1 / H0) if e0 and e1 else math.nan


def free_bodies(contact, striker):
    ref = monolithic(contact, m=M1 * M2 / (M1 + M2), v=V)
    rows = []
    for coupling, order_, label in COUPLINGS:
        for H in FREE_STEPS:
            r = cosimulate(contact, striker, H, coupling, order_, m=M1, v=V, m2=M2)
            rows.append((label, H, r["F_peak"] / ref["F_peak"] - 1, r["eps"] - ref["eps"], r["momentum_error"],
                         r["energy_error"]))
    return ref, rows


LATER = (4e-3, 5e-3, 6e-3)  # where a run still in debt at its end is followed on (the spring returns after 10 ms)


def spring(contact, striker, ref):
    """The k_s case's runs; a run that ends having created energy is run
    again to each of LATER: r["later"], the energy error at those ends."""
    table = {}
    for coupling, order_, label in COUPLINGS:
        for fed in (False, True):
            runs = []
            for H in STEPS:
                r = cosimulate(contact, striker, H, coupling, order_, k_s=K_S, feed_a=fed)
                if r["energy_error"] > ROUNDING:
                    r["later"] = [(t, cosimulate(contact, striker, H, coupling, order_, k_s=K_S, feed_a=fed,
                                                 t_end=t)["energy_error"]) for t in LATER]
                runs.append((H, r))
            table[(label, fed)] = runs
    return table


def repaid(r):
    """How a run in debt at its end pays it back later."""
    return ", then " + ", ".join(f"{e(E)} at {t * 1e3:g} ms" for t, E in r["later"])


def e(x):
    return "—" if x is None or not math.isfinite(x) else f"{x:+.2e}"


def write(path, free_ref, free_rows, spring_ref, table):
    E0 = 0.5 * M * V0 ** 2
    out = ["# The contact between two moving bodies", "",
           "Generated by `scripts/report two_bodies` (reports/two_bodies.py); every figure below "
           "is measured by that run. Tests: `tests/test_two_bodies.py`.", "", PLACING]
    out += ["## Two free bodies", "",
            f"A {M1:g} kg striker at {V:g} m/s on a free {M2:g} kg body at rest (the closed-form Hertz law, the h20 "
            "specimen's k and c), each body a striker FMU instance, against the contact FMU's own drop test of the "
            f"reduced mass {M1 * M2 / (M1 + M2):.6g} kg at {V:g} m/s (F_peak = {free_ref['F_peak']:.6g} N, "
            f"eps = {free_ref['eps']:.6g}). Errors: F_peak relative, eps absolute (from the final approach speed), the "
            "momentum's change over its size, the energy's change over the bodies' kinetic energy at the start "
            "(negative: the scheme's own dissipation error).", "",
            "| coupling | H [s] | F_peak error | eps error | momentum error | energy error |", "|---|---|---|---|---|---|"]
    out += [f"| {label} | {H:g} | {e(dF)} | {e(de)} | {e(dp)} | {e(dE)} |" for label, H, dF, de, dp, dE in free_rows]
    out += ["", "The proxy is the relative motion, so the co-simulation takes the single body's internal steps: the "
            "errors are rounding at any H.", ""]
    out += ["## A force the proxy does not see, and fed as `a`", "",
            f"The h20 striker ({M:g} kg at {V0:.6g} m/s) held by a spring k_s = {K_S:g} N/m where the contact begins "
            "(the striker FMU's `k_s`), against scipy's solution of the same ODE (DOP853, rtol 1e-12: "
            f"F_peak = {spring_ref['F_peak']:.6g} N, eps = {spring_ref['eps']:.6g}). Blind: the contact knows nothing "
            "of the spring; fed: the master feeds `a = −k_s x / m` at each step's start. Orders between neighbouring "
            "steps in brackets. The energy error includes the spring's energy; > 0 is energy created. The FMU's "
            "energy account (docs/model.md §17) corrects the force each step so that the coupling creates none; the "
            "last column is the closed form of what the fed coupling created without it (on main), "
            "(k_s / m) (H² / 4) E_diss / E0: the proxy holds the spring's acceleration over the step (its path runs "
            "ahead by k_s v H³ / (6 m)) and the master holds the contact force on a striker the spring slows "
            "(k_s v H³ / (12 m)).", ""]
    for coupling, order_, label in COUPLINGS:
        runs = {fed: table[(label, fed)] for fed in (False, True)}
        errs = {fed: [errors(r, spring_ref["F_peak"], spring_ref["eps"]) for _, r in runs[fed]] for fed in runs}
        out += [f"**{label}**", "",
                "| H [s] | F_peak error, blind | fed | eps error, blind | fed | energy, blind | fed | without the correction |",
                "|---|---|---|---|---|---|---|---|"]
        for i, H in enumerate(STEPS):
            cells = []
            for k in range(2):  # F_peak, eps
                for fed in (False, True):
                    cell = e(errs[fed][i][k])
                    if i:
                        cell += f" ({order(errs[fed][i][k], errs[fed][i - 1][k], H, STEPS[i - 1]):.1f})"
                    cells.append(cell)
            blind, fed = runs[False][i][1], runs[True][i][1]
            predicted = K_S / M * H * H / 4 * fed["E_diss"] / E0
            cells += [e(blind["energy_error"]), e(fed["energy_error"]), e(predicted)]
            out.append(f"| {H:g} | " + " | ".join(cells) + " |")
        out.append("")
    gain = min(abs(table[(label, False)][STEPS.index(1e-5)][1]["F_peak"] / spring_ref["F_peak"] - 1)
               / abs(table[(label, True)][STEPS.index(1e-5)][1]["F_peak"] / spring_ref["F_peak"] - 1)
               for _, _, label in COUPLINGS)
    created = [f"{label} {'fed' if fed else 'blind'} at H = {H:g} s ({r['energy_error']:+.2g} at "
               f"{T_END * 1e3:g} ms{repaid(r)})"
               for _, _, label in COUPLINGS for fed in (False, True) for H, r in table[(label, fed)]
               if r["energy_error"] > ROUNDING]
    out += [f"What it shows: fed `a`, the error in F_peak falls from first order in H to second ({gain:.0f} times "
            "smaller at H = 1e-5 s under either coupling), and eps's with it until it meets the FMU's own error "
            "against scipy's (internal steps of 1e-7 s) at the smallest steps. The energy correction takes from the "
            "bodies, each step, what the coupling would create so far and never gives energy back: the steps that "
            "would return some are left as they are, so the runs end somewhat below their start energy; once the "
            "contact is over it pulls the separating bodies where it must. At H comparable with the impact (it "
            f"lasts {spring_ref['t_contact'] * 1e3:.2g} ms) every coupling is coarse. Runs that still create "
            f"energy (beyond {ROUNDING:g} E0) at the end of the run: " + ("; ".join(created) if created else "none")
            + ". A Jacobi master announces each step's force before the step, from the inputs of the step before: "
            "where the impact lasts one step or a few and `a` is not fed, what the spring did in the impact's last "
            "step is seen a step late, and the pulls of the following steps take it back.", ""]
    atomic.write_text(path, "\n".join(out))


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    add_fmu_options(parser)
    args = output.parse(parser, argv)
    contact, striker = fmu_paths(parser, args)
    free_ref, free_rows = free_bodies(contact, striker)
    spring_ref = spring_reference(K_S)
    table = spring(contact, striker, spring_ref)
    path = args.out / "two_bodies.md"
    write(path, free_ref, free_rows, spring_ref, table)
    print(f"wrote {path}")
