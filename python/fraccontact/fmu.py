"""Drives an FMU by variable name through fmpy's FMU2Slave, as a master does:
the co-simulation driver, the hostile-input report and the tests use it."""

import atexit
import collections
import functools
import pathlib
import shutil
from ctypes import byref

from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
from fmpy.logging import addLoggerProxy

# fmpy's native logger proxy keeps the last callback it was given in a global,
# which a later FMU that logs (a warning from fmpy.simulate_fmu, say) calls:
# so no callback handed to it may be freed before the process ends.
_PROXIED_CALLBACKS = []
# The proxy calls the last callback given, so an instance's messages may land
# in another's log: every message also lands here, with its instance's name.
_RECENT = collections.deque(maxlen=100)


def description(path, names, fmi2=False):
    """The model description of the co-simulation FMU file at path, which
    must have the variables names (and be FMI 2.0 where fmi2, for the
    masters driving FMU2Slave); else ValueError saying what the file is."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise ValueError("no such file" if not path.exists() else "not a file")
    try:
        md = read_model_description(str(path))
    except Exception as e:  # fmpy's: BadZipFile, KeyError, XML and schema errors, each saying "not an FMU"
        raise ValueError(f"not an FMU ({e})") from None
    if md.coSimulation is None:
        raise ValueError(f"the FMU {md.modelName} is not for co-simulation")
    if fmi2 and md.fmiVersion != "2.0":
        raise ValueError(f"the FMU {md.modelName} is FMI {md.fmiVersion}; this master drives FMI 2.0")
    missing = [n for n in names if n not in {v.name for v in md.modelVariables}]
    if missing:
        shown = ", ".join(missing[:4]) + (f" and {len(missing) - 4} more" if len(missing) > 4 else "")
        raise ValueError(f"the FMU {md.modelName} lacks the variables {shown}")
    return md


@functools.lru_cache(maxsize=None)
def unpacked(path):
    """The FMU's model description and the folder it is extracted to: once
    per file and process (a study makes hundreds of instances), removed when
    the process exits. The instances share the folder's shared library."""
    md = read_model_description(path)
    folder = extract(path)
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    return md, folder


class Slave:
    """One instance of the FMU, set, read and stepped by variable name.

    Log messages land in self.log as (status, category, message), the
    instance names they carry in self.log_names."""

    def __init__(self, model_description, unzipped, start=True, instance_name="test", **values):
        self.md = model_description
        self.variables = {v.name: v for v in model_description.modelVariables}
        self.log = []
        self.log_names = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._logger)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(self.callbacks))
        _PROXIED_CALLBACKS.append(self.callbacks)
        self.fmu = FMU2Slave(guid=model_description.guid, unzipDirectory=unzipped,
                             modelIdentifier=model_description.coSimulation.modelIdentifier,
                             instanceName=instance_name)
        self.fmu.instantiate(callbacks=self.callbacks)
        self.fmu.setupExperiment(startTime=0.0)
        self.t = 0.0
        self.set(**values)
        if start:
            self.start()

    def _logger(self, env, name, status, category, message):
        self.log.append((status, category.decode(), message.decode()))
        self.log_names.append(name.decode())
        _RECENT.append((name.decode(), status, message.decode()))

    def start(self):
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def enter(self):
        """Initialization mode: values can be set and read back."""
        self.fmu.enterInitializationMode()

    def set(self, **values):
        for name, value in values.items():
            v = self.variables[name]
            if v.type == "Real":
                self.fmu.setReal([v.valueReference], [float(value)])
            elif v.type == "Integer":
                self.fmu.setInteger([v.valueReference], [int(value)])
            else:
                self.fmu.setBoolean([v.valueReference], [bool(value)])

    def get(self, name):
        v = self.variables[name]
        if v.type == "Real":
            return self.fmu.getReal([v.valueReference])[0]
        if v.type == "Integer":
            return self.fmu.getInteger([v.valueReference])[0]
        return bool(self.fmu.getBoolean([v.valueReference])[0])

    def step(self, H):
        self.fmu.doStep(currentCommunicationPoint=self.t, communicationStepSize=H)
        self.t += H

    def last_error(self):
        errors = [m for s, c, m in self.log if s >= 3]
        return errors[-1] if errors else ""

    def recent_error(self):
        """The last error logged under this instance's name, in whichever
        Slave's callback fmpy's proxy delivered it."""
        return next((m for n, s, m in reversed(_RECENT) if n == self.fmu.instanceName and s >= 3), "")

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
