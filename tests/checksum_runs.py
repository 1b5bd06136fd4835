"""Every figure of a set of runs, in hex, for comparing two builds to the
last bit (a refactoring of the model must leave them all equal):

    PYTHONPATH=python FRACCONTACT_LIBRARY=build/libfraccontact.so \
        python tests/checksum_runs.py build > after.txt

(the FMUs are BUILD/fraccontact.fmu and BUILD/fraccontact-fmi3.fmu). One
line per figure, "run figure value.hex()"; a time series is one line per
column, the SHA-256 of its doubles and how many there are. The last line
counts the figures. Not a test: diff the output of the two builds."""

import hashlib
import sys

import numpy as np
from fmpy import simulate_fmu

from fraccontact import model

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
)
FMU_RUNS = dict(
    drop={},
    drop_law2_tolerance=dict(law=2, tolerance=1e-6),
    drop_springpot=dict(damper=2),
    drop_gravity=dict(g=9.81, gap0=1e-3),
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


if __name__ == "__main__":
    library_runs()
    fmu_runs(sys.argv[1])
    print("figures", count)
