"""The speed as a tested promise: the instructions a few
short runs execute, counted by valgrind's callgrind, against the counts
recorded in tests/instruction_counts.tsv.

Each row runs its program twice under callgrind, with two repeat counts
(`--repeat` of the solver, the experiments of tests/fmu_importer.c, the
impacts of `fraccontact-bench batch`): the difference of the two totals is
the work of the extra repeats alone, start-up and output cancelling, and it
is divided by what those repeats did (internal steps, impacts or runs). A
count is exact and does not depend on the machine's load; it depends on the
compiler and the C library, so the record holds for the toolchain it names.

    instruction_counts.py [--update] SOLVE BENCH IMPORTER FMU_BINARY COMPILER

(ctest instruction_counts passes this build's fraccontact-solve,
fraccontact-bench, fmu_importer, the FMI 2.0 FMU's shared library and the C
compiler; --update rewrites the record from them.)

A row fails when it exceeds its record by more than 2 %, and when it falls
below it by more than 10 % (the record would then let a regression of that
size pass: update it). The record changes only in a commit that says why.
Exit status: 0 every row within, 1 a row outside, 77 skipped (no valgrind,
or a toolchain other than the record's)."""

import json
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

RECORD = pathlib.Path(__file__).with_name("instruction_counts.tsv")
ABOVE, BELOW = 0.02, 0.10
SKIP = 77


def read_record():
    """The toolchain line and the rows: name, unit, record, n1, n2, command."""
    toolchain, rows = None, []
    for line in RECORD.read_text().splitlines():
        if line.startswith("# toolchain:"):
            toolchain = line.split(":", 1)[1].strip()
        if not line.strip() or line.startswith("#"):
            continue
        name, unit, record, n1, n2, command = line.split("\t")
        rows.append(dict(name=name, unit=unit, record=float(record), n1=int(n1), n2=int(n2), command=command))
    return toolchain, rows


def toolchain_of(compiler):
    """The C compiler's version and the C library's (less the names they were
    called by: cc and gcc are one compiler)."""
    version = subprocess.run([compiler, "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    libc = subprocess.run(["ldd", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    return f"{version.partition(' ')[2] or version}; {libc.partition(' ')[2] or libc}"


def counted(argv):
    """callgrind's total instructions of one run of argv, and its stdout."""
    with tempfile.TemporaryDirectory() as tmp:
        done = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={tmp}/out"] + argv,
                              capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"instruction_counts: {' '.join(argv)} failed under valgrind: {done.stderr[-1000:]}")
    return int(re.search(r"Collected : (\d+)", done.stderr).group(1)), done.stdout


def units(unit, stdout, extra):
    """What the extra repeats did: the solver's steps or impacts (its JSON), or the repeats themselves."""
    if unit in ("step", "impact"):
        return extra * json.loads(stdout)["steps" if unit == "step" else "impacts"]
    if unit == "batch impact":  # fraccontact-bench batch runs its batch 5 times
        return extra * 5
    return extra


def measure(row, paths):
    argv = [str(paths.get(word, word)) for word in row["command"].split()]
    counts = []
    for n in (row["n1"], row["n2"]):
        counts.append(counted([word.replace("{n}", str(n)) for word in argv]))
    (low, _), (high, out) = counts
    return (high - low) / units(row["unit"], out, row["n2"] - row["n1"])


def main(argv):
    update = argv[1:2] == ["--update"]
    args = argv[2:] if update else argv[1:]
    if len(args) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    solve, bench, importer, fmu_binary, compiler = args
    paths = {"fraccontact-solve": solve, "fraccontact-bench": bench, "fmu_importer": importer,
             "FMU_BINARY": fmu_binary}
    toolchain, rows = read_record()
    here = toolchain_of(compiler)
    if shutil.which("valgrind") is None:
        print("instruction_counts: skipped: valgrind is not installed")
        return SKIP
    if not update and here != toolchain:
        print(f"instruction_counts: skipped: the record counts {toolchain!r}, this build is {here!r}")
        return SKIP
    failed, lines = [], []
    for row in rows:
        value = measure(row, paths)
        ratio = value / row["record"]
        verdict = "ok"
        if ratio > 1.0 + ABOVE:
            verdict = f"FAILED: {100 * (ratio - 1):.1f} % more than the record (at most {100 * ABOVE:.0f} %)"
        elif ratio < 1.0 - BELOW:
            verdict = (f"FAILED: {100 * (1 - ratio):.1f} % fewer than the record (at most {100 * BELOW:.0f} %): "
                       "update the record (--update) in a commit that says why")
        if verdict != "ok":
            failed.append(row["name"])
        print(f"{row['name']:24} {value:12.1f} per {row['unit']:20} record {row['record']:12.1f} "
              f"({ratio:.4f})  {verdict}", flush=True)
        lines.append("\t".join([row["name"], row["unit"], f"{value:.1f}", str(row["n1"]), str(row["n2"]),
                                row["command"]]))
    if update:
        head = [line for line in RECORD.read_text().splitlines() if line.startswith("#")
                and not line.startswith("# toolchain:")]
        RECORD.write_text("\n".join(head + [f"# toolchain: {here}"] + lines) + "\n")
        print(f"instruction_counts: {RECORD} rewritten")
        return 0
    if failed:
        print(f"instruction_counts: {len(failed)} of {len(rows)} rows outside their record: {', '.join(failed)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
