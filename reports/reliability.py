"""Reliability report: scale (10 000 instances), threads, a soak of 1e8
internal steps with resident memory sampled, hours of bouncing through the
FMU, valgrind memcheck over the C tests, the fuzzer's executions and the
line coverage its corpus reaches, and the hostile-input table. Writes
docs/reliability.md (and docs/reliability_hostile.md), keeping its mutation
section (scripts/report mutation) as it is.

Regenerate: scripts/report reliability   (about ten minutes; builds build-fuzz and build-coverage)
"""

import argparse
import json
import pathlib
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

from tqdm import tqdm

from fraccontact import atomic
from fraccontact.output import make_folder

from . import BAR, source_tree

ROOT = source_tree()


def fmu_sources():
    """The FMU's C sources as its modelDescription.xml lists them (co-simulation's SourceFiles, the fullest),
    each found in the folder that holds it."""
    names = [f.get("name") for f in ET.parse(ROOT / "modelDescription.xml").getroot().iter("File")]
    folders = ("model", "fmu_src/glue", "fmu_src/binding")
    return list(dict.fromkeys(next(f"{d}/{n}" for d in folders if (ROOT / d / n).exists()) for n in names))


FMU_SOURCES = fmu_sources()


def sh(*args, **kw):
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=ROOT, **kw)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, args))} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    return done


def soak(build):
    run = lambda *a: json.loads(sh(build / "fraccontact-soak", *a).stdout)
    return dict(instances=run("instances", 10000), memory=run("memory"), threads=run("threads", 8), steps=run("steps", 1e8),
                resting=run("fmu-seconds", 60))


def valgrind(build):
    tests = [[build / "test_g1"], [build / "test_fmi2"], [build / "test_g1_grid"], [build / "test_contact"],
             [build / "fuzz_replay", *sorted((ROOT / "tests" / "fuzz_corpus").glob("*.bin")),
              *sorted((ROOT / "tests" / "fuzz_regressions").glob("*"))]]
    rows = []
    for cmd in tests:
        done = subprocess.run(["valgrind", "--tool=memcheck", "--error-exitcode=99", "--leak-check=full",
                               "--errors-for-leak-kinds=definite,indirect", *map(str, cmd)],
                              capture_output=True, text=True, cwd=ROOT)
        summary = re.search(r"ERROR SUMMARY: (\d+) errors", done.stderr)
        leaks = re.search(r"definitely lost: ([\d,]+) bytes", done.stderr)
        rows.append(dict(test=pathlib.Path(cmd[0]).name, exit=done.returncode,
                         errors=int(summary.group(1)) if summary else -1,
                         definitely_lost=leaks.group(1) if leaks else "0"))
    return rows


