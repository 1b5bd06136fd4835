"""Mutation testing: does the test suite notice a small wrong change to the
code it tests? Each mutant is one precise edit (or a few) of the C sources:
the force laws, the G1 weights and sums, the time scheme, the events, the
proxy striker, gravity and the gap, the FMU state's CRC and fields, the
outputs' scaling, the FMI call sequence and the solver's per-impact figures.
Each numeric mutant is perturbed by a little more (two to three times) than
the smallest error that the named test's stated tolerance claims to catch.

The mutants are applied to a copy of the working tree (its tracked and
untracked, not ignored, files: work not yet committed is tested too), never
to the sources themselves. Every edit's original text must occur exactly once
in its file, or the run stops before building anything: the source moved and
the mutant must be rewritten. For each mutant the copy is rebuilt
incrementally, then the C tests run (ctest, stopping at the first failure),
then pytest with -x (test files in alphabetical order, the slow
test_stability, test_sweep and test_fit last). The mutant is KILLED by the
first test that fails, or SURVIVES. The unmutated copy runs every test
first: one that fails there (work in progress) is left out of the mutant
runs and named in the report (--strict-baseline stops instead).

Writes the table between the markers <!-- mutation:begin --> and
<!-- mutation:end --> of docs/reliability.md (appended when missing;
the reliability report keeps that section when it rewrites the file).

Regenerate: scripts/report mutation   (about ten minutes on 2 cores: a killed
mutant costs a rebuild and the tests up to its first failure, seconds; a
survivor the whole suite, about a minute; the baseline one more)
  scripts/report mutation --list               the mutants, checked against the sources
  scripts/report mutation --only NAME [NAME...]  run some, print, leave the docs alone
"""

import argparse
import concurrent.futures
import dataclasses
import datetime
import json
import os
import pathlib
import re
import shutil
import signal
import stat
import subprocess
import tempfile
import threading
import time

from fraccontact import atomic

from . import source_tree

ROOT = source_tree()
DOC = ROOT / "docs" / "reliability.md"
BEGIN, END = "<!-- mutation:begin -->", "<!-- mutation:end -->"
SLOW_LAST = ["test_stability.py", "test_sweep.py", "test_fit.py"]  # pytest runs these last, in this order
PYTHON = ROOT / ".venv" / "bin" / "python"


@dataclasses.dataclass(frozen=True)
class Mutant:
    name: str
    category: str
    change: str                 # what the edit does, for the table
    claim: str                  # the perturbation and the test/tolerance that claims to catch it
    edits: tuple                # (file, original text, replacement), applied in order


def mutant(name, category, change, claim, *edits):
    return Mutant(name, category, change, claim, tuple(edits))


G1, MODEL, STATE, INSTANCE = \
    "model/g1.c", "fmu_src/binding/fmu_model.c", "fmu_src/glue/fmi2_cosim.c", "fmu_src/glue/fmu_instance.c"
# The model's files (model/): one responsibility each.
PARAMETERS, LIFE, GRADIENT, RADAU, EVENTS, EVOLVE, PASSIVITY = ("model/" + f for f in (
    "parameters.c", "model.c", "gradient.c", "radau_iia.c", "events.c", "evolve.c", "passivity.c"))
CONTACT_H, HISTORY = "model/contact.h", "model/g1_history.c"
SOLVE, STRIKER = "solver/fraccontact.c", "striker/striker_model.c"
STRUCTURAL = "structural (no tolerance involved)"

