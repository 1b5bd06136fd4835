"""Writes docs/fitting.md's example drop-test data (docs/examples/*.csv): measured-
looking force curves and a drop campaign made by the contact FMU (through fmpy)
from stated constants, with Gaussian noise of stated seeds, so that the
`fraccontact fit` commands of docs/fitting.md run as written and what they find can be
checked against the constants that made the data.

    .venv/bin/python docs/examples/make_examples.py [FMU [FOLDER]]   # build/fraccontact.fmu, docs/examples

The curves: the striker's mass 0.7437 kg dropped from the file's height; rows
every 2 us from a trigger 50 us before the contact onset (zero force there),
each force with 5 N of noise. h20_dashpot.csv: the Hertz spring k = 3e8
N/m^1.5 and the dashpot c = 5000 N s/m. h10/h20/h50_springpot.csv: the same
spring with the springpot alpha = 0.6, c_alpha = 6000 t_c^(alpha - 1) N s^alpha/m
(t_c the Hertz contact time at h20: damping like c = 6000 there). drops.csv:
that springpot's peak force and restitution at five heights, three drops
each, with 1 % noise on F_max and 0.01 on eps."""

import math
import pathlib
import sys

import numpy as np
from fmpy import simulate_fmu

HERE = pathlib.Path(__file__).resolve().parent
G, M = 9.81, 0.7437
K, C = 3e8, 5000.0
ALPHA = 0.6
STEP, TRIGGER, NOISE = 2e-6, 50e-6, 5.0
DROP_HEIGHTS, REPEATS = (0.005, 0.010, 0.020, 0.050, 0.100), 3


def speed(height):
    return math.sqrt(2 * G * height)


def hertz_contact_time(k, m, v):
    """2.94327 (5 m / (4 k))^(2/5) v^(-1/5): the elastic Hertz impact's duration."""
    return 2.9432751843247 * (5 * m / (4 * k)) ** 0.4 * v ** -0.2


C_ALPHA = 6000.0 * hertz_contact_time(K, M, speed(0.020)) ** (ALPHA - 1)
DASHPOT = dict(k=K, c=C, law=2)
SPRINGPOT = dict(k=K, damper=2, damper_order=ALPHA, c_alpha=C_ALPHA, law=2)


def run(fmu, height, stop, interval, outputs, **values):
    """The FMU's drop test from height (the striker touches at t = 0)."""
    return simulate_fmu(str(fmu), stop_time=stop, output_interval=interval, output=outputs,
                        start_values=dict(values, v=speed(height), m=M))


def curve(fmu, height, seed, **values):
    """Times from the trigger and noisy forces over the contact and 0.2 ms after."""
    r = run(fmu, height, 2e-3 * (0.02 / height) ** 0.1 + 2e-4, STEP, ["F"], **values)
    pad = np.arange(round(TRIGGER / STEP)) * STEP
    t = np.concatenate([pad, r["time"] + TRIGGER])
    F = np.concatenate([np.zeros(len(pad)), r["F"]])
    return t, F + np.random.default_rng(seed).normal(0.0, NOISE, len(F))


def campaign(fmu, seed):
    """Height, F_max, eps of every drop."""
    rng = np.random.default_rng(seed)
    rows = []
    for height in DROP_HEIGHTS:
        end = run(fmu, height, 3e-3, 1e-5, ["F_peak", "eps"], **SPRINGPOT)[-1]
        for _ in range(REPEATS):
            rows.append((height, end["F_peak"] * (1 + 0.01 * rng.normal()), end["eps"] + 0.01 * rng.normal()))
    return rows


def examples(fmu):
    """File name -> (header, rows) of every example."""
    files = {"h20_dashpot.csv": ("t_s,F_N", zip(*curve(fmu, 0.020, 1, **DASHPOT)))}
    for height, seed in ((0.010, 2), (0.020, 3), (0.050, 4)):
        files[f"h{round(height * 1000)}_springpot.csv"] = ("t_s,F_N", zip(*curve(fmu, height, seed, **SPRINGPOT)))
    files["drops.csv"] = ("height_m,F_max_N,eps", campaign(fmu, 5))
    return files


def main(fmu, folder):
    for name, (header, rows) in examples(fmu).items():
        text = header + "\n" + "".join(",".join(f"{x:.6g}" for x in row) + "\n" for row in rows)
        (pathlib.Path(folder) / name).write_text(text)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else HERE.parent.parent / "build" / "fraccontact.fmu",
         sys.argv[2] if len(sys.argv) > 2 else HERE)
