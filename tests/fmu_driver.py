"""Drives the FMU by variable name through fmpy's FMU2Slave, as a master does."""

import math
from ctypes import byref

from fmpy import calloc, free
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
from fmpy.logging import addLoggerProxy

# The paper's h20 test (MODEL.md §1, §6).
G = 9.81
V0 = math.sqrt(2 * G * 0.020)
M = 0.7437
K = 3.299e8
C = 6080.0

# fmpy's native logger proxy keeps the last callback it was given in a global,
# which a later FMU that logs (a warning from fmpy.simulate_fmu, say) calls:
# so no callback handed to it may be freed before the process ends.
_PROXIED_CALLBACKS = []


class Slave:
    """One instance of the FMU, set, read and stepped by variable name.

    Log messages land in self.log as (status, category, message), the
    instance names they carry in self.log_names."""

    def __init__(self, model_description, unzipped, start=True, **values):
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
                             instanceName="test")
        self.fmu.instantiate(callbacks=self.callbacks)
        self.fmu.setupExperiment(startTime=0.0)
        self.t = 0.0
        self.set(**values)
        if start:
            self.start()

    def _logger(self, env, name, status, category, message):
        self.log.append((status, category.decode(), message.decode()))
        self.log_names.append(name.decode())

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


def run_impact(s, H=1e-5, t_end=5e-3):
    """Steps a started drop test until its first impact ends; returns the
    results read from the outputs, the contact time from the free flight that
    follows: x - x2 = v_striker (t - t_sep) with no gravity."""
    while s.get("eps") == 0.0 and s.t < t_end:
        s.step(H)
    v = s.get("v_striker")
    t_sep = s.t - (s.get("x") - s.get("x2")) / v
    return dict(F_peak=s.get("F_peak"), eps=s.get("eps"), x2=s.get("x2"), E_diss=s.get("E_diss"),
                t_contact=t_sep, v_end=v)
