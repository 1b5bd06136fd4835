"""Hostile and degenerate input across the FMU's whole surface: every real
parameter and input at 0, negative, denormal, huge (1e300), NaN and +-Inf;
communication steps of 1e-15 s and 1e3 s; a step that does not start at the
last communication point; inputs changed during contact. Each case runs in
its own process (a crash would be caught, not fatal) and must end in a
clear error (status and message) or a correct result: finite outputs and
F >= 0. Writes the table to docs/reliability_hostile.md (part of
docs/reliability.md's evidence) and exits 1 if any case fails.

Regenerate: scripts/report hostile
"""

import argparse
import json
import math
import pathlib
import subprocess
import sys

import atomic
from progress import progress

ROOT = pathlib.Path(__file__).resolve().parent.parent
REALS = ["v", "m", "R", "E_i", "nu_i", "E_s", "nu_s", "k", "c", "dt_max", "g", "gap0"]
VALUES = {"0": 0.0, "negative": -1.0, "denormal": 5e-324, "huge": 1e300, "NaN": math.nan, "+Inf": math.inf,
          "-Inf": -math.inf}
OUTPUTS = ["F", "F_avg", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps", "semi_integral"]

def run_case_in(s, case):
    """Runs one case on s, a fresh instance not yet in initialization mode
    (tests/fmu_driver.Slave); returns its outcome and the last error message."""
    from fmpy.fmi1 import FMICallException
    out = dict(result="ran")
    try:
        s.enter()
        out["result"] = "refused when set"
        for name, value in case.get("values", {}).items():
            s.set(**{name: value})
        out["result"] = "refused at initialization"
        s.fmu.exitInitializationMode()
        out["result"] = "error in a step"
        for kind, arg in case.get("steps", [["step", 1e-5]] * 200):
            if kind == "step":
                s.step(arg)
            elif kind == "at":                  # a step from the wrong time
                s.fmu.doStep(currentCommunicationPoint=arg, communicationStepSize=1e-5)
            else:
                s.set(**arg)
            values = [s.get(n) for n in OUTPUTS]
            if not all(math.isfinite(v) for v in values):
                out.update(result="NON-FINITE OUTPUT", values=values)
                break
            if s.get("F") < 0:
                out["result"] = "TENSION"
                break
        else:
            out.update(result="ran", F_peak=s.get("F_peak"), eps=s.get("eps"))
    except FMICallException:
        pass
    errors = [m for status, category, m in s.log if status >= 3]
    out["message"] = errors[-1] if errors else ""
    return out


# One case in a child process of its own, so that a crash is a finding.
CHILD = r'''
import json, sys
sys.path[:0] = [sys.argv[1], sys.argv[2]]
from fmpy import extract, read_model_description
from fmu_driver import Slave
from hostile import run_case_in
md = read_model_description(sys.argv[3])
print(json.dumps(run_case_in(Slave(md, extract(sys.argv[3]), start=False), json.loads(sys.argv[4]))))
'''


def cases():
    for name in REALS:
        for label, value in VALUES.items():
            yield f"{name} = {label}", dict(values={name: value})
    yield "communication step 1e-15 s", dict(steps=[["step", 1e-15]] * 10 + [["step", 1e-5]] * 200)
    yield "communication step 1e3 s", dict(steps=[["step", 1e3]])
    yield "communication step 1e3 s, dt_max 1 s", dict(values={"dt_max": 1.0}, steps=[["step", 1e3]])
    yield "a step from the wrong time", dict(steps=[["step", 1e-5], ["at", 0.5]])
    yield "driven: v changed during contact", dict(values={"scene": 2, "m": 0.0, "v": 0.5},
                                                   steps=[["step", 1e-4], ["set", {"v": -2.0}], ["step", 1e-4],
                                                          ["set", {"v": 5.0}], ["step", 1e-4]])
    yield "driven: m changed during contact", dict(values={"scene": 2, "m": 0.7, "v": 0.5},
                                                   steps=[["step", 1e-4], ["set", {"m": 1e-6}], ["step", 1e-4],
                                                          ["set", {"m": 0.0}], ["step", 1e-4]])
    yield "driven: v = 1e300 during contact", dict(values={"scene": 2, "m": 0.0, "v": 0.5},
                                                   steps=[["step", 1e-4], ["set", {"v": 1e300}], ["step", 1e-4]])
    yield "drop test: v and m changed during contact (ignored)", dict(
        steps=[["step", 1e-4], ["set", {"v": 99.0, "m": 1e-9}], ["step", 1e-3]])


def run_case(fmu, case):
    try:
        done = subprocess.run([sys.executable, "-c", CHILD, str(ROOT / "tests"), str(ROOT / "scripts"), str(fmu),
                               json.dumps(case)],
                              capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        return dict(result="HANG (over 300 s)", message="")
    if done.returncode != 0:
        return dict(result=f"CRASH (exit {done.returncode})", message=done.stderr.strip().splitlines()[-1:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def acceptable(r):
    if r["result"] in ("refused when set", "refused at initialization", "error in a step"):
        return bool(r["message"])            # an error must say why
    return r["result"] == "ran"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fmu", type=pathlib.Path, default=ROOT / "build" / "fraccontact.fmu")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "docs")
    args = parser.parse_args()
    all_cases = list(cases())
    rows = []
    for i, (name, case) in enumerate(all_cases):
        progress(i, len(all_cases), name)
        rows.append((name, run_case(args.fmu, case)))
    progress(len(all_cases), len(all_cases), "done")
    bad = [(n, r) for n, r in rows if not acceptable(r)]
    out = ["# Hostile and degenerate input", "",
           "Regenerate: `scripts/report hostile`. Each case runs through fmpy in a process of its own; it passes "
           "with a clear error (an FMI error status and a message, quoted) or a correct run (every output "
           "finite, F >= 0, over 2 ms of the h20 test unless stated).", "",
           f"**{len(rows) - len(bad)} of {len(rows)} cases pass.**", "",
           "| case | outcome | message or result |", "|---|---|---|"]
    for name, r in rows:
        detail = r.get("message") or (f"F_peak = {r['F_peak']:.6g} N, eps = {r['eps']:.4g}" if "F_peak" in r else "")
        detail = str(detail).replace("|", "/")
        out.append(f"| {name} | {r['result']}{'' if acceptable(r) else ' (FAIL)'} | {detail} |")
    args.out.mkdir(parents=True, exist_ok=True)
    atomic.write_text((args.out / "reliability_hostile.md"), "\n".join(out) + "\n")
    print(f"{len(rows) - len(bad)} passed, {len(bad)} failed")
    for name, r in bad:
        print(f"FAILED {name}: {r}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
