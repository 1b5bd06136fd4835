"""The springpot's sections of docs/stability.md: how its runs are checked,
its convergence study, the summary, its findings and every run."""

import math

from .core import RESOLVED, check_table
from .springpot import (AGREE, CHECKS, DEFECTS, FAST, FAST_CONVERGENCE, K1, K2, KE, KNOWN, MEMORY1_STEPS, QUANTITIES,
                        REF_MEMORY1, REF_MEMORY2, expected)

# The line that opens the springpot's part of docs/stability.md.
HEADING = "\n# The springpot (damper = 2)\n"
# Why the runs listed in springpot.KNOWN and DEFECTS fail.
FINDINGS = {}
# Non-failing: the compressed memory's order (built into springpot.K2's form).
ORDER_FINDING = (
    "**The compressed memory converges at the order 2 - alpha, not 2**, where its kernel's lumped part "
    "dominates (alpha from about 0.7 to just below 1). Its kernel (model/soe.c) keeps the exponentials "
    "whose rates lie below about 15/dt_max and lumps the faster ones into a dashpot with the same integral "
    "sum a_j/b_j, which drops their first moment mu = sum a_j/b_j^2 ~ sin(pi alpha) dt_max^(2 - alpha): "
    "D^alpha x2 errs by -mu x2''. At alpha = 0.9 (h20, law hertz) memory 2's E_diss error over "
    "lambda = mu/t_c^(2 - alpha) is 0.69, 0.91, 0.96 at dt = t_c/2560, /10240, /40960 (against memory 1's "
    "Richardson extrapolation; its h^2 part still shows at t_c/640), F_peak's 0.4 to 0.6, eps's -0.3 to -0.5, "
    "t_contact's -0.1 to -0.4, the same at a kernel tolerance of 1e-10, and F_peak converges at the order 1.1 "
    "(successive differences 7.8e-5, 3.5e-5, 1.6e-5, 7.4e-6, 3.4e-6, 1.6e-6 N from dt = t_c/4096 to "
    "t_c/262144); at alpha = 0.99 E_diss errs by 0.3 lambda. At the default dt_max = 1e-7 it is 1.3e-7 "
    "relative, far below the target of 1e-4; a dashpot lumped with the first moment kept (or the rates kept "
    "to 1/dt_max^(2/(2 - alpha))) would restore the second order. The matrix's tolerance for memory 2 "
    "carries lambda, computed from the kernel the library reports (springpot.lumped_moment); the study "
    "measures its coefficient.")


def separation_note(study):
    """How memory 1 locates the separation, with the study's measured
    constants and orders of its t_contact and x2_end."""
    by_name = {s["name"]: s for s in study}

    def cells(name, memory, quantities=("t_contact", "x2_end")):
        s = by_name.get(name)
        if s is None:
            return "not run"
        out = []
        for q in quantities:
            c, o = s["constants"][memory].get(q), s["orders"][memory].get(q)
            out.append(f"{q} {c:.2g}" + (f" (order {o:.2f})" if o is not None else "") if c is not None else q)
        return ", ".join(out)
    return ("**Memory 1 locates the separation inside its step.** It ends a contact at the grid point after "
            "the separation, where F = 0 and x2 = I^alpha(F/c_alpha) recovers with a second derivative "
            "~ (t - t_s)^(alpha - 1): a secant to that grid point would err at the order 1 + alpha, with a "
            "constant moving with the separation's place in the step. It takes the separation where x (linear "
            "between the grid points: its curvature is the force's, near 0) less x2 continued from the "
            "contact's side (the parabola through the last three grid points in contact) is 0, and x2_end from "
            "that parabola (docs/model.md §7). The study's constants over h^p (and orders): at n = 1, "
            f"alpha 0.05 {cells('n = 1, alpha 0.05', 1)}; at n = 1.5, alpha 0.05 {cells('alpha 0.05', 1)}, "
            "where the force ~ (t_s - t)^n makes the solution itself only as smooth as (t_s - t)^(n + alpha) "
            "at the separation: the errors fall as h^(n + alpha) times a factor that moves with the "
            "separation's place in the step (so that x2_end's successive orders scatter), and the compressed "
            "memory, which locates the separation by its own steps, converges there at about that order too "
            f"({cells('alpha 0.05', 2, ('t_contact',))}).")