def fuzz(seconds):
    """Fuzzes for a while in build-fuzz (keeping its corpus), then measures
    the line coverage of the FMU's sources that the corpus reaches."""
    sh("cmake", "-S", ".", "-B", "build-fuzz", f"-DPython3_EXECUTABLE={ROOT / '.venv/bin/python'}",
       "-DFRACCONTACT_FUZZ=ON", env=dict(__import__("os").environ, CC="clang"))
    sh("cmake", "--build", "build-fuzz", "--target", "fuzz_fmi2", "-j", "2")
    corpus = ROOT / "build-fuzz" / "fuzz_corpus"
    corpus.mkdir(exist_ok=True)
    # -timeout: an input slow enough to hang the report is a finding (fuzz-crash-*), not a wait
    done = subprocess.run([ROOT / "build-fuzz" / "fuzz_fmi2", f"-max_total_time={seconds}", "-print_final_stats=1",
                           "-timeout=10", "-artifact_prefix=build-fuzz/fuzz-crash-", corpus,
                           ROOT / "tests" / "fuzz_corpus"],
                          capture_output=True, text=True, cwd=ROOT)
    stats = dict(re.findall(r"stat::(\w+):\s+(\d+)", done.stderr))
    edges = re.findall(r"cov: (\d+)", done.stderr)
    # Line coverage: the harness and the sources built with clang's profile
    # instrumentation, replaying the corpus.
    out = ROOT / "build-coverage"
    out.mkdir(exist_ok=True)
    headers = sh(ROOT / ".venv/bin/python", "-c",
                 "import fmpy, os; print(os.path.join(os.path.dirname(fmpy.__file__), 'c-code'))").stdout.strip()
    sh("clang", "-O1", "-fprofile-instr-generate", "-fcoverage-mapping", "-Imodel", "-Ifmu_src/glue",
       "-Ifmu_src/binding", f"-I{headers}",
       "-Ibuild/generated/fraccontact", "tests/fuzz_replay.c", "tests/fuzz_fmi2.c", *FMU_SOURCES, "-lm",
       "-o", out / "replay")
    inputs = sorted(str(p) for p in corpus.iterdir()) + sorted(str(p) for p in (ROOT / "tests/fuzz_corpus").iterdir())
    profraw = out / "replay.profraw"
    for i in range(0, len(inputs), 500):  # the command line has a limit
        subprocess.run([out / "replay", *inputs[i:i + 500]], cwd=ROOT, capture_output=True,
                       env=dict(__import__("os").environ, LLVM_PROFILE_FILE=str(out / f"replay-{i}.profraw")))
    sh("llvm-profdata", "merge", "-sparse", *sorted(out.glob("replay-*.profraw")), "-o", out / "replay.profdata")
    report = sh("llvm-cov", "report", out / "replay", f"-instr-profile={out / 'replay.profdata'}",
                *FMU_SOURCES).stdout
    profraw.unlink(missing_ok=True)
    return dict(executions=int(stats.get("number_of_executed_units", 0)),
                per_second=int(stats.get("average_exec_per_sec", 0)), edges=int(edges[-1]) if edges else 0,
                corpus=len(inputs), crashed=done.returncode != 0, report=report)


MUTATION_BEGIN, MUTATION_END = "<!-- mutation:begin -->", "<!-- mutation:end -->"


def mutation_section(path):
    """The mutation table (scripts/report mutation) lives in the same file
    but is another report's: it is kept as it is, markers included."""
    text = path.read_text() if path.exists() else ""
    start, end = text.find(MUTATION_BEGIN), text.find(MUTATION_END)
    return text[start:end + len(MUTATION_END)] + "\n" if 0 <= start < end else ""


# What CI's fuzzing runs, from the harnesses' budget (tests/fuzz_program.h) and
# the fuzz tests' floors (CMakeLists.txt, add_fmi_fuzzer; tests/fuzz_rate.py):
# tests/test_reliability_claims.py reads both.
FUZZ_BUDGET = ("Each input's work is bounded (`tests/fuzz_program.h`): at most 1,024 internal steps in all its "
               "steps of dt_max and 262,144 terms of a full G1 history's sums, and the fuzzers build the FMU with "
               "a limit of 4,096 internal steps a communication step with the sanitizers and 16,384 without (its own is 1e9), which a light striker's "
               "contact (refined far below dt_max) or error-controlled steps (not capped by dt_max) would otherwise "
               "pass; so no input runs long (`fuzz_replay "
               "-timeout=1` fails one that takes a second of CPU, in every build). CI fuzzes each harness for 30 s "
               "with ASan and UBSan, then 10 s without sanitizers (`scripts/test`, FUZZ_SECONDS = 60); the fuzz "
               "tests fail below 250 inputs per second of CPU with the sanitizers and 1,000 without "
               "(`tests/fuzz_rate.py`, which prints each run's count): on an idle core, CI's fuzzing runs at least "
               "17,500 inputs a harness.")


def configuration_name(c):
    """A configuration of fraccontact-soak memory, as the page names it."""
    if c["damper"] == 1:
        return "dashpot"
    if c["memory"] == 1:
        return "springpot, memory = 1 (before its first step)"
    return f"springpot, memory = 2, memory_tolerance = {c['memory_tolerance']:g} (M = {c['modes']})"


