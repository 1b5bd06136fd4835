"""Runs a libFuzzer harness (the ctest tests 'fuzz' and 'fuzz_fmi3' of a
build with FRACCONTACT_FUZZ) and fails when it ran fewer inputs a second of
its CPU time than MIN_RATE: the harnesses bound each input's work
(tests/fuzz_program.h), and docs/reliability.md states what CI's fuzz
seconds run from this floor. Per second of CPU, not of the clock, so that a
loaded machine does not fail it.
    python fuzz_rate.py MIN_RATE FUZZER [LIBFUZZER OPTIONS AND CORPUS FOLDERS...]"""

import re
import resource
import subprocess
import sys


def main(argv):
    if len(argv) < 3:
        raise SystemExit(__doc__)
    min_rate, command = float(argv[1]), argv[2:]
    done = subprocess.run(command, stderr=subprocess.PIPE, text=True)
    sys.stderr.write(done.stderr)
    if done.returncode != 0:
        return done.returncode
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = used.ru_utime + used.ru_stime
    units = re.search(r"stat::number_of_executed_units:\s+(\d+)", done.stderr)
    if not units:
        print("fuzz_rate: libFuzzer printed no stat::number_of_executed_units (run it with -print_final_stats=1)")
        return 1
    rate = int(units.group(1)) / cpu
    print(f"fuzz_rate: {int(units.group(1)):,} inputs in {cpu:.1f} s of CPU: {rate:,.0f} a second "
          f"(at least {min_rate:,.0f} asked)")
    return 0 if rate >= min_rate else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