def section(study, rows, elapsed):
    """The springpot's section of docs/stability.md, as lines."""
    def g(x, spec=".2g"):
        if x is None or (isinstance(x, float) and math.isnan(x)):
            return ""
        return "0" if x == 0 else format(x, spec)
    n_cases = len({name for name, _, _ in rows})
    out = ["", HEADING.strip(), "",
           f"The springpot matrix ({n_cases} cases, {len(rows)} runs, {elapsed / 60:.1f} min here; `pytest` runs "
           f"{len(FAST)} of the cases and the study's {len(FAST_CONVERGENCE)} regimes) crosses the springpot's "
           "order alpha from 0.05 to 1 at the h20 damping (c_alpha = c omega^(1 - alpha), omega = 2400 rad/s, "
           "c = 6080 N s/m: 3.0e5 N s^0.5/m at alpha = 0.5), c_alpha over twelve decades (1e-6 to 1e6 times "
           "that) at alpha 0.05, 0.5, 0.95 and 1, the spring exponent n = 1, 1.5 and 2 (k x_ref^n = "
           "k_h20 x_ref^1.5, x_ref the h20 impact's x_max, so the forces are alike), runs of 1.0e6 to 1.6e6 "
           "internal steps (memory 2 at dt_max = 1e-9 for one impact, 5e-9 for five under gravity, 1e-7 over "
           "0.1 s of creep), five and "
           "ten impacts under gravity with the dent recovering in every flight, the striker at rest under "
           "gravity (creep), and the striker's extremes (v0 1e-4 and 30 m/s, m 1 g and 1 t).", "",
           "Every case runs both memories, with the closed-form spring k x1^n (law = 2: its energy is a potential, "
           "so the energy identity holds exactly in the model; the G1 spring law's own first-order error is the "
           "dashpot matrix's): the compressed memory (memory = 2) at the case's dt_max, every internal step's "
           "row kept (under gravity also the recovering flights, sampled 4000 times), and the full G1 history "
           f"(memory = 1) at the same step (or just below: a whole number of steps to the end) or, where that "
           f"would take more than {MEMORY1_STEPS:,} steps, at the uniform step that takes that many. Memory 1 "
           "costs O(N^2), 0.92 ns per history term here (N^2/2 of them): 1.2 s at 5e4 steps, 4.6 s at 1e5, some "
           "8.5 min at its limit of 1,048,576; 5e4 keeps the test to some 20 s, and the memories are compared "
           "each at its own step (the tolerance adds both errors).", "",
           "## Checks (springpot)", "",
           "At every row, with no allowance beyond rounding (4 ulp per step, as above):", "",
           "- **finite**: every output and row finite, the run completed;",
           "- **x2 >= 0**: the dent x2 = I^alpha(F/c_alpha) never goes negative while F >= 0 (I^alpha has a "
           "positive kernel; after a separation it recovers towards 0 from above);",
           "- **passivity**: E_diss = the integral of F dx2 (the work on the damper) >= 0 from t = 0 on (the "
           "Riemann-Liouville integral of order 1 - alpha is a positive operator); it may fall while the "
           "springpot gives back what it stored;",
           "- **0 <= eps <= 1** for every impact: eps >= 0 because at a separation x1' = v - x2' <= 0 and x2' <= 0 "
           "(the dent recovers once F = 0); eps <= 1 without gravity, by passivity (under gravity an impact may "
           "gain gravity's work and what the springpot stored in earlier impacts);",
           "- **no energy created**: 1/2 m v^2 + k x1^(n+1)/(n+1) <= 1/2 m v0^2 + m g (x + gap0), what the "
           "striker and the spring hold never exceeds what came in. (Unlike the dashpot's, E_diss is not on the "
           "left: memory 2 sums the stage powers F z and memory 1 the trapezoid of F dx2, quadratures whose "
           "O(dt^2) error has either sign; the identity below bounds them.)", "",
           "To the scheme's error, where the step resolves the contact (dt <= t_c/20, t_c the elastic contact "
           "time on k x1^n):", "",
           f"- **energy identity**: |1/2 m v0^2 + m g (x + gap0) - 1/2 m v^2 - k x1^(n+1)/(n+1) - E_diss| <= "
           f"KE (dt/t_c)^2 of the largest energy in the run, at every row, KE = {KE[1]:g} (memory 1), "
           f"{KE[2]:g} (memory 2);",
           "- **memories agree**: the two runs end the same number of impacts the same way, and every figure "
           "differs by at most K1 h1^p + K2 (h2^2 + lambda) + the kernel's tolerance + rounding, h1, h2 each "
           "memory's dt_max/t_c, p = 2 but p = min(2, n + alpha) for memory 1's t_contact and x2_end (it takes "
           "them at its separation, where the solution is only as smooth as (t_s - t)^(n + alpha): finding "
           "below), lambda = mu/t_c^(2 - alpha) the lumped kernel's lost first moment (finding "
           "below), times t_end/t_c for the figures at t_end (x2, v, E_end: an oscillation's phase error grows "
           "with the time); F_peak, E_diss and E_end only where memory 1's step resolves the force's rise, "
           "dt <= t_F/20, t_F = min(t_c, t_q), t_q the time at which the springpot driven at v with a rigid "
           "spring carries the spring's force (a step across an unresolved rise errs at the order 2 - alpha: "
           "first order for alpha = 1, as the dashpot's). Per impact: F_peak, t_contact, E_diss, v_onset "
           "(impacts after the first) relative, eps absolute, x2_end (the dent left) over the run's largest "
           "x2 (at small alpha the dent left is a small part of the largest); at t_end (when both stopped there; memory 1's "
           "rows interpolated): x2 and E_end relative, v over the impact speed.", "",
           "| | " + " | ".join(QUANTITIES) + " |", "|---|" + "---|" * len(QUANTITIES),
           "| K1 (memory 1: G1 history, BDF2) | " + " | ".join(f"{K1[q]:g}" for q in QUANTITIES) + " |",
           "| K2 (memory 2: exponentials, fixed steps) | " + " | ".join(f"{K2[q]:g}" for q in QUANTITIES) + " |",
           "", "twice the largest the study below measures.", "",
           "## Convergence study (springpot)", "",
           "Each regime with both memories at dt = t_c/20, t_c/40, ..., t_c/2560 (memory 1 up to 3e4 steps) "
           f"against a reference: memory 1 at t_c/{REF_MEMORY1} where that takes at most 6e4 steps, else "
           f"memory 2 at t_c/{REF_MEMORY2} with its kernel to 1e-10; its own error is its distance to the same "
           "run at twice the step. Each cell is the largest of (error - the reference's error - rounding [- the "
           "kernel's tolerance, memory 2]) over h^p (memory 1) or h^2 + lambda (memory 2), times t_c/t_end at "
           "t_end, and the order of the finest pair whose errors stand 100 times above that floor. Identity: "
           "the largest residual over h^2. Fails if a constant exceeds K1, K2 or KE.", "",
           "| regime | memory | " + " | ".join(QUANTITIES) + " | identity | result |",
           "|---|---|" + "---|" * (len(QUANTITIES) + 2)]
    for s in study:
        for memory in (1, 2):
            cells = []
            for q in QUANTITIES:
                c, o = s["constants"][memory].get(q), s["orders"][memory].get(q)
                cells.append("" if c is None else f"{c:.2g}" + (f" ({o:.2f})" if o is not None else ""))
            fails = [f for f in s["failures"] if f.startswith(f"memory {memory}") or not f.startswith("memory")]
            out.append(f"| {s['name']} | {memory} | " + " | ".join(cells) + f" | {g(s['identity'].get(memory))} | "
                       + ("; ".join(fails) if fails else "pass") + " |")
    out += ["", "References: " + "; ".join(f"{s['name']}: {s['reference']}" for s in study) + ".", ""]
    n_runs = len(rows)
    passed = sum(1 for *_, r in rows if not r["failures"])
    n_known = sum(1 for name, _, r in rows if r["failures"] and not r["unexpected"]
                  and set(KNOWN.get((name, r["memory"]), {})))
    n_defect = sum(1 for name, _, r in rows if r["failures"] and not r["unexpected"]
                   and set(DEFECTS.get((name, r["memory"]), {})))
    n_bad = sum(1 for *_, r in rows if r["unexpected"])
    out += ["## Summary (springpot)", "",
            f"**{passed} of {n_runs} runs pass every check; {n_known} fail one as a known finding, {n_defect} as a "
            f"defect reported to the model's owners (below); {n_bad} fail otherwise.**", "",
            *check_table(rows, CHECKS)]
    unresolved = sum(1 for *_, r in rows if r["memory"] == 1 and r["checks"].get(AGREE) is None)
    fast_only = sum(1 for *_, r in rows if r["memory"] == 1 and r.get("h_F", 0) > 1.0 / RESOLVED
                    and r["checks"].get(AGREE) is not None)
    out += ["", f"The memories are compared in {sum(1 for *_, r in rows if r['memory'] == 1) - unresolved} "
                f"cases ({unresolved} where memory 1's step does not resolve t_c; in {fast_only} of them memory 1's "
                "step does not resolve the force's rise t_F, so F_peak, E_diss and E_end are left out).", "",
            "## Findings (springpot)", "", "- " + ORDER_FINDING, "- " + separation_note(study)]
    reported = {finding for checks in DEFECTS.values() for finding in checks.values()}
    out += [f"- **{k}** ({'defect, reported' if k in reported else 'known finding'}): {v}"
            for k, v in FINDINGS.items()]
    out.append("")
    failed = [(n, r) for n, c, r in rows if r["failures"]]
    if failed:
        out += ["Runs that fail a check:", ""]
        for n, r in failed:
            listed = expected(n, r["memory"])
            tag = "UNEXPECTED" if r["unexpected"] else "; ".join(sorted(set(listed.values())))
            out.append(f"- {n} (memory {r['memory']}, dt/t_c = {r['h']:.2g}; {tag}): " + "; ".join(r["failures"]))
        out.append("")
    out += ["## Every springpot run", "",
            "identity: the largest residual over its tolerance (blank: dt > t_c/20); x2 min, E_diss min: the "
            "smallest over the largest x2, over the largest energy; created: the largest 1/2 m v^2 + spring "
            "energy minus what came in, over the largest energy; agreement: memory 1's row, the largest "
            "difference over its tolerance.", "",
            "| case | memory | dt [s] | dt/t_c | dt/t_F | steps | impacts | stop | F_peak [N] | eps (first, largest) | "
            "x2 end [m] | identity | x2 min | E_diss min | created | agreement | result |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, case, r in rows:
        ag = f"{r['agreement'][1]:.2f} ({r['agreement'][0]})" if r.get("agreement") else ""
        if r["memory"] == 1 and not ag and r["checks"].get(AGREE):
            ag = "mismatch"
        listed = expected(name, r["memory"])
        result = "pass" if not r["failures"] else ("FAIL" if r["unexpected"] else
                                                   ("defect" if (name, r["memory"]) in DEFECTS else "known"))
        eps = f"{g(r.get('eps'), '.4g')}, {g(r.get('eps_max'), '.4g')}" if r.get("impacts") else ""
        out.append(f"| {name} | {r['memory']} | {r['dt']:.3g} | {r['h']:.2g} | {r['h_F']:.2g} | {r.get('steps', '')} | "
                   f"{r.get('impacts', '')} | {r.get('stopped', '')} | {g(r.get('F_peak'), '.5g')} | {eps} | "
                   f"{g(r.get('x2'), '.4g')} | {g(r.get('identity_ratio'), '.2f')} | {g(r.get('x2_min'), '.1e')} | "
                   f"{g(r.get('E_min'), '.1e')} | {g(r.get('created'), '.1e')} | {ag} | {result} |")
    return out


def summary(study, rows, seconds):
    """The study's line for the terminal, and its failures that are not
    listed findings or defects as (name, where, failure)."""
    bad = [(s["name"], "springpot study", f) for s in study for f in s["failures"]]
    bad += [(n, f"springpot, memory {r['memory']}", f) for n, c, r in rows for f in r["unexpected"]]
    listed = sum(1 for _, _, r in rows if r["known"])
    return (f"springpot: {len(rows) - sum(1 for *_, r in rows if r['failures'])} of {len(rows)} runs pass "
            f"every check, {listed} fail only as known findings or reported defects; {len(bad)} unexpected; "
            f"{seconds:.0f} s"), bad