MUTANTS = [
    # ------------------------------------------------------------ force laws
    mutant("hertz-exponent", "force laws", "fixed step: the force at its end F = K x1^(3/2 + 2e-12)",
           "exponent +2e-12: F off by 2.2e-11 to 2.9e-11 at the driven test's x1 = 5e-7..2e-5 m; "
           "DRIVEN_RTOL 1e-11 (test_fmu_physics::test_driven_hertz_law_is_k_x1_to_the_3_2)",
           (GRADIENT, "f->F_end = K * s * *X;", "f->F_end = K * s * *X * pow(s, 4e-12);")),
    mutant("hertz-constant", "force laws", "k from the materials ×(1 + 3e-15)",
           "3e-15; test_contact test_hertz_constant rel 1e-15",
           (PARAMETERS, "return 4.0 / 3.0 * E_star * sqrt(R);", "return 4.0 / 3.0 * E_star * sqrt(R) * (1.0 + 3e-15);")),
    mutant("g1-ratio-tgamma", "force laws", "G1 ratio Γ(N+3/2)/(Γ(N) N^(3/2)), N < 30 branch, ×(1 + 3e-14)",
           "3e-14; test_g1 test_line_ratio rel 1e-14 against extended-precision lgamma",
           (G1, "return tgamma(N + a) / (tgamma(N) * pow(N, a));",
            "return tgamma(N + a) / (tgamma(N) * pow(N, a)) * (1.0 + 3e-14);")),
    mutant("g1-ratio-stirling", "force laws", "G1 ratio, Stirling branch (N >= 30): exp(... - a (1 + 2e-14) ...)",
           "ratio ×(1 - 3e-14); test_g1 test_line_ratio rel 1e-14 (N up to 5000)",
           (G1, "return exp((N + a - 0.5) * log1p(a / N) - a\n",
            "return exp((N + a - 0.5) * log1p(a / N) - a * (1.0 + 2e-14)\n")),
    mutant("gamma-5-2", "force laws", "the constant Γ(5/2) ×(1 + 3e-15) (it scales the semi-integral)",
           "3e-15; test_fmu_coupling::test_output_derivatives_in_the_driven_scene_are_the_closed_forms: "
           "d semi_integral/dt = dF/dt / (Γ(5/2) k) rel 1e-15",
           (LIFE, "#define GAMMA_5_2 1.329340388179137", "#define GAMMA_5_2 (1.329340388179137 * (1.0 + 3e-15))")),
    mutant("richardson-odd-N", "force laws", "extrapolated G1 ratio: M = ceil(N/2) instead of floor(N/2) for odd N > 1",
           STRUCTURAL + "; the FMU's law 3 meets odd N at every other step since onset",
           (G1, "double M = floor(0.5 * N);", "double M = N > 1.0 ? ceil(0.5 * N) : 0.0;")),
    # ------------------------------------------------------ G1 weights and sums
    mutant("g1-weight-w0", "G1 weights and sums", "w_0 = 1 + 2e-12 (every weight scaled)",
           "2e-12; test_g1 test_line_identity rel 1e-12 (at N = 1 the sum is w_0 x)",
           (G1, "w[0] = 1.0;", "w[0] = 1.0 + 2e-12;")),
    mutant("g1-weight-recursion", "G1 weights and sums", "w_j = w_(j-1) (1 - (α + 1 + 2e-13)/j)",
           "2e-13 in α + 1: the line's sum moves by 1.2e-12 (N = 1e3) to 2.6e-12 (N = 1e6); "
           "test_g1 test_line_identity rel 1e-12",
           (G1, "w[j] = w[j - 1] * (1.0 - (alpha + 1.0) / (double)j);",
            "w[j] = w[j - 1] * (1.0 - (alpha + 1.0 + 2e-13) / (double)j);")),
    mutant("g1-history-oldest", "G1 weights and sums", "history sum stops one term early (j < n instead of j <= n)",
           STRUCTURAL + "; the oldest sample is 0 on the line, not in test_g1_grid's sine history (rel 1e-12)",
           (G1, "for (j = 0; j <= n / stride; j++) {", "for (j = 0; j < n / stride; j++) {")),
    mutant("g1-sum-compensation", "G1 weights and sums", "history sum without Neumaier's compensation",
           "rounding only (~sqrt(N) ulp, 5.7e-14 at N = 1e6); test_g1 test_history_sum_is_compensated 4 ulp",
           (G1, "return sum + carry;", "return sum;")),
    mutant("g1-delta-power", "G1 weights and sums", "history sum: Δ^(-α) with Δ ×(1 + 4e-12)",
           "sum off by |α| 4e-12 >= 2e-12; test_g1 test_line_identity rel 1e-12",
           (G1, "return pow(delta, -alpha) * weighted_history(w, f, n_samples - 1, 1);",
            "return pow(delta * (1.0 + 4e-12), -alpha) * weighted_history(w, f, n_samples - 1, 1);")),
    mutant("g1-extrapolated-coarse", "G1 weights and sums", "Richardson sum: the 2Δ grid's term ×(1 + 4e-13)",
           "2e-13 absolute at α = -1 on the line (value 1/2); test_g1 test_extrapolated_order: error < 1e-13 there",
           (G1, "- pow(2.0 * delta, -alpha) * weighted_history(w, f, n, 2);",
            "- pow(2.0 * delta, -alpha) * (1.0 + 4e-13) * weighted_history(w, f, n, 2);")),
    mutant("g1-N-off-by-one", "G1 weights and sums", "the G1 law counts N = steps since onset + 2 (not + 1)",
           STRUCTURAL + "; test_fmu_physics::test_driven_g1_law_has_the_straight_line_error, DRIVEN_RTOL 1e-11",
           (EVOLVE, "K = spring_stiffness(cm, s->n + 1);\n        J = fixed_step(",
            "K = spring_stiffness(cm, s->n + 2);\n        J = fixed_step(")),
    # ------------------------------------------------------------ time scheme
    mutant("gradient-trapezoid", "time scheme", "fixed step: the position's trapezoid weighs the velocity's "
           "change by 1/2 (1 + 1e-6)",
           "energy created 1e-6 h² F²/m a step, about 1e-12 of the impact's energy over an impact at 1e-7 s; "
           "test_contact test_energy_balance to rounding (13 000 steps: 1.2e-11) and test_energy's every step",
           (GRADIENT, "const double b = h * (d.inv_B + 0.5 * h * cm->inv_m),",
            "const double b = h * (d.inv_B + 0.5 * (1.0 + 1e-6) * h * cm->inv_m),")),
    mutant("gradient-flow", "time scheme", "fixed step: the dent moves by h z (1 + 1e-11)",
           "x2 off by ~1e-11; momentum identity x2 = m v0 (1 + eps)/c rel 1e-12 (test_contact, "
           "test_fmu_physics::test_drop_momentum_identity)",
           (GRADIENT, "out->x2 = in->x2 + h * z;", "out->x2 = in->x2 + h * z * (1.0 + 1e-11);")),
    mutant("gradient-dissipation", "time scheme", "each step's dissipation h F z ×(1 + 2e-8)",
           "2e-8; test_contact test_energy_balance to rounding, "
           "test_solver::test_one_impact_per_impact_figures_match_the_closed_forms: "
           "E_diss = m v0² (1 - eps²)/2 rel 1e-8",
           (GRADIENT, "out->E_diss = in->E_diss + h * f.F * z;", "out->E_diss = in->E_diss + h * f.F * z * (1.0 + 2e-8);")),
    mutant("gradient-secant", "time scheme", "fixed step, n = 3/2: the secant's s0³ term ×(1 + 1e-6), "
           "the mean force off its discrete gradient",
           "the spring's energy off by up to 4e-7 F dx1 a step; test_contact test_energy_balance to rounding",
           (GRADIENT, "f->S = 0.4 * K * (*X * *X / (s + s0) + s0 * *X + s0 * x1);",
            "f->S = 0.4 * K * (*X * *X / (s + s0) + s0 * *X + s0 * x1 * (1.0 + 1e-6));")),
    mutant("step-count", "time scheme", "H = n dt_max takes n + 1 internal steps (ceil forgives no ulp)",
           STRUCTURAL + "; test_fmu_physics::test_driven_g1_law_has_the_straight_line_error counts "
           "N = 10 steps per 1 us",
           (EVOLVE, "(1.0 - 1e-12)),", "(1.0 + 1e-12)),")),
    mutant("radau-eigenvalue", "time scheme", "Radau IIA: A's real eigenvalue ×(1 + 1e-11) in the modes' elimination",
           "each mode's 1/(1 + h b λ) off by up to 1e-11; test_contact test_radau_modes_are_the_last_stage: "
           "the advanced modes against the last stage solved from A built anew, 1e-13 of their scale",
           (RADAU, "{0.15906584442746913, 0.0}, {0.13317907701829959",
            "{0.15906584442746913 * (1.0 + 1e-11), 0.0}, {0.13317907701829959")),
    mutant("radau-advance-pair", "time scheme", "Radau IIA: the modes' update divides the second complex pair's "
           "term by the wrong pair",
           STRUCTURAL + "; test_contact test_radau_modes_are_the_last_stage",
           (RADAU, "(phi * t1r + w1r) * c1r_of[j] + (phi * t1i + w1i) * c1i_of[j];\n"
                   "        const double n2 = (phi * t2r + w2r) * c2r_of[j] + (phi * t2i + w2i) * c2i_of[j];",
            "(phi * t1r + w1r) * c2r_of[j] + (phi * t1i + w1i) * c2i_of[j];\n"
            "        const double n2 = (phi * t2r + w2r) * c1r_of[j] + (phi * t2i + w2i) * c1i_of[j];")),
    mutant("radau-kept-reciprocals", "time scheme", "Radau IIA: the modes' update takes the kept reciprocals "
           "whatever trial's step they were built for",
           STRUCTURAL + "; test_contact test_radau_modes_are_the_last_stage: the update of a model copied "
           "without them",
           (RADAU, "    if (m->radau_h != h) {", "    if (0 && m->radau_h != h) {")),
    mutant("radau-newton-settled", "time scheme", "Radau IIA: the stages' simplified Newton iteration stops "
           "1e4 times early (100 tolerances of the largest indentation left to the root, not a hundredth)",
           "each stage's indentation off by up to 100 tolerances of its scale; test_claims: the springpot table's "
           "figures against the full G1 history",
           (RADAU, "#define NEWTON_SETTLED 1e-2", "#define NEWTON_SETTLED 1e2")),
    mutant("kernel-reuse-tolerance", "springpot memory", "a batch reuses a springpot's kernel across "
           "memory_tolerance values",
           STRUCTURAL + "; test_api::test_a_batch_shares_a_springpots_kernel_only_between_runs_alike: each run of an "
           "interleaved batch exactly as alone",
           (LIFE, "           && k->memory_tolerance == p->memory_tolerance;", "           && 1;")),
    mutant("history-separation-secant", "springpot memory", "memory 1: the separation along x1's secant across "
           "its grid step, x2 not continued from the contact's side",
           "t_contact's orders 0.77, 2.32 at alpha 0.05, n 1; test_springpot::"
           "test_full_history_locates_the_separation_at_second_order_at_small_alpha, band [1.9, 2.2]",
           (HISTORY, "return 2.0 * C / (sqrt(larger(B * B - 4.0 * A * C, 0.0)) - B);",
            "return before->x1 / (before->x1 - s->x1);")),
    mutant("history-x2_end-secant", "springpot memory", "memory 1: x2_end along x2's secant to the grid point "
           "after the separation",
           "x2_end's orders 0.73, 2.46 at alpha 0.05, n 1; test_springpot::"
           "test_full_history_locates_the_separation_at_second_order_at_small_alpha, band [1.9, 2.2]",
           (HISTORY, "return x2[i] + theta * (slope + theta * curve);", "return x2[i] + theta * (s->x2 - x2[i]);")),
    mutant("copy-padding", "springpot memory", "contact_copy leaves the modes padded to whole lanes as the "
           "memory it copies into held them",
           STRUCTURAL + "; test_contact test_a_copy_steps_as_its_original: a copy into 0xff bytes steps as its "
           "original, to the bit",
           (LIFE, "    pad_modes(t);\n}", "}")),
    mutant("radau-dense-output", "events", "Radau IIA's dense output through half the step's starting indentation",
           STRUCTURAL + "; F_peak read off a wrong polynomial: test_claims, the springpot table's F_peak against the "
           "full G1 history",
           (RADAU, "    y[0] = s->x1;", "    y[0] = 0.5 * s->x1;")),
    mutant("radau-dense-table", "events", "Radau IIA's dense output: one entry of its table ×(1 + 1e-9)",
           "theta's coefficient off by 2.8e-8 of the second stage's x1; test_contact "
           "test_radau_dense_output_interpolates: a quintic's coefficients within 1e-12",
           (RADAU, "{-25.0, 27.78093394406464,", "{-25.0, 27.78093394406464 * (1.0 + 1e-9),")),
    mutant("radau-estimate-memory", "time scheme", "Radau IIA: the error estimate's filter without the modes' own "
           "residuals",
           "the estimate changes, and with it the steps; test_claims::test_the_springpot_table_of_error_controlled_steps: "
           "the steps of docs/numerics.md's springpot table exactly",
           (RADAU, "    kk = 1.0 / (cm->modes.eta + w * s->q[0].re);",
            "    rho = 0.0;\n    kk = 1.0 / (cm->modes.eta + w * s->q[0].re);")),
    # ----------------------------------------------------------------- events
    mutant("onset-location", "events", "contact onset inside a free-flight step: time ×(1 + 3e-14)",
           "3e-14; test_solver::test_free_flight_is_one_exact_step: t_onset, v_onset rel 1e-14",
           (EVENTS, "return fmin(fmax(t, 0.0), h);", "return fmin(fmax(t * (1.0 + 3e-14), 0.0), h);")),
    mutant("separation-location", "events", "separation located where x1 = -1e-10 m instead of 0",
           "t_contact +2.1e-7 (1e-10 m at 0.36 m/s over 1.32 ms); "
           "test_solver::test_per_impact_figures_against_the_reference rel 1e-7",
           (EVENTS, "return s->x1;", "return s->x1 + 1e-10;"),
           (EVOLVE, "is not one. */\n        separates = !(trial.x1 > 0.0)",
            "is not one. */\n        separates = !(trial.x1 + 1e-10 > 0.0)"),
           (EVENTS, "return event_time(cm, s, h, K, indentation, trial->x1, 1e-15",
            "return event_time(cm, s, h, K, indentation, trial->x1 + 1e-10, 1e-15")),
    mutant("peak-in-step", "events", "F_peak sampled at step ends only (the peak inside a step dropped)",
           STRUCTURAL + "; ~(π h / t_c)²/8 ~ 7e-9 at dt 1e-7 (events.c, force_at_turn: more than the scheme's error)",
           (EVENTS, "return at.F > end->F ? at.F : end->F;", "return end->F;")),
    # ---------------------------------------------------------- proxy striker
    mutant("proxy-gravity", "proxy striker", "the driven scene's proxy striker ignores g",
           STRUCTURAL + "; test_readme::test_the_readme_master_loop_is_the_drop_test with g, bit-exact "
           "drop vs driven (test_fmu_coupling)",
           (LIFE, "cm->accel = m > 0.0 ? cm->p.g + accel : accel;", "cm->accel = m > 0.0 ? accel : accel;")),
    mutant("energy-displacement", "energy account", "the bodies' displacement by the trapezoid, not Hermite's "
           "quadrature (the change of a over the interval ignored)",
           "the held force's share of the energy a spring makes, k_s v H^3 / (12 m) a step; "
           "test_two_bodies::test_the_energy_correction_takes_back_no_more_than_the_coupling_creates: "
           "energy_error >= -C, the closed form of what the coupling creates",
           (PASSIVITY, "return 0.5 * H * (u_start + u_end) + H * H * (a_start - a_end) / 12.0;",
            "return 0.5 * H * (u_start + u_end) + 0.0 * (a_start - a_end);")),
    mutant("energy-correction-off", "energy account", "the correction computed but never applied",
           "the energy a coupled spring creates, second order in H; test_jacobi / test_two_bodies / test_scenes: "
           "energy_error <= 1e-12 of the impact's",
           (PASSIVITY, "return limited(smallest_change(", "return 0.0 * limited(smallest_change(")),
    mutant("energy-lag-off", "energy account", "the proxy's own work never settled at the contact's end (the lag "
           "summed but not added to what was created)",
           "the potential energy gravity given as g leaves the striker under Gauss-Seidel, 5.0e-7 E0 at H = 1e-4, "
           "and most of a Jacobi master's at 1 ms; test_two_bodies::test_a_constant_force_fed_as_a_is_g: energy "
           "<= the drop test's own + 1e-12",
           (PASSIVITY, "e->created += e->lag;", "e->created += 0.0 * e->lag;")),
    mutant("energy-restart-off", "energy account", "the owed impulse's share where a Jacobi proxy restarts left out",
           "the share of a Jacobi master's energy at H = 1 ms that the lag does not hold; "
           "test_two_bodies::test_a_spring_fed_as_a_creates_no_energy[1 ms]: energy_error <= 1e-12 of the impact's",
           (PASSIVITY, "e->created -= owed * dv;", "e->created -= 0.0 * owed * dv;")),
    mutant("energy-no-pull", "energy account", "no pull on separated bodies: the correction never turns the force round",
           "+0.41 E0 under a Jacobi master at H = 1 ms; test_two_bodies::test_a_spring_fed_as_a_creates_no_energy: "
           "energy_error <= 1e-12 of the impact's",
           (PASSIVITY, "if (fabs(d) <= fabs(F0) || (ends_free && d < 0.0))",
            "if (fabs(d) <= fabs(F0) || (ends_free && d < -HUGE_VAL))")),
    mutant("energy-early-return-off", "energy account", "a step FMI 3.0's early return ends at an event left out "
           "of the account",
           "+2.4e-3 E0 under a Gauss-Seidel master at H = 1 ms; "
           "test_two_bodies::test_an_early_returns_part_of_a_step_is_a_step_of_the_account: energy <= 1e-12",
           (MODEL, "if (accounted)\n        account_step(", "if (accounted && !*event)\n        account_step(")),
    mutant("proxy-mass", "proxy striker", "the proxy striker's 1/m one ulp high",
           "1 ulp; test_fmu_coupling::test_mass_aware_coupling_with_an_exact_master_is_the_drop_test: bit for bit",
           (LIFE, "cm->inv_m = m > 0.0 ? 1.0 / m : 0.0;", "cm->inv_m = m > 0.0 ? nextafter(1.0 / m, 2.0 / m) : 0.0;")),
    mutant("striker-velocity", "proxy striker", "striker FMU: v += H a (1 + 2e-12)",
           "v off by 2.9e-13 after 100 steps; test_striker_fmu::test_motion_under_a_held_force_is_the_parabola "
           "v rel 1e-13",
           (STRIKER, "fm->v += H * a;", "fm->v += H * a * (1.0 + 2e-12);")),
    # -------------------------------------------------------- gravity and gap
    mutant("gravity-sign", "gravity and gap", "the drop test's gravity points away from the specimen",
           STRUCTURAL + "; test_contact test_gap_and_gravity, test_solver free fall",
           (LIFE, "cm->accel = p->g;", "cm->accel = -p->g;")),
    mutant("gravity-scale", "gravity and gap", "the drop test's g ×(1 + 5e-14)",
           "t_onset, v_onset off by 2.5e-14; test_solver::test_free_flight_is_one_exact_step rel 1e-14",
           (LIFE, "cm->accel = p->g;", "cm->accel = p->g * (1.0 + 5e-14);")),
    mutant("gap-ignored", "gravity and gap", "gap0 ignored: the striker starts on the specimen",
           STRUCTURAL + "; test_contact test_gap_and_gravity onset time rel 1e-12",
           (LIFE, "cm->s.x1 = -p->gap0;", "cm->s.x1 = 0.0;")),
    mutant("gap-scale", "gravity and gap", "gap0 ×(1 + 5e-14)",
           "t_onset, v_onset off by 2.5e-14; test_solver::test_free_flight_is_one_exact_step rel 1e-14",
           (LIFE, "cm->s.x1 = -p->gap0;", "cm->s.x1 = -p->gap0 * (1.0 + 5e-14);")),
    # ------------------------------------------------------- the state's CRC
    mutant("crc-check-skipped", "state CRC", "a state's payload checksum is not checked",
           STRUCTURAL + "; test_fmu_state::test_damaged_states_are_refused[corrupted]",
           (INSTANCE, "if (serial_get_u32(b + 16) != serial_crc32(b + STATE_HEADER, payload))",
            "if (0 && serial_get_u32(b + 16) != serial_crc32(b + STATE_HEADER, payload))")),
    mutant("crc-range-short", "state CRC", "the checksum (written and checked) leaves out the payload's last 8 bytes",
           STRUCTURAL + "; a damaged last field would pass",
           (INSTANCE, "serial_put_u32(b + 16, serial_crc32(p, payload));",
            "serial_put_u32(b + 16, serial_crc32(p, payload - 8));"),
           (INSTANCE, "serial_crc32(b + STATE_HEADER, payload))", "serial_crc32(b + STATE_HEADER, payload - 8))")),
    mutant("crc-guid-unchecked", "state CRC", "a state's GUID checksum is not checked (another FMU's state)",
           STRUCTURAL + "; test_fmu_state::test_damaged_states_are_refused[another FMU]",
           (INSTANCE, "if (serial_get_u32(b + 8) != token_crc())",
            "if (0 && serial_get_u32(b + 8) != token_crc())")),
    mutant("crc-polynomial", "state CRC", "CRC-32C's polynomial instead of CRC-32's (zlib's)",
           STRUCTURAL + "; the state tests re-checksum with zlib.crc32",
           ("fmu_src/glue/serial.c", "0xEDB88320u", "0x82F63B78u")),
    # ---------------------------------------------------------- output scaling
    mutant("x2-output", "output scaling", "output x2 ×(1 + 2e-12)",
           "2e-12; test_fmu_physics::test_drop_momentum_identity x2 rel 1e-12, "
           "test_fmu_compliance x = x1 + x2 rel 1e-12",
           (MODEL, "case VR_x2: return cm->s.x2;", "case VR_x2: return cm->s.x2 * (1.0 + 2e-12);")),
    mutant("F_avg-length", "output scaling", "F_avg = impulse / (H (1 + 2e-12))",
           "2e-12; test_fmu_coupling::test_F_avg_is_the_impulse_that_conserves_momentum rel 1e-12",
           (MODEL, "fm->step.F_avg = part > 0.0 ? impulse / part : cm->s.F;",
            "fm->step.F_avg = part > 0.0 ? impulse / (part * (1.0 + 2e-12)) : cm->s.F;")),
    mutant("F_avg_next-owed", "output scaling", "F_avg_next without the impulse owed",
           "the first step's impulse, 3 % of the impact's at H = 1e-5 s; test_jacobi (every Jacobi run) rel 1.2e-11",
           (MODEL, "(fm->next && fm->next->valid ? fm->next->impulse / fm->step.H : fm->step.F_avg) + fm->step.owed / fm->step.H;",
            "(fm->next && fm->next->valid ? fm->next->impulse / fm->step.H : fm->step.F_avg);")),
    mutant("semi-integral-output", "output scaling", "output semi_integral ×(1 + 2e-12)",
           "2e-12; test_fmu_compliance::test_every_variable_is_read_or_written semi_integral rel 1e-12",
           (MODEL, "case VR_semi_integral: return contact_semi_integral(cm);",
            "case VR_semi_integral: return contact_semi_integral(cm) * (1.0 + 2e-12);")),
    mutant("semi-integral-rate", "output scaling", "d semi_integral/dt ×(1 + 3e-14)",
           "3e-14; test_fmu_coupling::test_output_derivatives_in_the_driven_scene_are_the_closed_forms rel 1e-14",
           (MODEL, "*value = F_rate * contact_semi_integral_per_force(cm); break;",
            "*value = F_rate * contact_semi_integral_per_force(cm) * (1.0 + 3e-14); break;")),
    mutant("F-rate", "output scaling", "dF/dt = n (1 + 2e-11) K x1^(n-1) x1'",
           "2e-11; test_fmu_coupling::test_output_derivatives_in_the_driven_scene_are_the_closed_forms "
           "dF/dt rel 1e-11",
           (LIFE, "*F_rate = x1 > 0.0 ? n * contact_spring_stiffness",
            "*F_rate = x1 > 0.0 ? n * (1.0 + 2e-11) * contact_spring_stiffness")),
    mutant("eps-output", "output scaling", "restitution eps = -v_end/v_onset ×(1 + 3e-14)",
           "3e-14; test_fmu_compliance::test_every_variable_is_read_or_written eps rel 1e-14",
           (EVENTS, "s->eps = s->v_onset > 0.0 ? -v / s->v_onset : 0.0;",
            "s->eps = s->v_onset > 0.0 ? -v / s->v_onset * (1.0 + 3e-14) : 0.0;")),
    # ------------------------------------------------------------ serialization
    mutant("state-drop-F_peak", "serialization", "F_peak left out of the state's field table (FMU state, finiteness)",
           STRUCTURAL + "; test_fmu_state restores into a new instance and compares every output bit for bit",
           (CONTACT_H, "DOUBLE(F_peak) ", "")),
    mutant("state-drop-v_onset", "serialization", "v_onset left out of the state's field table (eps after a restore)",
           STRUCTURAL + "; test_fmu_state restores mid-contact and runs through the separation bit for bit",
           (CONTACT_H, "DOUBLE(v_onset) ", "")),
    # ------------------------------------------------------------ call sequence
    mutant("seq-set-after-terminate", "call sequence", "fmi2Set* allowed in the terminated state",
           STRUCTURAL + "; test_fmi2 'after terminate'",
           (STATE, "#define SETTABLE (INSTANTIATED | INITIALIZATION_MODE | RUNNING)",
            "#define SETTABLE (INSTANTIATED | INITIALIZATION_MODE | RUNNING | TERMINATED)")),
    mutant("seq-step-in-initialization", "call sequence", "fmi2DoStep allowed in initialization mode",
           STRUCTURAL + "; test_fmi2, test_fmu_bad_input::test_wrong_call_order_is_an_error_not_a_crash",
           (STATE, 'REQUIRE(STEP_COMPLETE, "fmi2DoStep");', 'REQUIRE(STEP_COMPLETE | INITIALIZATION_MODE, "fmi2DoStep");')),
    # -------------------------------------------------- solver's per-impact figures
    mutant("per-impact-E_diss", "solver per-impact", "each impact's E_diss counted from t = 0, not from its onset",
           STRUCTURAL + "; test_solver::test_top_level_figures_say_which_impact_they_describe: "
           "sum = total rel 1e-13",
           (SOLVE, "done.E_diss = s->E_diss - E_diss_onset;", "done.E_diss = s->E_diss - 0.0 * E_diss_onset;")),
    mutant("per-impact-v_onset", "solver per-impact", "each impact's v_onset ×(1 + 3e-14)",
           "3e-14; test_solver::test_free_flight_is_one_exact_step v_onset rel 1e-14",
           (SOLVE, "done.v_onset = s->v_onset;", "done.v_onset = s->v_onset * (1.0 + 3e-14);")),
    mutant("per-impact-F_peak", "solver per-impact", "each impact's F_peak one ulp high",
           "1 ulp; test_solver::test_top_level_figures_say_which_impact_they_describe: "
           "F_peak = max of the impacts', exactly",
           (SOLVE, "done.F_peak = s->F_peak_contact;", "done.F_peak = nextafter(s->F_peak_contact, INFINITY);")),
]


