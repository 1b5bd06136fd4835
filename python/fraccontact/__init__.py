"""fraccontact: a fractional-calculus contact element for impact simulation.

The model runs in-process on its C library:

    import fraccontact
    r = fraccontact.impact(height=0.020, c=5000.0)      # a Run: r.F_peak, r.eps, r.end.x2, r.per_impact
    r = fraccontact.impact(damper="springpot", damper_order=0.5, c_alpha=3e5)
    a = fraccontact.impacts(c=numpy.linspace(3e3, 9e3, 100))   # a Run of arrays, one library call
    s = fraccontact.simulate(output_interval=1e-5)       # a Series: s.t, s.F, ..., s.run
    fraccontact.fmu_path()                               # the FMI 2.0 FMU to co-simulate

Results read by attribute or key alike (r.F_peak, r["F_peak"]); their
fields are listed in fraccontact.model's docstring. The console command
`fraccontact` (python -m fraccontact) runs the h20 example, fits, sweeps,
co-simulations and the crash scenes (fraccontact --help).
"""

from .export import export
from .model import (End, Impact, ParameterWarning, Run, Series, defaults, drop_velocity, impact, impacts,
                    memory_kernel, parameters, simulate, warning)
from .shipped import fmu_path

__all__ = ["End", "Impact", "ParameterWarning", "Run", "Series", "defaults", "drop_velocity", "export", "fmu_path", "impact",
           "impacts", "memory_kernel", "parameters", "simulate", "warning"]