def memory_sentence(m):
    """The memory an instance holds per configuration (fraccontact-soak memory)."""
    sizes = "; ".join(f"{configuration_name(c)}: {c['instance_bytes']:,} B, state {c['state_bytes']:,} B"
                      for c in m["configurations"])
    return ("- **Memory per configuration** (`fraccontact-soak memory`: the heap bytes an initialized FMU instance "
            "holds with 1,000 alive, malloc's own overhead included, and its serialized FMU state's size): " + sizes + ". A dashpot "
            "instance holds no springpot memory: at most 2 KiB. The compressed memory's M modes take, in the model "
            "and again in its prediction of the next step, one block of 12 arrays of M doubles rounded up to whole "
            "8 lanes, allocated at initialization (never in a step); the FMU state 8 B a mode. The full G1 "
            "history's buffer grows as the run steps (16 B a step; 8 B a step in the state). An exported FMU "
            "that does not offer F_avg_next keeps no prediction (docs/export.md).")


def write(path, s, v, f, hostile_summary):
    steps = s["steps"]
    lines = ["# Reliability", "",
             "Regenerate: `scripts/report reliability` (about ten minutes). Measured on this machine "
             "(2 cores); the figures are this run's.", "",
             "## Scale, threads, soak", "",
             f"- **{s['instances']['instances']:,} instances alive at once** in one process: resident memory "
             f"{s['instances']['rss_before_mib']:.1f} MiB before, {s['instances']['rss_alive_mib']:.1f} MiB with all "
             f"alive ({s['instances']['kib_per_instance']:.1f} KiB per instance: an instance holds the contact model "
             f"twice, its state and its prediction of the next communication step, "
             f"{s['instances']['bytes_contact_model']:,} B each with the dashpot, which holds no springpot memory); "
             f"each then run through an impact "
             f"(dt_max = 1e-6 s), {s['instances']['seconds_for_all_impacts']:.2f} s for all; every 997th compared "
             f"with the same instance alone: {'identical' if not s['instances']['sampled_differ_from_alone'] else 'DIFFERENT'}.",
             memory_sentence(s["memory"]),
             f"- **{s['threads']['threads']} threads** stepping {s['threads']['instances']} distinct instances at "
             f"once (FMI allows that; nothing in the FMU is shared): results "
             f"{'identical, bit for bit,' if s['threads']['identical_to_one_thread'] else 'DIFFERENT'} to one thread "
             f"({s['threads']['seconds_one_thread']:.2f} s alone, {s['threads']['seconds_threaded']:.2f} s threaded "
             f"on {s['threads']['cores']} cores).",
             "- **Thread safety in CI**: `tests/test_threads.c` runs both FMUs and the library's batch, built with "
             "ThreadSanitizer, in parallel threads, in every configuration whose code differs, each run against the "
             "same run alone, bit for bit; a data race fails it (ctest `c_threads`).",
             f"- **{steps['internal_steps']:,} internal steps** of a striker bouncing under gravity "
             f"({steps['impacts']} impacts, {steps['simulated_seconds']:.1f} s simulated, {steps['wall_seconds']:.1f} s "
             f"of CPU): resident memory sampled every tenth of the run "
             f"{', '.join(f'{x:.2f}' for x in steps['rss_mib_samples'])} MiB, at most {steps['rss_mib_max']:.2f} MiB. "
             f"The model's whole state is {steps['state_bytes']} bytes: the G1 law on the straight-line grid has a "
             "closed form, so there is no history to grow.",
             f"- **{s['resting']['simulated_seconds']:.0f} simulated seconds** through the FMU of a striker that "
             "bounces under gravity and then rests on the specimen, in contact, its dashpot creeping "
             f"({s['resting']['communication_steps']:,} communication steps of 1 ms, dt_max = 1e-6 s, "
             f"{s['resting']['wall_seconds']:.1f} s): resident memory {s['resting']['rss_mib_start']:.2f} MiB at the "
             f"start, at most {s['resting']['rss_mib_max']:.2f} MiB.",
             "", "## valgrind memcheck over the C tests", "",
             "| test | memcheck errors | definitely lost | the test's own checks |", "|---|---|---|---|"]
    lines += [f"| {r['test']} | {r['errors']} | {r['definitely_lost']} bytes | "
              f"{'pass' if r['exit'] == 0 else 'fail' if r['exit'] != 99 else 'not run to the end'} |" for r in v]
    if any(r["exit"] not in (0, 99) for r in v):
        lines += ["", "A test whose own checks fail under valgrind but not natively: valgrind computes `long double` "
                  "in 64 bits, so test_g1's extended-precision reference of the G1 ratio loses the digits its "
                  "1e-14 tolerance relies on (the checks then miss by 1.1e-14 to 1.6e-14). Memcheck itself finds "
                  "nothing there."]
    lines += ["", "## Fuzzing the FMI API", "",
              "`tests/fuzz_fmi2.c` reads bytes as a program of FMI calls on two instances (instantiate, set and get "
              "any value reference with raw doubles — NaN, Inf, denormals —, initialization, steps from any time, "
              "states got, set, serialized and deserialized from mutated or truncated bytes, reset, terminate, free; "
              "for Model Exchange, its instance, a solver's evaluation (a state moved, the time, derivatives, event "
              "indicators and nominals required finite) and its modes) "
              "and checks after each call that the status is one the standard allows and that readable outputs "
              "are finite with F >= 0; `tests/fuzz_fmi3.c` does the same for FMI 3.0. Every input that ever broke "
              "them is replayed in every build (`tests/fuzz_regressions/`).", "",
              FUZZ_BUDGET, "",
              f"This run: **{f['executions']:,} executions** ({f['per_second']:,} per second, libFuzzer with ASan and "
              f"UBSan), {f['edges']} coverage edges, a corpus of {f['corpus']} inputs, "
              f"{'a CRASH (see build-fuzz/fuzz-crash-*)' if f['crashed'] else 'no crash'}. Line coverage of the FMU's "
              "sources reached by replaying the corpus (clang source-based coverage):", "", "```",
              f["report"].strip(), "```", "",
              "## Hostile and degenerate input", "",
              f"{hostile_summary} The table, case by case: [reliability_hostile.md](reliability_hostile.md) "
              "(`scripts/report hostile`); pytest runs the same cases in CI (`tests/test_hostile.py`)."]
    kept = mutation_section(path)
    atomic.write_text(path, "\n".join(lines) + "\n" + ("\n" + kept if kept else ""))