# --------------------------------------------------------------- the copy

def source_files():
    """The working tree's tracked and untracked (not ignored) files that exist."""
    out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                         capture_output=True, check=True).stdout.decode()
    return sorted({f for f in out.split("\0") if f and (ROOT / f).is_file()})


def check_mutants(mutants):
    """Every edit's original text occurs exactly once in the working tree's
    file (after the mutant's earlier edits): otherwise the source moved."""
    problems = []
    for m in mutants:
        texts = {}
        for path, old, new in m.edits:
            text = texts.setdefault(path, (ROOT / path).read_text())
            n = text.count(old)
            if n != 1:
                problems.append(f"{m.name}: {path}: the text {old!r} occurs {n} times (expected once): "
                                "the source moved, rewrite the mutant")
            else:
                texts[path] = text.replace(old, new)
    return problems


def run(cmd, cwd, env=None, timeout=None):
    """(returncode, output, seconds); returncode None after a timeout. The
    command runs in its own process group, which a timeout kills whole."""
    start = time.monotonic()
    proc = subprocess.Popen([str(c) for c in cmd], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, errors="replace", start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        code = None
    return code, out, time.monotonic() - start


class Copy:
    """A copy of the sources with its own incremental build."""

    def __init__(self, path, build_jobs):
        self.src = pathlib.Path(path)
        self.build = self.src / "build"
        self.build_jobs = build_jobs
        self.cmake = os.environ.get("CMAKE", "cmake")
        self.ctest = str(pathlib.Path(shutil.which(self.cmake) or self.cmake).with_name("ctest"))

    def sync(self, files):
        """Makes the copy's sources equal to the working tree's; files are
        written (new modification time) only where their bytes differ."""
        wanted = set(files)
        for rel in files:
            data, dst = (ROOT / rel).read_bytes(), self.src / rel
            if not dst.is_file() or dst.read_bytes() != data:
                dst.parent.mkdir(parents=True, exist_ok=True)
                dst.write_bytes(data)
            os.chmod(dst, stat.S_IMODE((ROOT / rel).stat().st_mode))
        for path in list(self.src.rglob("*")):
            rel = path.relative_to(self.src)
            if rel.parts[0] == "build" or "__pycache__" in rel.parts or not path.is_file():
                continue
            if str(rel) not in wanted:
                path.unlink()

    def make(self):
        """Configures (once) and builds; (ok, output)."""
        if not (self.build / "CMakeCache.txt").exists():
            code, out, _ = run([self.cmake, "-S", self.src, "-B", self.build, f"-DPython3_EXECUTABLE={PYTHON}"],
                               self.src)
            if code != 0:
                return False, out
        code, out, _ = run([self.cmake, "--build", self.build, "-j", self.build_jobs], self.src)
        return code == 0, out

    def apply(self, m):
        """Applies the mutant's edits; returns the files' original texts."""
        originals, texts = {}, {}
        for path, old, new in m.edits:
            if path not in texts:
                texts[path] = originals[path] = (self.src / path).read_text()
            if texts[path].count(old) != 1:
                raise SystemExit(f"{m.name}: {path}: {old!r} does not occur exactly once in the copy")
            texts[path] = texts[path].replace(old, new)
        for path, text in texts.items():
            (self.src / path).write_text(text)
        return originals

    def revert(self, originals):
        for path, text in originals.items():
            (self.src / path).write_text(text)  # a new modification time: the next build recompiles it

    def c_tests(self, timeout, skip=(), stop=True):
        """The C tests (every ctest test but pytest and those in skip),
        stopping at the first failure: (failures, seconds), each failure
        (test name, what failed), none when all pass."""
        exclude = "^(" + "|".join(re.escape(t) for t in ("pytest", *skip)) + ")$"
        code, out, seconds = run([self.ctest, "--test-dir", self.build, "-E", exclude, "--output-on-failure",
                                  "--timeout", int(timeout), *(["--stop-on-failure"] if stop else [])], self.src,
                                 timeout=timeout + 60)
        if code == 0:
            return [], seconds
        if code is None:
            return [("ctest", f"timed out after {seconds:.0f} s")], seconds
        failed = re.findall(r"^\s*\d+ - (\S+) \(([^)]*)\)", out, re.M)
        if not failed:
            return [("ctest", shorten(out[-300:]))], seconds
        check = re.search(r"^(?:\S*/)?([\w.]+\.c):(\d+): check failed: .*?: (.*)$", out, re.M)
        first = f"{check.group(1)}:{check.group(2)}: {check.group(3)}" if check else failed[0][1]
        return [(failed[0][0], shorten(first))] + [(name, why) for name, why in failed[1:]], seconds

    def pytest_environment(self):
        """The environment CMakeLists.txt gives ctest's pytest test (the
        build's FMUs, solver, library...), read from ctest itself."""
        shown = subprocess.run([self.ctest, "--test-dir", str(self.build), "--show-only=json-v1", "-R", "^pytest$"],
                               cwd=self.src, capture_output=True, text=True, check=True).stdout
        env = dict(os.environ)
        for test in json.loads(shown)["tests"]:
            for prop in test.get("properties", []):
                if prop["name"] == "ENVIRONMENT":
                    env.update(value.split("=", 1) for value in prop["value"])
        # no bytecode in the copy; a wide terminal, so that the summary keeps each failure's message
        env.update(PYTHONDONTWRITEBYTECODE="1", COLUMNS="400")
        return env

    def pytest(self, timeout, skip=(), stop=True):
        """pytest over the copy's tests, slow files last, without the node ids
        (or files) in skip, with -x when stop: (failures, seconds), each
        failure (node id, why), none when all pass."""
        tests = sorted(p.name for p in (self.src / "tests").glob("test_*.py") if f"tests/{p.name}" not in skip)
        order = [t for t in tests if t not in SLOW_LAST] + [t for t in SLOW_LAST if t in tests]
        env = self.pytest_environment()
        # a file that fails to import is left out whole; without -x the others still run
        skipping = [f"--deselect={n}" for n in skip if "::" in n]
        code, out, seconds = run([PYTHON, "-m", "pytest", *(["-x"] if stop else ["--continue-on-collection-errors"]),
                                  "-v", "-rfE",
                                  "-p", "no:cacheprovider", *skipping, *(f"tests/{t}" for t in order)],
                                 self.src, env=env, timeout=timeout)
        if code == 0:
            return [], seconds
        started = re.findall(r"^(tests/\S+?::.*?)(?: (?:PASSED|FAILED|ERROR|SKIPPED|XFAIL|XPASS)\b.*)?$", out, re.M)
        where = started[-1] if started else "?"
        if code is None:
            return [(where, f"timed out after {seconds:.0f} s")], seconds
        failed = re.findall(r"^(?:FAILED|ERROR) (tests/.+?)(?: - (.*))?$", out, re.M)
        if failed:
            return [(node, shorten(why or "failed")) for node, why in failed], seconds
        return [(where, f"pytest exited with {code}" + (f" (signal {-code})" if code < 0 else ""))], seconds


def shorten(text, n=140):
    text = " ".join(text.split())
    return text if len(text) <= n else text[:n - 1] + "…"


# ------------------------------------------------------------------- runs

@dataclasses.dataclass
class Result:
    mutant: Mutant
    verdict: str        # KILLED, SURVIVED, ERROR
    by: str             # the first failing test and why, or what went wrong
    seconds: float


def run_mutant(copy, m, py_timeout, skip_c, skip_py):
    start = time.monotonic()
    originals = copy.apply(m)
    try:
        ok, out = copy.make()
        if not ok:
            errors = [line for line in out.splitlines() if "error" in line]
            return Result(m, "ERROR", "build failed: " + shorten(errors[0] if errors else out[-300:]),
                          time.monotonic() - start)
        failed, _ = copy.c_tests(300, skip_c)
        if not failed:
            failed, _ = copy.pytest(py_timeout, skip_py)
    finally:
        copy.revert(originals)
    by = f"{failed[0][0]}: {failed[0][1]}" if failed else ""
    return Result(m, "KILLED" if failed else "SURVIVED", by, time.monotonic() - start)


def baseline(copy):
    """The unmutated copy must build; its C tests and pytest run whole.
    Returns (C test names, pytest node ids that fail unmutated, C seconds,
    pytest seconds): the mutants run without those, and the report says so
    (work in progress in the working tree can fail on its own)."""
    ok, out = copy.make()
    if not ok:
        raise SystemExit(f"the unmutated copy does not build:\n{out[-3000:]}")
    c_failed, c_seconds = copy.c_tests(600, stop=False)
    py_failed, py_seconds = copy.pytest(1800, stop=False)
    return [n for n, _ in c_failed], [n for n, _ in py_failed], c_seconds, py_seconds


def cell(text):
    return text.replace("|", "\\|").replace("\n", " ")


def section(results, started, seconds, jobs, source, left_out):
    killed = sum(r.verdict == "KILLED" for r in results)
    survived = [r.mutant.name for r in results if r.verdict == "SURVIVED"]
    errors = [r.mutant.name for r in results if r.verdict == "ERROR"]
    lines = [BEGIN, "## Mutation testing", "",
             "Regenerate: `scripts/report mutation` (this section only; `--list` shows the mutants, "
             "`--only NAME...` re-runs some without writing here). `reports/mutation.py` copies the working tree "
             "(tracked and untracked files) to a scratch directory, applies each mutant there (each edit's original "
             "text must occur exactly once in its file, or the run stops: the source moved), rebuilds, and runs the "
             "C tests (ctest, stopping at the first failure) and then `pytest -x` (files in alphabetical order, "
             f"{', '.join(SLOW_LAST)} last). The first failing test kills the mutant. A numeric mutant is perturbed "
             "by two to three times the smallest error that the named test's stated tolerance claims to catch; "
             "structural ones change what is computed.", "",
             f"This run: {started:%Y-%m-%d %H:%M} UTC, {seconds / 60:.1f} min on this machine "
             f"({os.cpu_count()} cores, shared; {jobs} mutant{'s' if jobs > 1 else ''} at a time), sources {source}. "
             f"**{len(results)} mutants: {killed} killed, {len(survived)} survived"
             + (f", {len(errors)} did not build" if errors else "") + "**"
             + (f" (survivors: {', '.join(survived)})." if survived else "."), ""]
    if left_out:
        lines += ["Tests that failed on the unmutated sources (work in progress in the working tree) and were "
                  "therefore left out of the mutant runs: " + ", ".join(f"`{n}`" for n in left_out) + ".", ""]
    lines += ["| mutant | category | change | perturbation: the tolerance that claims it | verdict | first failing test |",
              "|---|---|---|---|---|---|"]
    for r in results:
        files = ", ".join(dict.fromkeys(pathlib.Path(e[0]).name for e in r.mutant.edits))
        lines.append(f"| `{r.mutant.name}` | {r.mutant.category} | {cell(files)}: {cell(r.mutant.change)} | "
                     f"{cell(r.mutant.claim)} | **{r.verdict}** | {cell(r.by) or '—'} |")
    lines += ["", END]
    return "\n".join(lines) + "\n"


def write_section(text):
    """Replaces the marked section of docs/reliability.md, or appends it."""
    old = DOC.read_text() if DOC.exists() else "# Reliability\n"
    start, end = old.find(BEGIN), old.find(END)
    if start >= 0 and end > start:
        new = old[:start] + text + old[end + len(END):].lstrip("\n")
    else:
        new = old.rstrip("\n") + "\n\n" + text
    atomic.write_text(DOC, new)


def source_description():
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=normal"], cwd=ROOT,
                           capture_output=True, text=True).stdout.strip()
    return f"`{head.strip()}`" + (" with uncommitted changes" if dirty else "")


