"""Writes the fuzzer's seed corpus, tests/fuzz_corpus/*.bin: programs in the
byte language of tests/fuzz_fmi2.c that walk the FMU through its ordinary
life, so that the fuzzer starts from deep states. Run it after changing the
language: .venv/bin/python tests/fuzz_seeds.py"""

import pathlib
import struct

HERE = pathlib.Path(__file__).resolve().parent
INSTANTIATE, FREE, SETUP, ENTER, EXIT, TERMINATE, RESET, SET_REAL, SET_INT = range(9)
OUTPUTS, STEP, GET_STATE, SET_STATE, FREE_STATE, SERIALIZE, DESERIALIZE, IN_DER, OUT_DER = range(10, 19)
LOGGING, STRINGS, STATUSES, GET_INT_BOOL = 19, 20, 21, 22
INSTANTIATE_ME, ME_EVALUATE, ME_MODE = 23, 24, 25  # Model Exchange: the instance, a solver's evaluation, a mode
# indices into the harness's tables
V = {0.0: 0, 1.0: 2, -1.0: 3, 0.5: 4, 1e-5: 6, 1e-4: 7, 1e-3: 8, 0.626418: 11, 0.7437: 12, 9.81: 20, 1e3: 22}
REF = {1: 0, 2: 1, 9: 8, 10: 9, 11: 10, 12: 11, 13: 12, 30: 22, 31: 23, 32: 24, 40: 25, 23: 29, 24: 30, 25: 31,
       26: 32, 33: 33, 34: 34, 27: 37, 36: 38, 37: 39, 38: 40, 39: 41}


def raw(x):
    return bytes([0x80]) + struct.pack("<d", x)


def start(b=0, params=b""):
    return bytes([INSTANTIATE | b, 1, SETUP | b, V[0.0], ENTER | b]) + params + bytes([EXIT | b])


def steps(n, H=1e-4, b=0):
    return bytes([STEP | b, V[H], 0] * n)


