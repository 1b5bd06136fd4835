"""Whether a model compiled for one configuration pays: the FMU with the law
and the damper known at compile time against the general build, side by
side in callgrind's instructions and on the clock, and the decision the
clock supports, written into docs/export.md (between its markers
<!-- specialized:begin/end -->).

The configuration is the h20 drop test's, the default experiment of
tests/fmu_importer.c (law 1, the dashpot; 300 doSteps of 10 us). The
specialized build is a copy of the working tree whose model/contact_internal.h
answers the damper and the law with constants (SPECIALIZED below), built
for the FMI 2.0 FMU alone; the general one is this build's. Each binary runs
the experiment under callgrind with 1 and 3 repeats: the difference over 2
is one run's instructions, start-up cancelling (as tests/instruction_counts.py
counts). Both must print the same results to the last digit.

The clock: the two binaries' runs of the experiment (REPEATS times in one
process) alternate for ROUNDS rounds, the order swapped every round; each
run's CPU time (user and system, of the child), medians and the spread of
the rounds (their interquartile range over the median). The decision
follows the rule of docs/benchmarks.md: a ratio beyond the noise is off 1
by more than twice the larger spread and by over 3 %; only then would the
export ship a binary per law and damper (six per platform and FMI version)
instead of one. Instructions are exact but are not the time: they are
shown beside it.

Regenerate: scripts/report specialized (a configure and a build of the FMU:
a few minutes)."""

import pathlib
import re
import resource
import statistics
import subprocess
import tempfile

from fraccontact import atomic, output

from . import source_tree

ROOT = source_tree()
BEGIN, END = "<!-- specialized:begin -->", "<!-- specialized:end -->"
BEYOND_NOISE = 0.03  # docs/benchmarks.md: a ratio off 1 by over 3 % (and twice the larger spread)
ROUNDS, REPEATS = 11, 300  # a run of about a second: far above the clock's resolution
BINARY = pathlib.Path("fraccontact.fmu.d", "binaries", "linux64", "fraccontact.so")
# The edits that fix the configuration at compile time: (file, original, specialized).
SPECIALIZED = (
    ("model/contact_internal.h",
     "static inline int springpot(const contact_model *cm) { return cm->p.damper == CONTACT_DAMPER_SPRINGPOT; }",
     "static inline int springpot(const contact_model *cm) { (void)cm; return 0; }"),
    ("model/contact_internal.h",
     "    if (cm->p.law == CONTACT_LAW_HERTZ || cm->p.g1_nodes > 0)\n        return cm->k_fixed;\n"
     "    return n_steps > 0 ? cm->k * g1_ratio(cm->p.law, cm->p.spring_exponent, (double)n_steps) : cm->k;",
     "    if (cm->p.g1_nodes > 0)\n        return cm->k_fixed;\n"
     "    return n_steps > 0 ? cm->k * g1_ratio(CONTACT_LAW_G1, cm->p.spring_exponent, (double)n_steps) : cm->k;"),
)


def source_files():
    """The working tree's tracked and untracked (not ignored) files that exist."""
    out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                         capture_output=True, check=True).stdout.decode()
    return sorted({f for f in out.split("\0") if f and (ROOT / f).is_file()})


def specialized_copy(folder):
    """The working tree copied into folder with the SPECIALIZED edits; SystemExit where one no longer applies."""
    for name in source_files():
        target = folder / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes((ROOT / name).read_bytes())
    for name, old, new in SPECIALIZED:
        text = (folder / name).read_text()
        if text.count(old) != 1:
            raise SystemExit(f"{name}: the text {old!r} occurs {text.count(old)} times (expected once): "
                             "the source moved, rewrite SPECIALIZED")
        (folder / name).write_text(text.replace(old, new))


