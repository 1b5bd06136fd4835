"""FMU state: get, set, serialize and deserialize restore the simulation bit
for bit, in the same instance, in a new one and in another process; damaged,
truncated or foreign states are refused with an error."""

import struct
import subprocess
import sys
import textwrap

import pytest
from fmpy.fmi1 import FMICallException

OUTPUTS = ["F", "F_avg", "F_avg_next", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps", "semi_integral"]
H = 1e-5


def outputs(s):
    """The outputs as exact bit patterns, so that equality means bit for bit."""
    return [struct.pack("<d", s.get(name)) for name in OUTPUTS] + [s.get("contact")]


def run(s, n):
    history = []
    for _ in range(n):
        s.step(H)
        history.append(outputs(s))
    return history


@pytest.mark.parametrize("law", [1, 2])
def test_step_save_step_restore_step_is_bit_exact(slave, law):
    s = slave(law=law)
    run(s, 40)                      # into the contact
    t = s.t
    state = s.fmu.getFMUstate()
    first = run(s, 60)              # through peak and separation
    s.fmu.setFMUstate(state)
    s.t = t
    assert run(s, 60) == first
    s.fmu.freeFMUstate(state)


def test_a_state_restores_in_a_new_instance(slave):
    """Taken mid-contact, restored in an instance of other settings, and run
    on through the peak and the separation: every output, eps (which needs
    the onset's velocity from the state) included, bit for bit."""
    a = slave(law=1)
    run(a, 50)
    t = a.t
    blob = a.fmu.serializeFMUstate(a.fmu.getFMUstate())
    expected = run(a, 90)           # to 1.4 ms: the contact ends at 1.32 ms
    assert expected[-1][OUTPUTS.index("eps")] != struct.pack("<d", 0.0)
    b = slave(law=2, c=1000.0)      # different settings: the state brings its own
    b.fmu.setFMUstate(b.fmu.deSerializeFMUstate(blob))
    b.t = t
    assert run(b, 90) == expected


def test_a_serialized_state_survives_a_file_and_another_process(slave, fmu_path, tmp_path):
    s = slave()
    run(s, 30)
    path = tmp_path / "state.bin"
    path.write_bytes(s.fmu.serializeFMUstate(s.fmu.getFMUstate()))
    expected = run(s, 50)
    script = textwrap.dedent(f"""
        import struct
        from fmpy import extract, read_model_description
        from fraccontact.fmu import Slave
        md = read_model_description({str(fmu_path)!r})
        s = Slave(md, extract({str(fmu_path)!r}, unzipdir={str(tmp_path / "unzipped")!r}))
        s.fmu.setFMUstate(s.fmu.deSerializeFMUstate(open({str(path)!r}, "rb").read()))
        s.t = {s.t - 50 * H!r}
        for _ in range(50):
            s.step({H!r})
            print(" ".join(struct.pack("<d", s.get(n)).hex() for n in {OUTPUTS!r}), s.get("contact"))
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    got = done.stdout.split("\n")[:-1]
    assert got == [" ".join(b.hex() for b in row[:-1]) + f" {row[-1]}" for row in expected]


def damaged(blob):
    yield "truncated", blob[:-1]
    yield "empty", b""
    yield "extended", blob + b"\0"
    flipped = bytearray(blob)
    flipped[len(blob) // 2] ^= 0x40
    yield "corrupted", bytes(flipped)
    version = bytearray(blob)
    version[4] += 1
    yield "another format version", bytes(version)
    guid = bytearray(blob)
    guid[8] ^= 1
    yield "another FMU", bytes(guid)
    yield "not a state", b"x" * len(blob)


@pytest.mark.parametrize("case", ["truncated", "empty", "extended", "corrupted", "another format version",
                                  "another FMU", "not a state"])
def test_damaged_states_are_refused(slave, case):
    s = slave()
    run(s, 20)
    blob = dict(damaged(s.fmu.serializeFMUstate(s.fmu.getFMUstate())))[case]
    before = outputs(s)
    with pytest.raises(FMICallException):
        s.fmu.deSerializeFMUstate(blob)
    assert "FMU state" in s.last_error() or "fraccontact" in s.last_error(), s.last_error()
    assert outputs(s) == before     # nothing changed ...
    s.step(H)                        # ... and the instance goes on


def test_a_valid_checksum_does_not_smuggle_in_invalid_values(slave):
    """A state whose bytes were rewritten and re-checksummed (a crafted or
    buggy master) is still checked value by value."""
    import zlib
    s = slave()
    blob = bytearray(s.fmu.serializeFMUstate(s.fmu.getFMUstate()))
    payload = 20 + 12
    blob[payload + 6 * 8: payload + 7 * 8] = struct.pack("<d", -1.0)  # the 7th field: c
    blob[16:20] = struct.pack("<I", zlib.crc32(bytes(blob[20:])))
    state = s.fmu.deSerializeFMUstate(bytes(blob))
    with pytest.raises(FMICallException):
        s.fmu.setFMUstate(state)
    assert "c = -1" in s.last_error()
    s.step(H)


def test_restoring_a_state_from_before_initialization_goes_back_there(slave):
    s = slave(start=False)
    state = s.fmu.getFMUstate()
    s.start()
    run(s, 5)
    s.fmu.setFMUstate(state)
    with pytest.raises(FMICallException):   # instantiated again: no step before initialization
        s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=H)
    s.set(c=1000.0)                          # parameters are settable again
    s.t = 0.0
    s.start()
    s.step(H)


@pytest.mark.parametrize("mode", [0, 3, 8, 32, 64, 1 << 31])
def test_a_state_in_a_mode_the_fmu_never_enters_is_refused(slave, mode):
    """The slave has the modes instantiated (1), initialization (2), step
    complete (4) and terminated (16) only: no stepFailed (8) or error (32)
    state is ever entered, so a state that claims one (re-checksummed, as a
    crafted or buggy master might) is refused and the instance goes on."""
    import zlib
    s = slave()
    run(s, 3)
    blob = bytearray(s.fmu.serializeFMUstate(s.fmu.getFMUstate()))
    blob[20:24] = struct.pack("<I", mode)
    blob[16:20] = struct.pack("<I", zlib.crc32(bytes(blob[20:])))
    state = s.fmu.deSerializeFMUstate(bytes(blob))
    before = outputs(s)
    with pytest.raises(FMICallException):
        s.fmu.setFMUstate(state)
    assert "impossible mode" in s.last_error()
    assert outputs(s) == before
    s.step(H)