SEEDS = {
    "h20_drop": start() + steps(20) + bytes([OUTPUTS, GET_STATE, SERIALIZE, DESERIALIZE, 40, 0, 0, SET_STATE, 0])
    + steps(5) + bytes([TERMINATE, FREE]),
    "driven_with_slope": start(params=bytes([SET_INT, REF[32], 2, SET_REAL, REF[1], V[0.5], SET_REAL, REF[2],
                                              V[0.0]])) + bytes([IN_DER, REF[1], 1, V[9.81]]) + steps(10)
    + bytes([OUT_DER, REF[13], 1, OUTPUTS, RESET, FREE]),
    "two_instances_and_gravity": start(0) + start(0x80, bytes([SET_REAL | 0x80, REF[11], V[9.81],
                                                                 SET_REAL | 0x80, REF[12], V[1e-3]]))
    + steps(8, 1e-3, 0) + steps(8, 1e-3, 0x80) + bytes([GET_STATE | 0x80, SET_STATE, 0, STATUSES, GET_INT_BOOL,
                                                          REF[30], STRINGS, REF[13], 1, LOGGING, 1, 3]),
    "hostile_values": start(params=bytes([SET_REAL, REF[9]]) + raw(float("nan")) + bytes([SET_REAL, REF[10]])
                            + raw(5e-324) + bytes([SET_REAL, REF[1]]) + raw(1e300)) + steps(3, 1e3)
    + bytes([STEP, V[1e-5], 1]) + raw(0.5) + bytes([OUTPUTS]),
    "springpot_compressed": start(params=bytes([SET_INT, REF[33], 2])) + steps(20)
    + bytes([OUTPUTS, GET_STATE, SERIALIZE, DESERIALIZE, 40, 0, 0, SET_STATE, 0]) + steps(5) + bytes([TERMINATE, FREE]),
    "springpot_full_history": start(params=bytes([SET_INT, REF[33], 2, SET_INT, REF[34], 1, SET_REAL, REF[10], V[1e-5]]))
    + steps(20) + bytes([OUTPUTS, GET_STATE, SERIALIZE, DESERIALIZE, 40, 0, 0, SET_STATE, 0]) + steps(5)
    + bytes([TERMINATE, FREE]),
    # error-controlled steps (tolerance > 0): ESDIRK 5(4) for the dashpot, Radau IIA for the springpot
    "dashpot_controlled": start(params=bytes([SET_INT, REF[30], 2, SET_REAL, REF[27], V[1e-5]])) + steps(20)
    + bytes([OUTPUTS, GET_STATE, SERIALIZE, DESERIALIZE, 40, 0, 0, SET_STATE, 0]) + steps(50) + bytes([TERMINATE, FREE]),
    # a linear spring (the stage's root for n other than 3/2) through the separation, and a driven proxy striker
    # between two bodies under other forces (the coupling's energy account)
    "linear_spring_to_separation": start(params=bytes([SET_REAL, REF[23], V[1.0]])) + steps(70) + bytes([OUTPUTS]),
    "driven_proxy_two_bodies": start(params=bytes([SET_INT, REF[32], 2, SET_REAL, REF[37], V[1e3]]))
    + bytes([SET_REAL, REF[38], V[9.81]]) + steps(30) + bytes([OUTPUTS, RESET, FREE]),
    "springpot_controlled": start(params=bytes([SET_INT, REF[30], 2, SET_INT, REF[33], 2, SET_REAL, REF[27],
                                                V[1e-5]])) + steps(20)
    + bytes([OUTPUTS, GET_STATE, SERIALIZE, DESERIALIZE, 40, 0, 0, SET_STATE, 0]) + steps(5) + bytes([TERMINATE, FREE]),
    "two_free_bodies": start(params=bytes([SET_REAL, REF[37], V[0.7437], SET_REAL, REF[36], V[-1.0]])) + steps(20)
    + bytes([OUTPUTS, RESET, FREE]),
    # law 2, through the initial event into continuous time, the striker moved into the specimen and out
    "model_exchange": bytes([INSTANTIATE_ME, 1, SETUP, V[0.0], ENTER, SET_INT, REF[30], 2, EXIT, ME_MODE, 1, ME_MODE, 2])
    + bytes([ME_EVALUATE, 0, V[1e-4], V[1e-4], ME_MODE, 0, ME_MODE, 1, ME_MODE, 2, ME_MODE, 3, OUTPUTS, GET_STATE])
    + bytes([ME_EVALUATE, 0]) + raw(-1e-3) + bytes([V[1e-3], ME_MODE, 0, ME_MODE, 1, SET_STATE, 0, TERMINATE, FREE]),
    "out_of_order": bytes([STEP, V[1e-4], 0, EXIT, TERMINATE, INSTANTIATE, 0, STEP, V[1e-4], 0, OUTPUTS, EXIT,
                           GET_STATE, SERIALIZE, TERMINATE, ENTER, SET_INT, REF[30], 7, EXIT, EXIT, STEP, V[1e-4], 0,
                           ENTER, FREE_STATE, 0, FREE, FREE]),
}

for name, program in SEEDS.items():
    (HERE / "fuzz_corpus" / f"{name}.bin").write_bytes(program)
print(f"wrote {len(SEEDS)} seeds to {HERE / 'fuzz_corpus'}")

# --- FMI 3.0: the language of tests/fuzz_fmi3.c, seeds fmi3_*.bin -----------------------------------------
# Its opcodes (the low 5 bits; 0x80 picks the second instance) and arguments:
F3_INSTANTIATE, F3_FREE, F3_ENTER, F3_EXIT, F3_EVENT_MODE, F3_UPDATE, F3_STEP_MODE, F3_TERMINATE = range(8)
F3_RESET, F3_SET_REAL, F3_SET_INT, F3_SET_BOOL, F3_OUTPUTS, F3_STEP, F3_GET_STATE, F3_SET_STATE = range(8, 16)
F3_FREE_STATE, F3_SERIALIZE, F3_DESERIALIZE, F3_OUT_DER, F3_LOGGING, F3_REFUSED, F3_GET_INT_BOOL = range(16, 23)
F3_INSTANTIATE_ME, F3_ME_EVALUATE, F3_ME_MODE = 23, 24, 25  # as FMI 2.0's; a mode: 1 continuous time, 0 a step done
# F3_INSTANTIATE's flags byte
LOGGING_ON, EVENT_MODE, EARLY_RETURN, CALLBACK = 1, 2, 4, 8
WRONG_TOKEN, EMPTY_NAME, REQUIRED_VARIABLES = 0x10, 0x20, 0x40
# F3_DESERIALIZE's mangling: flip a byte (else overwrite 8 bytes with a value), cut there, fix the checksum
FLIP, CUT, FIX_CRC = 1, 2, 4


