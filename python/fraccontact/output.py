"""What the commands' outputs share (fraccontact run's and fit's, and the
reports' under reports/): the command line (--out, --solver, --fmu), and how
numbers are written and figures drawn."""

import argparse
import math
import os
import pathlib

from . import atomic, fmu_path, solver
from .options import OneLineParser


def parser(prog, doc, out_help="folder of the report (default: docs/)"):
    """A report's command line: its docstring as help, and --out."""
    p = OneLineParser(prog=prog, description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("docs"), help=out_help)
    return p


def add_solver(p, what="fraccontact-solve"):
    """--solver: the C solver program (its GSL reference, its own timing)."""
    p.add_argument("--solver", type=pathlib.Path, help=f"{what} (default: $FRACCONTACT_SOLVE, else on PATH)")


def add_fmu(p):
    """--fmu: the contact FMU."""
    p.add_argument("--fmu", type=pathlib.Path, help="the FMU (default: fraccontact.fmu_path(), $FRACCONTACT_FMU)")


def make_folder(p, out):
    """The report's folder (--out), made before anything is computed: a report
    of minutes must not fail at its end for want of it. One that cannot be
    made or written is a usage error."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        p.error(f"--out {out}: cannot make the folder ({e.strerror})")
    if not os.access(out, os.W_OK):
        p.error(f"--out {out}: the folder is not writable")


def parse(p, argv, check=None):
    """The arguments, --solver and --fmu (where the report has them) filled
    in with their defaults, check(p, args) (the report's own rules) passed,
    then --out made; one that cannot be found or made is a usage error."""
    args = p.parse_args(argv)
    try:
        if "solver" in args:
            args.solver = args.solver or solver.solve_path()
        if "fmu" in args:
            args.fmu = args.fmu or fmu_path()
            if not args.fmu.exists():
                raise FileNotFoundError(f"{args.fmu} does not exist: build it first (scripts/build)")
    except (solver.Failed, FileNotFoundError) as e:
        p.error(str(e))
    if check is not None:
        check(p, args)
    make_folder(p, args.out)
    return args


def significant(x, digits):
    """x to that many significant digits, trailing zeros kept, 'e8' for 'e+08'."""
    mantissa, _, exponent = f"{x:#.{digits}g}".partition("e")
    return mantissa.rstrip(".") + (f"e{int(exponent)}" if exponent else "")


def with_error(value, sigma, unit):
    """'value ± sigma unit', the value to the second significant digit of
    sigma (its further digits are noise); 6 digits when there is no sigma."""
    if sigma is None or not sigma > 0:
        return f"{significant(value, 6)} {unit}".rstrip()
    magnitude = math.floor(math.log10(abs(value))) if value else math.floor(math.log10(sigma))
    digits = max(magnitude - math.floor(math.log10(sigma)) + 2, 1)
    return f"{significant(value, digits)} ± {significant(sigma, 2)} {unit}".rstrip()


def pyplot():
    """matplotlib.pyplot drawing to files only (the Agg backend: no display
    needed), imported on first use so that a command that may not plot
    runs without matplotlib."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save(fig, path, dpi=100, rect=None):
    """The figure laid out (tight, within rect) and written whole or not at
    all, without matplotlib's version in its metadata: the file changes
    only when the figure does."""
    fig.tight_layout(rect=rect)
    atomic.save_figure(fig, path, dpi=dpi, metadata={"Software": None})
