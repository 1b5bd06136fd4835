"""The drop test as an SSP file (build/drop_test.ssp, made by CMake from ssp/):
the striker and the contact FMU wired for the predictive coupling (F_avg_next),
run by two independent SSP importers, fmpy and libcosim (libcosimpy), and by
OMSimulator where it is installed (fraccontact.omsimulator).

Both step every FMU from the values of the last communication point (Jacobi),
so the results are those of fraccontact.cosim's Jacobi order, predictive
coupling. Used by the cosim_study report and tests/test_ssp.py.
"""

import math
import os
import pathlib

import numpy as np

from . import fmu_path
from .cosim import M, V0

T_END = 3e-3  # the SSD's DefaultExperiment: the impact and the rebound


def ssp_path():
    """The scene: $DROP_TEST_SSP, else drop_test.ssp next to the contact FMU
    (the build folder, or the installed package, which ships both)."""
    path = pathlib.Path(os.environ.get("DROP_TEST_SSP") or fmu_path().parent / "drop_test.ssp")
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: build it (scripts/build makes build/drop_test.ssp; pip install . puts it in the package)")
    return path


def bound_parameters(ssp):
    """The parameter bindings of every component of the SSP ssp (a path) as
    one fmpy parameter set, for simulate_ssp(ssp, ..., parameter_set=...):
    fmpy applies no binding itself, only a set it is given, and matches its
    names by the component's path ("contact.scene", "head.v0"), where a
    binding names the component's own variables ("scene")."""
    from fmpy.ssp.ssd import ParameterSet, Parameter, find_components, read_ssd
    merged = ParameterSet(name="bindings")
    for component in find_components(read_ssd(str(ssp)).system):
        for binding in component.parameterBindings:
            for values in binding.parameterValues:
                for p in values.parameters:
                    merged.parameters.append(Parameter(name=f"{component.name}.{p.name}", type=p.type,
                                                       value=p.value, unit=p.unit))
    return merged


def summary(F_peak, E_diss, v_end):
    """What fraccontact.cosim reports of a run: eps from the striker's final
    velocity, the energy error against the impact energy."""
    return dict(F_peak=F_peak, eps=-v_end / V0, E_diss=E_diss,
                energy_error=(0.5 * M * v_end ** 2 + E_diss) / (0.5 * M * V0 ** 2) - 1)


def run_fmpy(ssp, H, t_end=T_END):
    """The scene in fmpy's SSP master. It starts every connector at 0, so the
    contact's first step sees v = 0 and the impact begins one step late; the
    run is the Jacobi run shifted by H, its results the same once the
    rebound is over."""
    from fmpy.ssp.simulation import simulate_ssp
    rows = simulate_ssp(str(ssp), stop_time=t_end, step_size=H, parameter_set=bound_parameters(ssp))
    last = rows[-1]
    return dict(summary(last["contact.F_peak"], last["contact.E_diss"], last["striker.v"]), rows=rows)


def run_libcosim(ssp, H, t_end=T_END):
    """The scene in libcosim's SSP loader (it applies the parameter bindings
    itself), with its fixed-step algorithm at step H instead of the SSD's."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=round(H * 1e9))  # libcosim counts nanoseconds
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    ex.simulate_until(target_time=round(t_end * 1e9))
    contact, striker = (ex.slave_index_from_instance_name(n) for n in ("contact", "striker"))
    vr = {name: {v.name.decode(): v.reference for v in ex.slave_variables(index)}
          for name, index in (("contact", contact), ("striker", striker))}
    F_peak, E_diss = observer.last_real_values(contact, [vr["contact"]["F_peak"], vr["contact"]["E_diss"]])
    v_end = observer.last_real_values(striker, [vr["striker"]["v"]])[0]
    # libcosim only warns when a binding fails to apply: report what the contact runs with
    names = ("scene", "law", "coupling")
    applied = dict(zip(names, observer.last_integer_values(contact, [vr["contact"][n] for n in names])))
    return dict(summary(F_peak, E_diss, v_end), applied=applied)


def grid(H, t_end):
    """A fixed-step master's communication points 0, H, ..., N H with N H the last <= t_end."""
    n = int(math.floor(t_end / H * (1 + 1e-12)))
    return np.arange(n + 1) * H


def run_omsimulator(ssp, H, t_end=T_END):
    """The scene in OMSimulator's fixed-step master (it applies the parameter
    bindings itself) at step H instead of the SSD's."""
    from .omsimulator import simulate
    trace = simulate(ssp, H, grid(H, t_end), {}, ("contact.F_peak", "contact.E_diss", "striker.v"))
    return summary(trace["contact.F_peak"][-1], trace["contact.E_diss"][-1], trace["striker.v"][-1])
