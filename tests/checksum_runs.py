"""Every figure of a set of runs, in hex, for comparing two builds to the
last bit (a refactoring of the model must leave them all equal):

    PYTHONPATH=python FRACCONTACT_LIBRARY=build/libfraccontact.so \
        python tests/checksum_runs.py build > after.txt

(the FMUs, the solver and the scenes' SSPs are BUILD's: the library runs,
the FMUs' runs in fmpy, the solver's JSON answers, and the crash scenes in
fmpy and libcosim). One line per figure, "run figure value.hex()"; a time series is one line per
column, the SHA-256 of its doubles and how many there are. The last line
counts the figures. Not a test: diff the output of the two builds."""

import hashlib
import json
import os
import subprocess
import sys

import numpy as np
from fmpy import simulate_fmu

# The package loads the library of the build compared.
os.environ.setdefault("FRACCONTACT_LIBRARY", f"{sys.argv[1]}/libfraccontact.so")
os.environ.setdefault("FRACCONTACT_FMU", f"{sys.argv[1]}/fraccontact.fmu")
from fraccontact import model  # noqa: E402

LAW_N = {f"law{law}_n{n}": dict(law=law, spring_exponent=n, k=3.299e8) for law in (1, 2, 3) for n in (1.0, 1.5, 2.0)}
SPRINGPOT = dict(damper="springpot")
GRAVITY = dict(g=9.81, gap0=1e-3, impacts=3, t_end=1.0)
RUNS = dict(
    LAW_N,
    law2_g1_nodes=dict(law=1, g1_nodes=50),
    central=dict(scheme="central", dt_max=1e-7),
    springpot_compressed=dict(SPRINGPOT, memory="compressed"),
    springpot_compressed_alpha08=dict(SPRINGPOT, damper_order=0.8, c_alpha=3e4),
    springpot_full=dict(SPRINGPOT, memory="full", dt_max=2e-7),
    tolerance_law2=dict(law=2, tolerance=1e-6),
    tolerance_law2_n2=dict(law=2, tolerance=1e-7, spring_exponent=2.0, k=3e10, dt_max=1e-5),
    tolerance_g1_nodes=dict(law=1, g1_nodes=100, tolerance=1e-6),
    tolerance_springpot=dict(SPRINGPOT, law=2, tolerance=1e-7),
    gravity_fixed=dict(GRAVITY),
    gravity_law2_fixed=dict(GRAVITY, law=2),
    gravity_tolerance=dict(GRAVITY, law=2, tolerance=1e-6),
    gravity_springpot=dict(GRAVITY, **SPRINGPOT),
    gravity_springpot_tolerance=dict(GRAVITY, law=2, tolerance=1e-7, **SPRINGPOT),
    gravity_central=dict(GRAVITY, scheme="central", dt_max=1e-7),
    driven_m0=dict(scene="driven", v=0.3, m=0.0, t_end=2e-3),
    driven_proxy=dict(scene="driven", v=0.3, m=0.5, t_end=2e-3),
    driven_springpot=dict(SPRINGPOT, scene="driven", v=0.3, m=0.0, t_end=2e-3),
    two_bodies=dict(v2=-0.2, m2=2.0),
    two_bodies_springpot_tolerance=dict(SPRINGPOT, law=2, tolerance=1e-7, v2=0.1, m2=5.0),
    springpot_full_law3=dict(SPRINGPOT, law=3, memory="full", dt_max=5e-7),
    law3_central=dict(law=3, scheme="central", dt_max=1e-7),
    tolerance_n1=dict(law=2, tolerance=1e-6, spring_exponent=1.0, k=3e6),
    hertz_from_material=dict(law=2, k=0.0),
)
SOLVER_RUNS = dict(
    default=[],
    law2_tolerance=["--law", "2", "--tolerance", "1e-7", "--dt-max", "1e-3"],
    springpot_tolerance=["--law", "2", "--damper", "2", "--tolerance", "1e-6"],
    springpot_full=["--damper", "2", "--memory", "1", "--dt-max", "5e-7"],
    gravity=["--g", "9.81", "--gap0", "1e-3", "--impacts", "2", "--law", "2"],
    two_bodies=["--v2", "-0.2", "--m2", "2"],
    driven=["--scene", "2", "--v", "0.3", "--m", "0", "--t-end", "2e-3"],
    reference=["--reference"],
)
SCENES = [("headform", "fmpy"), ("bumper", "fmpy"), ("headform", "libcosim"), ("bumper", "libcosim")]
FMU_RUNS = dict(
    drop={},
    drop_law2_tolerance=dict(law=2, tolerance=1e-6),
    drop_springpot=dict(damper=2),
    drop_gravity=dict(g=9.81, gap0=1e-3),
    drop_springpot_full=dict(damper=2, memory=1),
    drop_law3=dict(law=3),
    two_bodies=dict(v2=-0.2, m2=2.0),
    driven_m0=dict(scene=2, v=0.3, m=0.0),
    driven_proxy=dict(scene=2, v=0.3, m=0.5),
)
FMU_OUTPUTS = ["F", "F_avg", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps", "semi_integral"]

count = 0


def show(run, name, value):
    global count
    if isinstance(value, str):
        print(run, name, value)
        return
    a = np.ascontiguousarray(np.asarray(value, dtype=float))
    if a.size == 1:
        print(run, name, float(a.reshape(())).hex())
    else:
        print(run, name, a.size, hashlib.sha256(a.tobytes()).hexdigest())
    count += a.size


def library_runs():
    for run, params in RUNS.items():
        s = model.simulate(output_interval=0, **params)
        for column in ("t", "F", "x", "x1", "x2", "v", "E_diss"):
            show(run, column, s[column])
        r = s.run
        for name in model.IMPACT_FIGURES:
            show(run, name, r[name])
        for name in model.END_FIGURES:
            show(run, "end." + name, r.end[name])
        show(run, "impacts", r.impacts)
        show(run, "steps", r.steps)
        show(run, "k", r.k)
        for i, impact in enumerate(r.per_impact):
            for name in model.IMPACT_FIGURES:
                show(run, f"impact{i}.{name}", impact[name])


def fmu_runs(build):
    for fmu in ("fraccontact.fmu", "fraccontact-fmi3.fmu"):
        for run, start in FMU_RUNS.items():
            result = simulate_fmu(f"{build}/{fmu}", stop_time=2e-3, output_interval=1e-5, start_values=start,
                                  output=FMU_OUTPUTS)
            for name in FMU_OUTPUTS:
                show(f"{fmu}:{run}", name, result[name])


def solver_runs(build):
    for run, options in SOLVER_RUNS.items():
        out = subprocess.run([f"{build}/fraccontact-solve", "--json", "--quiet", *options], check=True,
                             capture_output=True, text=True).stdout
        flat(f"solve:{run}", json.loads(out))


def flat(run, value, name=""):
    """Every number of a JSON answer, by its path; times measured on the clock left out."""
    if isinstance(value, dict):
        for key, item in value.items():
            if "seconds" not in key:
                flat(run, item, f"{name}.{key}" if name else key)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            flat(run, item, f"{name}[{i}]")
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        show(run, name, float(value))
    else:
        show(run, name, str(value))


def scene_runs():
    from fraccontact.scenes import masters
    for scene, master in SCENES:
        trace = masters.run(scene, master)
        for name in sorted(trace):
            show(f"scene:{scene}:{master}", name, trace[name])
        flat(f"scene:{scene}:{master}:figures", masters.figures(trace, scene))


if __name__ == "__main__":
    library_runs()
    fmu_runs(sys.argv[1])
    solver_runs(sys.argv[1])
    scene_runs()
    print("figures", count)