def main(argv=None, prog=None):
    parser = argparse.ArgumentParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", type=pathlib.Path, default=ROOT / "build")
    parser.add_argument("--fuzz-seconds", type=int, default=300)
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "docs")
    args = parser.parse_args(argv)
    make_folder(parser, args.out)
    with tqdm(total=4, file=sys.stderr, disable=None, bar_format=BAR) as bar:
        bar.set_description("soak")
        s = soak(args.build)
        bar.update()
        bar.set_description("valgrind")
        v = valgrind(args.build)
        bar.update()
        bar.set_description(f"fuzzing {args.fuzz_seconds} s")
        f = fuzz(args.fuzz_seconds)
        bar.update()
        bar.set_description("hostile input")
        done = subprocess.run([sys.executable, "-m", "reports", "hostile", "--out", args.out],
                              capture_output=True, text=True)
        bar.update()
    summary = done.stdout.strip().splitlines()[0] if done.stdout.strip() else "the hostile report failed"
    write(args.out / "reliability.md", s, v, f, f"Cases: {summary}.")
    print((args.out / "reliability.md").read_text())
    bad = f["crashed"] or done.returncode != 0 or any(r["errors"] != 0 for r in v) \
        or not s["threads"]["identical_to_one_thread"] or s["instances"]["sampled_differ_from_alone"]
    return 1 if bad else 0

