"""Stability and accuracy on stiff and extreme cases: the model (the C
library in-process, fraccontact.impact) over a matrix that crosses the
dashpot c from 1e-2 to 1e9 N s/m, specimens from foam (1 MPa) to steel
(210 GPa), v0 from 1e-4 to 30 m/s, m from 1 g to 1000 kg, steps from 1e-9 s
to longer than the contact, N up to 1e6, zero velocity, a gap and repeated
impacts with gravity; and a second matrix over the springpot (damper = 2):
its order alpha from 0.05 to 1, c_alpha over twelve decades, the
spring exponent n in {1, 1.5, 2}, both memories (the full G1 history and the
compressed one), runs of 1e6 steps and repeated impacts under gravity with
the dent recovering between them (stability/springpot.py).

Each dashpot case runs three ways: the G1 law and the Hertz law with fixed
discrete-gradient steps of the case's dt (tolerance = 0), and "adaptive", the Hertz
law with error-controlled steps (tolerance = 1e-6, Kvaerno's ESDIRK 5(4))
capped by the case's dt (so dt = 1e-2 caps them far beyond the contact
time). Every dashpot run is checked for what holds at any step (finite, no
tension, 0 <= eps <= 1, the momentum invariant, no energy created, no force
above c v_max), and every figure whose time scale its step resolves is
compared with the GSL reference at the scheme's own error, C (dt/T)^2, plus
D dt/T for the G1 law with N = steps since onset; the adaptive runs on every
figure at the error control's bound, (accepted steps) x tolerance. C and D are measured by the
convergence study that runs first (which fails if they exceed the values
written here). Every springpot run is checked for x2 >= 0, passivity, eps,
no energy created and the energy identity, and the two memories against
each other (see springpot.check). Writes docs/stability.md; exits 1 if a check
fails that is not a listed known finding (or reported defect), or a listed
one no longer fails.

Regenerate: scripts/report stability   (pytest runs the FAST subset;
--springpot the springpot's part alone)
"""

import time

from fraccontact import atomic, output

from . import dashpot, dashpot_report, springpot, springpot_report
from .core import over


def springpot_kept(parser, path):
    """The lines of the report at path before its springpot part (which
    --springpot rewrites); a usage error where there is none."""
    text = path.read_text() if path.is_file() else ""
    if springpot_report.HEADING not in text:
        parser.error(f"--springpot rewrites the springpot part of {path}: it has none "
                     f"(no line {springpot_report.HEADING.strip()!r}); run without --springpot first")
    return text.split(springpot_report.HEADING)[0].removesuffix("\n").split("\n")


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    output.add_solver(parser, "fraccontact-solve, for its GSL reference")
    parser.add_argument("--fast", action="store_true", help="the subset pytest runs")
    parser.add_argument("--springpot", action="store_true",
                        help="the springpot's part alone: its sections of the file rewritten, the rest kept")
    args = output.parse(parser, argv)
    target = args.out / ("stability_fast.md" if args.fast else "stability.md")
    kept = springpot_kept(parser, target) if args.springpot else None
    # The dashpot: its convergence study, then its matrix, every case with every law.
    start = time.monotonic()
    study = [] if kept else over(
        dashpot.CONVERGENCE, args.fast, dashpot.FAST_CONVERGENCE, "convergence: ",
        lambda name, case: [dashpot.convergence(args.solver, name, case, law) for law in ("hertz", "g1")])
    rows = [] if kept else over(dashpot.matrix(), args.fast, dashpot.FAST, "", lambda name, case: [
        (name, case, dashpot.check(args.solver, case, law, name)) for law in dashpot.LAWS])
    seconds = time.monotonic() - start
    # The springpot: its study, then its matrix, both memories per case.
    sp_start = time.monotonic()
    sp_study = over(springpot.CONVERGENCE, args.fast, springpot.FAST_CONVERGENCE, "springpot convergence: ",
                    lambda name, case: [springpot.convergence(name, case)])
    sp_rows = over(springpot.matrix(), args.fast, springpot.FAST, "springpot: ",
                   lambda name, case: [(name, case, row) for row in springpot.check(case, name)])
    sp_seconds = time.monotonic() - sp_start
    head = ["# Stability and accuracy on stiff and extreme cases", "",
            f"Regenerate: `scripts/report stability` ({(seconds + sp_seconds) / 60:.1f} min here). `pytest` runs a "
            "fast subset (`tests/test_stability.py`) in CI.", ""]
    lines = (kept or head + dashpot_report.section(study, rows)) + springpot_report.section(sp_study, sp_rows,
                                                                                            sp_seconds)
    atomic.write_text(target, "\n".join(lines) + "\n")
    bad = []
    summaries = [] if kept else [dashpot_report.summary(study, rows, seconds)]
    for line, failures in summaries + [springpot_report.summary(sp_study, sp_rows, sp_seconds)]:
        print(line)
        bad += failures
    for name, where, f in bad:
        print(f"FAILED {name} ({where}): {f}")
    return 1 if bad else 0