def main(argv=None, prog=None):
    parser = argparse.ArgumentParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--list", action="store_true", help="list the mutants (checked against the sources) and stop")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="run these mutants only; docs are left alone")
    parser.add_argument("--jobs", type=int, default=1, help="mutants at a time, each in its own copy (default 1)")
    parser.add_argument("--workdir", type=pathlib.Path,
                        default=pathlib.Path(tempfile.gettempdir()) / f"fraccontact-mutation-{os.getuid()}",
                        help="where the copies live, kept between runs for incremental builds")
    parser.add_argument("--no-baseline", action="store_true", help="skip the unmutated run (faster, less safe)")
    parser.add_argument("--strict-baseline", action="store_true",
                        help="stop when a test fails unmutated (default: leave it out of the mutant runs, and say so)")
    args = parser.parse_args(argv)

    names = [m.name for m in MUTANTS]
    assert len(set(names)) == len(names), "duplicate mutant names"
    mutants = MUTANTS
    if args.only:
        unknown = [n for n in args.only if n not in names]
        if unknown:
            raise SystemExit(f"unknown mutants: {', '.join(unknown)} (see --list)")
        mutants = [m for m in MUTANTS if m.name in args.only]
    problems = check_mutants(mutants)
    if problems:
        raise SystemExit("\n".join(problems))
    if args.list:
        for m in mutants:
            print(f"{m.name:28} {m.category:20} {m.change}\n{'':49} claim: {m.claim}")
        print(f"{len(mutants)} mutants, every edit found once in the sources")
        return 0

    started, t0 = datetime.datetime.now(datetime.timezone.utc), time.monotonic()
    source = source_description()
    files = source_files()
    jobs = max(1, min(args.jobs, len(mutants)))
    build_jobs = max(1, (os.cpu_count() or 1) // jobs)
    copies = [Copy(args.workdir / f"src-{i}", build_jobs) for i in range(jobs)]
    for c in copies:
        c.sync(files)
    py_timeout, skip_c, skip_py = 1800, [], []
    if not args.no_baseline:
        print("baseline: the unmutated copy, every test ...", flush=True)
        skip_c, skip_py, c_seconds, py_seconds = baseline(copies[0])
        py_timeout = max(300, 3 * py_seconds)
        print(f"baseline: C tests {c_seconds:.0f} s, pytest {py_seconds:.0f} s; "
              f"a mutant's pytest times out after {py_timeout:.0f} s", flush=True)
        for name in skip_c + skip_py:
            print(f"baseline: FAILS UNMUTATED, left out of the mutant runs: {name}", flush=True)
        if (skip_c or skip_py) and args.strict_baseline:
            raise SystemExit("the unmutated copy fails (--strict-baseline)")

    results = [None] * len(mutants)
    free = list(copies)
    lock = threading.Lock()
    done = 0

    def work(i):
        nonlocal done
        with lock:
            copy = free.pop()
        try:
            r = run_mutant(copy, mutants[i], py_timeout, skip_c, skip_py)
        finally:
            with lock:
                free.append(copy)
        with lock:
            results[i] = r
            done += 1
            print(f"[{done:2}/{len(mutants)}] {r.mutant.name:28} {r.verdict:8} {r.seconds:5.0f} s  {r.by}", flush=True)

    with concurrent.futures.ThreadPoolExecutor(jobs) as pool:
        for f in [pool.submit(work, i) for i in range(len(mutants))]:
            f.result()

    seconds = time.monotonic() - t0
    survived = [r.mutant.name for r in results if r.verdict != "KILLED"]
    print(f"{len(results)} mutants in {seconds / 60:.1f} min: {len(results) - len(survived)} killed"
          + (f"; not killed: {', '.join(survived)}" if survived else ""))
    if args.only:
        print("(--only: docs/reliability.md left as it was)")
    else:
        write_section(section(results, started, seconds, jobs, source, skip_c + skip_py))
        print(f"wrote the table to {DOC.relative_to(ROOT)}")
    return 1 if survived else 0

