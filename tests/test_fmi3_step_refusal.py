"""An FMI 3.0 step that goes on after an event inside it (an intermediate
update callback, no early return) and whose rest is refused changes
nothing, as every refused step: here a springpot under g = 1e300 touches at
t = 0 (the callback hears of it) and its state becomes non-finite after.
The fuzzer found the contact output left true and the time at the event
(tests/fuzz_regressions/fmi3-refused-rest-of-a-step-after-an-event.bin)."""

import os
import pathlib

from conftest import FMU

FMU3 = pathlib.Path(os.environ.get("FRACCONTACT_FMU3", FMU.parent / "fraccontact-fmi3.fmu"))


def test_a_refused_rest_of_a_step_takes_the_whole_step_back():
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Slave
    md = read_model_description(str(FMU3))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    errors, updates = [], []
    slave = FMU3Slave(guid=md.guid, unzipDirectory=extract(str(FMU3)), modelIdentifier="fraccontact")

    def intermediate_update(env, time, *rest):
        updates.append(time)
        return 0  # fmpy's ctypes callback returns nothing the FMU reads

    slave.instantiate(logMessage=lambda env, status, cat, msg: errors.append(msg.decode()) if status >= 3 else None,
                      intermediateUpdate=intermediate_update)
    slave.enterInitializationMode(startTime=0.0)
    slave.setInt32([vr["damper"]], [2])
    slave.setFloat64([vr["g"]], [1e300])
    slave.exitInitializationMode()
    names = ["time", "F", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps"]
    before = slave.getFloat64([vr[n] for n in names]), slave.getBoolean([vr["contact"]])
    try:
        slave.doStep(0.0, 1e-4)
        taken = True
    except Exception:  # fmpy's FMICallException on fmi3Error
        taken = False
    assert not taken and updates == [0.0] and "non-finite" in errors[-1], (updates, errors)
    after = slave.getFloat64([vr[n] for n in names]), slave.getBoolean([vr["contact"]])
    assert after == before  # bit for bit: nothing of the step's first part is left
