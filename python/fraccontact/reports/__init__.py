"""The reports under docs/, one module each with main(argv, prog):
fraccontact report NAME (scripts/report NAME from the source tree)."""

import argparse
import pathlib

from .. import fmu_path, solver


def source_tree():
    """The repository a source-tree report works in (mutation, reliability:
    they build and test copies of it): the current folder, which
    scripts/report makes the repository's root."""
    root = pathlib.Path.cwd()
    if not (root / "CMakeLists.txt").exists() or not (root / "fmu_src").is_dir():
        raise SystemExit(f"{root} is not the fraccontact repository: run this report from its root (scripts/report does)")
    return root


def parser(prog, doc, out_help="folder of the report (default: docs/)"):
    """A report's command line: its docstring as help, and --out."""
    p = argparse.ArgumentParser(prog=prog, description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("docs"), help=out_help)
    return p


def add_solver(p, what="fraccontact-solve"):
    """--solver: the C solver program (its GSL reference, its own timing)."""
    p.add_argument("--solver", type=pathlib.Path, help=f"{what} (default: $FRACCONTACT_SOLVE, else on PATH)")


def add_fmu(p):
    """--fmu: the contact FMU."""
    p.add_argument("--fmu", type=pathlib.Path, help="the FMU (default: fraccontact.fmu_path(), $FRACCONTACT_FMU)")


def parse(p, argv):
    """The arguments, --solver and --fmu (where the report has them) filled
    in with their defaults; one that cannot be found is a usage error."""
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
    return args