def f3_start(flags=0, b=0, params=b""):
    return (bytes([F3_INSTANTIATE | b, flags]) + params + bytes([F3_ENTER | b, V[0.0], 0, V[0.0], F3_EXIT | b])
            + (bytes([F3_UPDATE | b, F3_STEP_MODE | b]) if flags & EVENT_MODE else b""))


def f3_steps(n, H=1e-4, b=0, events=False):
    """n steps from the model's time; with event mode after each (legal in step mode, needed after an event)."""
    step = bytes([F3_STEP | b, V[H], 0, 0])
    return (step + bytes([F3_EVENT_MODE | b, F3_UPDATE | b, F3_STEP_MODE | b]) if events else step) * n


def f3_mangle(how, at, tail):
    return bytes([F3_DESERIALIZE, 1, how, at & 0xFF, at >> 8]) + tail


REF3 = {**REF, 0: 26}  # the same table, with time
GAP = bytes([F3_SET_REAL, REF[12]]) + raw(1e-4)
STATE_ROUND_TRIP = bytes([F3_GET_STATE, F3_SERIALIZE, F3_DESERIALIZE, 0])

SEEDS3 = {
    "fmi3_h20_plain": f3_start() + f3_steps(30) + bytes([F3_OUTPUTS]) + STATE_ROUND_TRIP
    + bytes([F3_TERMINATE, F3_OUTPUTS, F3_FREE]),
    "fmi3_gap_event_mode": f3_start(EVENT_MODE | EARLY_RETURN, params=GAP) + f3_steps(2, events=True)
    + STATE_ROUND_TRIP + f3_steps(28, events=True) + bytes([F3_OUTPUTS, F3_EVENT_MODE, F3_TERMINATE, F3_RESET]),
    "fmi3_gap_callback": f3_start(CALLBACK, params=GAP) + f3_steps(30) + bytes([F3_OUTPUTS, F3_OUT_DER, REF[13], 1]),
    "fmi3_gap_early_callback": f3_start(EARLY_RETURN | CALLBACK | LOGGING_ON, params=GAP) + f3_steps(30)
    + bytes([F3_OUTPUTS]),
    "fmi3_event_mode_callback_gravity": f3_start(EVENT_MODE | CALLBACK, params=GAP + bytes([F3_SET_REAL, REF[11], V[9.81]]))
    + f3_steps(30, 1e-4, events=True),
    "fmi3_two_instances_state": f3_start(EVENT_MODE | EARLY_RETURN, params=GAP)
    + f3_start(EVENT_MODE | EARLY_RETURN, 0x80) + f3_steps(4, events=True) + bytes([F3_GET_STATE, F3_EVENT_MODE | 0x80,
                                                                                    F3_SET_STATE | 0x80, 0])
    + f3_steps(10, b=0x80, events=True) + bytes([F3_FREE_STATE, 0, F3_FREE, F3_GET_INT_BOOL | 0x80, REF[40]]),
    "fmi3_mangled_states": f3_start(params=bytes([F3_SET_INT, REF[33], 2])) + f3_steps(4)
    + bytes([F3_GET_STATE, F3_SERIALIZE]) + f3_mangle(FIX_CRC, 40, bytes([V[1e3]]))
    + bytes([F3_FREE_STATE, 1]) + f3_mangle(FLIP | FIX_CRC, 20, bytes([0x02]))
    + bytes([F3_FREE_STATE, 1]) + f3_mangle(FLIP, 100, bytes([0x55]))
    + f3_mangle(CUT | FIX_CRC, 200, raw(float("nan"))) + bytes([F3_FREE_STATE, 1])
    + f3_mangle(FIX_CRC, 24, raw(float("inf"))) + f3_steps(2) + bytes([F3_OUTPUTS]),
    "fmi3_out_of_order": bytes([F3_STEP, V[1e-4], 0, 0, F3_INSTANTIATE, WRONG_TOKEN, F3_INSTANTIATE, EMPTY_NAME,
                                F3_INSTANTIATE, REQUIRED_VARIABLES, F3_INSTANTIATE, 0, F3_EVENT_MODE, F3_UPDATE,
                                F3_STEP_MODE, F3_EXIT, F3_STEP, V[1e-4], 0, 0, F3_OUTPUTS, F3_ENTER, V[0.0], 1, V[0.5],
                                F3_ENTER, V[0.0], 0, V[0.0], F3_SET_REAL, REF3[0], V[1e-4], F3_EXIT, F3_EVENT_MODE,
                                F3_UPDATE, F3_TERMINATE, F3_STEP, V[1e-4], 0, 0, F3_RESET, F3_LOGGING, 1, 4,
                                F3_LOGGING, 1, 2])
    + b"".join(bytes([F3_REFUSED, REF[13], k, V[1e-4]]) for k in range(24)) + bytes([F3_FREE, F3_FREE]),
    "fmi3_hostile_values": f3_start(EVENT_MODE | EARLY_RETURN | CALLBACK, params=bytes([F3_SET_REAL, REF[10]])
                                    + raw(5e-324) + bytes([F3_SET_REAL, REF[1]]) + raw(1e300) + GAP)
    + f3_steps(3, 1e3, events=True) + bytes([F3_STEP, V[1e-5], 1]) + raw(0.5) + bytes([0, F3_OUTPUTS])
    + bytes([F3_STEP, V[1e-5], 1]) + raw(float("nan")) + bytes([0]),
    "fmi3_springpot_controlled": f3_start(EVENT_MODE | EARLY_RETURN, params=bytes([F3_SET_INT, REF[30], 2, F3_SET_INT,
                                                                                   REF[33], 2, F3_SET_REAL, REF[27],
                                                                                   V[1e-5]]) + GAP)
    + f3_steps(20, events=True) + STATE_ROUND_TRIP + f3_steps(5) + bytes([F3_TERMINATE, F3_FREE]),
    # law 2, through the initial event into continuous time, the striker moved into the specimen and out
    "fmi3_model_exchange": bytes([F3_INSTANTIATE_ME, 1, F3_ENTER, V[0.0], 0, V[0.0], F3_SET_INT, REF[30], 2, F3_EXIT,
                                  F3_UPDATE, F3_ME_MODE, 1, F3_ME_EVALUATE, 0, V[1e-4], V[1e-4], F3_ME_MODE, 0,
                                  F3_EVENT_MODE, F3_UPDATE, F3_ME_MODE, 1, F3_OUTPUTS, F3_GET_STATE, F3_ME_EVALUATE, 0])
    + raw(-1e-3) + bytes([V[1e-3], F3_ME_MODE, 0, F3_EVENT_MODE, F3_UPDATE, F3_SET_STATE, 0, F3_TERMINATE, F3_FREE]),
    "fmi3_springpot_full_history": f3_start(EVENT_MODE | EARLY_RETURN, params=bytes([F3_SET_INT, REF[33], 2, F3_SET_INT,
                                                                                     REF[34], 1, F3_SET_REAL, REF[10],
                                                                                     V[1e-5]]) + GAP)
    + f3_steps(20, events=True) + STATE_ROUND_TRIP + f3_steps(5) + bytes([F3_TERMINATE, F3_FREE]),
}