def built(folder):
    """The specialized copy's FMI 2.0 binary, built."""
    build = folder / "build"
    for command in (["cmake", "-S", folder, "-B", build, f"-DPython3_EXECUTABLE={ROOT / '.venv' / 'bin' / 'python'}"],
                    ["cmake", "--build", build, "--target", "fraccontact", "-j", "2"]):
        subprocess.run([str(c) for c in command], capture_output=True, check=True)
    return build / BINARY


def instructions(importer, binary, repeats):
    """callgrind's total instructions of the importer's run of binary, and what it printed."""
    done = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", str(importer),
                           str(binary), str(repeats)], capture_output=True, text=True, check=True)
    return int(re.search(r"Collected : (\d+)", done.stderr).group(1)), done.stdout


def per_run(importer, binary):
    """One run's instructions (the difference of 3 repeats and 1, over 2) and its printed results."""
    (one, printed), (three, _) = (instructions(importer, binary, n) for n in (1, 3))
    return (three - one) / 2, printed


def cpu_seconds(command):
    """The CPU time (user and system) of one run of command, a child of this process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(command, capture_output=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def spread(times):
    """The interquartile range of the rounds over their median."""
    q = statistics.quantiles(times, n=4)
    return (q[2] - q[0]) / statistics.median(times)


def clock(importer, general, specialized):
    """{"general"/"specialized": the rounds' CPU seconds per run of the experiment}, alternated."""
    times = {"general": [], "specialized": []}
    for i in range(ROUNDS):
        order = (("general", general), ("specialized", specialized))
        for side, binary in order if i % 2 == 0 else order[::-1]:
            times[side].append(cpu_seconds([str(importer), str(binary), str(REPEATS)]) / REPEATS)
    return times


def beyond_noise(ratio, noise):
    """docs/benchmarks.md's rule: off 1 by more than twice the larger spread and by over 3 %."""
    return abs(ratio - 1) > max(2 * noise, BEYOND_NOISE)


def section(general, specialized, times):
    ratio = specialized / general
    g, s = (statistics.median(times[k]) for k in ("general", "specialized"))
    noise = max(spread(times["general"]), spread(times["specialized"]))
    kept = s < g and beyond_noise(s / g, noise)
    return (f"{BEGIN}\nCompiled for the h20 drop test's configuration alone (law 1 and the dashpot known at compile "
            f"time), the FMU executes {specialized:,.0f} instructions per run of the default experiment (300 "
            f"doSteps) against the general build's {general:,.0f}: ratio {ratio:.3f}, the same results to the last "
            f"digit (`scripts/report specialized`, callgrind). On the clock, side by side ({ROUNDS} alternated "
            f"rounds of {REPEATS} runs): {1e3 * s:.3f} ms against {1e3 * g:.3f} ms of CPU per run, clock ratio "
            f"{s / g:.3f}, spread {100 * noise:.1f} %. "
            + ("That is beyond the noise (off 1 by more than twice the spread and by over 3 %, docs/benchmarks.md's "
               "rule): worth a binary per law and damper." if kept else
               "That is not beyond the noise (docs/benchmarks.md's rule: off 1 by more than twice the spread and by "
               "over 3 %): exported FMUs keep the general binary, one per platform and FMI version, rather than one "
               "per law and damper.")
            + f"\n{END}")


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    args = output.parse(parser, argv)
    page = args.out / "export.md"
    importer = ROOT / "build" / "fmu_importer"
    with tempfile.TemporaryDirectory() as folder:
        folder = pathlib.Path(folder)
        specialized_copy(folder)
        binary = built(folder)
        specialized, theirs = per_run(importer, binary)
        general, mine = per_run(importer, ROOT / "build" / BINARY)
        times = clock(importer, ROOT / "build" / BINARY, binary)
    if mine != theirs:
        raise SystemExit(f"the specialized build's results differ from the general build's:\n{theirs}\n{mine}")
    text = page.read_text()
    start, end = text.index(BEGIN), text.index(END) + len(END)
    atomic.write_text(page, text[:start] + section(general, specialized, times) + text[end:])
    print(f"wrote {page}")
