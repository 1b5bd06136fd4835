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
# indices into the harness's tables
V = {0.0: 0, 0.5: 4, 1e-5: 6, 1e-4: 7, 1e-3: 8, 0.626418: 11, 0.7437: 12, 9.81: 20, 1e3: 22}
REF = {1: 0, 2: 1, 9: 8, 10: 9, 11: 10, 12: 11, 13: 12, 30: 22, 31: 23, 32: 24, 40: 25, 23: 29, 24: 30, 25: 31,
       26: 32, 33: 33, 34: 34}


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
    "out_of_order": bytes([STEP, V[1e-4], 0, EXIT, TERMINATE, INSTANTIATE, 0, STEP, V[1e-4], 0, OUTPUTS, EXIT,
                           GET_STATE, SERIALIZE, TERMINATE, ENTER, SET_INT, REF[30], 7, EXIT, EXIT, STEP, V[1e-4], 0,
                           ENTER, FREE_STATE, 0, FREE, FREE]),
}

for name, program in SEEDS.items():
    (HERE / "fuzz_corpus" / f"{name}.bin").write_bytes(program)
print(f"wrote {len(SEEDS)} seeds to {HERE / 'fuzz_corpus'}")