for name, program in SEEDS3.items():
    (HERE / "fuzz_corpus" / f"{name}.bin").write_bytes(program)
print(f"wrote {len(SEEDS3)} FMI 3.0 seeds to {HERE / 'fuzz_corpus'}")

# --- Regressions (tests/fuzz_regressions/): inputs that ran for a minute
# before the harnesses bounded each input's work (fuzz_program.h), a
# springpot's full G1 history run again and again from a state at its start.
FULL_HISTORY_1E8 = bytes([SET_INT, REF[33], 2, SET_INT, REF[34], 1, SET_REAL, REF[10]]) + raw(1e-8)
F3_FULL_HISTORY_1E8 = bytes([F3_SET_INT, REF[33], 2, F3_SET_INT, REF[34], 1, F3_SET_REAL, REF[10]]) + raw(1e-8)
REGRESSIONS = {
    "slow-full-history-run-again": start(params=FULL_HISTORY_1E8) + bytes([GET_STATE])
    + (steps(3) + bytes([SET_STATE, 0])) * 21,
    "fmi3-slow-full-history-run-again": f3_start(params=F3_FULL_HISTORY_1E8) + bytes([F3_GET_STATE])
    + (f3_steps(3) + bytes([F3_SET_STATE, 0])) * 21,
}
for name, program in REGRESSIONS.items():
    (HERE / "fuzz_regressions" / f"{name}.bin").write_bytes(program)
print(f"wrote {len(REGRESSIONS)} regression inputs to {HERE / 'fuzz_regressions'}")
