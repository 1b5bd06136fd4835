"""Figures of docs/reliability.md that every build measures again, not only
its report (scripts/report reliability): each test finds its sentence, reads
the figures as written there, and measures them on this build. A figure
that drifts, or a sentence reworded without its test, fails here."""

import json
import os
import pathlib
import re
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAGE = " ".join((ROOT / "docs" / "reliability.md").read_text().split())
SOAK = os.environ.get("FRACCONTACT_SOAK", str(ROOT / "build" / "fraccontact-soak"))


def claim(pattern):
    m = re.search(pattern, PAGE)
    assert m, f"docs/reliability.md no longer says {pattern!r}: update the sentence's test with it"
    return m.groups()


@pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                    reason="AddressSanitizer's redzones and shadow memory are resident memory too")
def test_the_memory_per_instance_is_what_an_instance_holds():
    """The resident memory per FMU instance, as fraccontact-soak measures it
    with that many instances alive, rounded to the page's digits; and the
    page's account of it: the dashpot's contact model twice (its size read
    from the build), with less than a page of memory besides."""
    count, kib, model = claim(r"\*\*([\d,]+) instances alive at once\*\*.*? \(([\d.]+) KiB per instance: "
                              r"an instance holds the contact model twice, its state and its prediction of "
                              r"the next communication step, ([\d,]+) B each with the dashpot, which holds no "
                              r"springpot memory\)")
    done = subprocess.run([SOAK, "instances", count.replace(",", "")], capture_output=True, text=True, check=True)
    measured = json.loads(done.stdout)
    assert measured["bytes_contact_model"] == int(model.replace(",", ""))
    decimals = len(kib.partition(".")[2])
    assert f"{measured['kib_per_instance']:.{decimals}f}" == kib, f"measured {measured['kib_per_instance']} KiB"
    per_instance = measured["kib_per_instance"] * 1024
    assert 2 * measured["bytes_contact_model"] <= per_instance < 2 * measured["bytes_contact_model"] + 4096


# What a springpot's FMU state adds to a dashpot's (docs/variables.md, FMU
# state; fmu_model.c writes it): damper_order, c_alpha, memory_tolerance
# (f64), memory (i32) and the count of the memory's values (u64), then 8 B a
# value: x2' and the M modes (memory = 2), or v and the G1 sum one step back
# and x2 at each step, x2(0) alone before the first (memory = 1).
SPRINGPOT_STATE = 3 * 8 + 4 + 8
# The compressed memory's block (model/model.c): 12 arrays of doubles, each
# of M rounded up to whole 8 lanes; one in the model, one in its prediction.
# malloc adds its header and alignment to each, under 32 B.
MODE_ARRAYS, LANES, MALLOC_OVERHEAD = 12, 8, 32


@pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                    reason="AddressSanitizer's allocator keeps its own account of the heap")
def test_the_memory_per_configuration_is_what_an_instance_allocates():
    """The heap bytes an initialized instance holds and its FMU state's
    size, per configuration, as fraccontact-soak memory measures them and
    the page writes them; a dashpot instance at most 2 KiB; and what a
    springpot adds, from the layouts: the state 8 B a value of its memory,
    the instance two blocks of 12 arrays of the modes padded to whole lanes,
    so that it grows with the kernel's mode count."""
    sizes, = claim(r"\*\*Memory per configuration\*\* \(`fraccontact-soak memory`: the heap bytes an initialized "
                   r"FMU instance holds with 1,000 alive, malloc's own overhead included, and its serialized FMU state's "
                   r"size\): "
                   r"(.*?)\. A dashpot instance holds no springpot memory: at most 2 KiB\.")
    rows = re.findall(r"(dashpot|springpot, memory = 1 \(before its first step\)|springpot, memory = 2, "
                      r"memory_tolerance = (\S+) \(M = (\d+)\)): ([\d,]+) B, state ([\d,]+) B", sizes)
    done = subprocess.run([SOAK, "memory"], capture_output=True, text=True, check=True)
    configs = json.loads(done.stdout)["configurations"]
    n = lambda text: int(text.replace(",", ""))
    assert [(c["damper"], c["memory"]) for c in configs[:2]] == [(1, 2), (2, 1)] and len(rows) == len(configs)
    for (_, tolerance, modes, held, state), c in zip(rows, configs):
        assert (n(held), n(state)) == (c["instance_bytes"], c["state_bytes"])
        if tolerance:
            assert (float(tolerance), int(modes)) == (c["memory_tolerance"], c["modes"])
    dashpot, history, compressed = configs[0], configs[1], configs[2:]
    assert dashpot["instance_bytes"] <= 2048
    assert history["state_bytes"] == dashpot["state_bytes"] + SPRINGPOT_STATE + 8 * 4
    assert history["instance_bytes"] == dashpot["instance_bytes"]  # no history before the first step
    for c in compressed:
        room = -(-c["modes"] // LANES) * LANES
        block = MODE_ARRAYS * 8 * room
        assert c["state_bytes"] == dashpot["state_bytes"] + SPRINGPOT_STATE + 8 * (1 + c["modes"])
        assert 2 * block <= c["instance_bytes"] - dashpot["instance_bytes"] < 2 * (block + MALLOC_OVERHEAD)
    assert [c["modes"] for c in compressed] == sorted({c["modes"] for c in compressed})
    assert [c["instance_bytes"] for c in compressed] == sorted({c["instance_bytes"] for c in compressed})


def test_the_fuzzing_ci_runs_is_what_the_harnesses_and_the_fuzz_tests_allow():
    """The budget of an input as the harnesses define it, the FMU's step limit
    in the fuzzers and its own, the seconds and
    the floors of the fuzz tests as CMake and scripts/test set them, and the
    count CI runs at least, which follows from them."""
    steps, terms, sanitized_limit, plain_limit, own, timeout, sanitized, plain, sanitized_floor, plain_floor, at_least = claim(
        r"Each input's work is bounded \(`tests/fuzz_program.h`\): at most ([\d,]+) internal steps in all its steps "
        r"of dt_max and ([\d,]+) terms of a full G1 history's sums, and the fuzzers build the FMU with a limit of "
        r"([\d,]+) internal steps a communication step with the sanitizers and ([\d,]+) without \(its own is (\S+)\), "
        r"which a light striker's contact "
        r"\(refined far below dt_max\) or error-controlled steps \(not capped by dt_max\) would otherwise pass; so no "
        r"input runs long \(`fuzz_replay -timeout=(\d+)` "
        r"fails one that takes a second of CPU, in every build\)\. CI fuzzes each harness for (\d+) s with ASan and "
        r"UBSan, then (\d+) s without sanitizers \(`scripts/test`, FUZZ_SECONDS = 60\); the fuzz tests fail below "
        r"([\d,]+) inputs per second of CPU with the sanitizers and ([\d,]+) without \(`tests/fuzz_rate.py`, which "
        r"prints each run's count\): on an idle core, CI's fuzzing runs at least ([\d,]+) inputs a harness\.")
    n = lambda text: int(text.replace(",", ""))
    program = (ROOT / "tests" / "fuzz_program.h").read_text()
    assert float(re.search(r"#define BUDGET_STEPS ([\d.]+)", program).group(1)) == n(steps)
    assert float(re.search(r"#define BUDGET_TERMS ([\d.]+)", program).group(1)) == n(terms)
    cmake = (ROOT / "CMakeLists.txt").read_text()
    fuzzer = cmake[cmake.index("function(add_fmi_fuzzer"):cmake.index("endfunction()", cmake.index("function(add_fmi_fuzzer"))]
    limits = [sanitized_limit.replace(",", ""), plain_limit.replace(",", "")]
    assert re.findall(r"set\(max_steps (\d+)\)", fuzzer) == limits
    assert "MAX_STEPS=${max_steps}" in fuzzer
    glue = (ROOT / "fmu_src" / "binding" / "fmu_model.c").read_text()
    assert float(re.search(r"#define MAX_STEPS (\d+)", glue).group(1)) == float(own)
    assert re.findall(r"set\(floor (\d+)\)", fuzzer) == [sanitized_floor.replace(",", ""), plain_floor.replace(",", "")]
    assert f"-timeout={timeout}" in fuzzer
    assert re.findall(r"fuzz_replay(?:_fmi3)? -timeout=(\d+)", cmake) == [timeout, timeout]
    assert re.search(r'FRACCONTACT_FUZZ_PLAIN_SECONDS (\d+) CACHE', cmake).group(1) == plain
    script = (ROOT / "scripts" / "test").read_text()
    assert '-DFRACCONTACT_FUZZ_SECONDS="$(( ${FUZZ_SECONDS:-60} / 2 ))"' in script and n(sanitized) == 60 // 2
    assert n(at_least) == n(sanitized) * n(sanitized_floor) + n(plain) * n(plain_floor)
