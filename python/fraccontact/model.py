"""The contact model in-process: one run, a batch of runs, a time series.

Parameters are the FMU's variable names (v, m, R, E_i, nu_i, E_s, nu_s, k, c,
law, g1_nodes, dt_max, scene, g, gap0), the scheme, the stop conditions
t_end and impacts, and height as a convenience for v (v = sqrt(2 g h)).
Word values are accepted where the CLI takes them: law g1/hertz/g1x, scene
drop/driven, scheme sdirk2/central. A bad value raises ValueError with the
library's own message (variable, value, rule)."""

import ctypes
import math
from dataclasses import dataclass, field

import numpy as np

from . import _lib

WORDS = {"law": {"g1": 1, "hertz": 2, "g1x": 3}, "scene": {"drop": 1, "driven": 2},
         "scheme": {"sdirk2": 1, "central": 2}}
IMPACT_FIGURES = ("t_onset", "v_onset", "F_peak", "eps", "t_contact", "x2_end", "E_diss")
NAMES = tuple(p["name"] for p in _lib.PARAMETERS)


def parameters():
    """Every parameter: name, kind, unit, default and help, from the C library."""
    default = defaults()
    return [dict(name=p["name"], kind=p["kind"], unit=p["unit"], default=default[p["name"]], help=p["help"])
            for p in _lib.PARAMETERS]


def defaults():
    """{name: default} of every parameter: the paper's h20 drop test."""
    p = _default_params()
    return {name: getattr(p, name) for name in NAMES}


def step_limit(**params):
    """The largest internal step of these parameters [s]: dt_max, or for
    dt_max = 0 (the default) the fixed step of 1e-7 s, or inf where
    error-controlled steps have no cap."""
    return _lib.LIB.fc_step_limit(ctypes.byref(_params(**params)))


def drop_velocity(height):
    """The impact velocity sqrt(2 g h) of a drop from height h [m], g = 9.81 m/s^2."""
    return _lib.LIB.fc_drop_velocity(float(height))


def _default_params():
    p = _lib.Params()
    _lib.LIB.fc_params_default(ctypes.byref(p))
    return p


def _number(name, value):
    """A parameter's value as the library takes it: words to their codes."""
    if name in WORDS and isinstance(value, str):
        try:
            return WORDS[name][value]
        except KeyError:
            raise ValueError(f"{name} = {value!r} is invalid: one of {', '.join(WORDS[name])}") from None
    return value


def _given(params):
    """The parameters as {name: value}, height turned into v; unknown names refused."""
    params = dict(params)
    if "height" in params:
        if "v" in params:
            raise ValueError("give height or v, not both")
        height = params.pop("height")
        heights = np.asarray(height, dtype=float)
        if not np.all(np.isfinite(heights) & (heights >= 0)):
            raise ValueError(f"height = {height} is invalid: a drop height must be finite and >= 0 [m]")
        params["v"] = np.vectorize(drop_velocity, otypes=[float])(heights) if heights.ndim \
            else drop_velocity(heights)
    unknown = sorted(set(params) - set(NAMES))
    if unknown:
        raise TypeError(f"unknown parameter {', '.join(unknown)}; the parameters are {', '.join(NAMES)} and height")
    return params


def _checked(p):
    why = _lib.message_buffer()
    if _lib.LIB.fc_params_check(ctypes.byref(p), why, len(why)) != _lib.FC_OK:
        raise ValueError(why.value.decode())
    return p


def _params(**given):
    p = _default_params()
    for name, value in _given(given).items():
        setattr(p, name, _number(name, value))
    return _checked(p)


def warning(**params):
    """The library's warning for these parameters (a value without effect), or None."""
    p = _params(**params)
    why = _lib.message_buffer()
    return why.value.decode() if _lib.LIB.fc_params_warning(ctypes.byref(p), why, len(why)) else None


def memory_kernel(**params):
    """The compressed memory's kernel for these parameters (damper_order,
    memory_tolerance, dt_max, and whether error-controlled steps apply, which
    fit it from min(dt_max, 1e-9 s); MODEL.md §8): (a, b, eta) with
    tau^(-alpha)/Gamma(1-alpha) ~ eta delta(tau) + sum a_i exp(-b_i tau),
    the last term the lumped spring (b = 0)."""
    p = _params(**params)
    size = 256
    a, b, eta = (ctypes.c_double * size)(), (ctypes.c_double * size)(), ctypes.c_double()
    why = _lib.message_buffer()
    n = _lib.LIB.fc_memory_kernel(ctypes.byref(p), size, a, b, ctypes.byref(eta), why, len(why))
    if n == 0 and why.value:
        raise ValueError(why.value.decode())
    return np.array(a[:n]), np.array(b[:n]), eta.value


@dataclass
class Impact:
    """One finished impact."""
    t_onset: float    # contact onset [s]
    v_onset: float    # striker velocity at onset [m/s]
    F_peak: float     # its largest force [N]
    eps: float        # restitution coefficient
    t_contact: float  # contact duration [s]
    x2_end: float     # permanent indentation when it ended (all impacts so far) [m]
    E_diss: float     # energy dissipated during it [J]


def _impact(c):
    return Impact(*(getattr(c, name) for name in IMPACT_FIGURES))


@dataclass
class End:
    """The FMU's outputs where a run stopped."""
    t: float          # time [s]
    F_peak: float     # the largest force of the run [N]
    eps: float        # restitution coefficient of the last finished impact (0 when none)
    t_contact: float  # duration of the last finished impact [s]
    E_diss: float     # energy dissipated in all [J]
    x: float          # total indentation [m]
    x1: float         # elastic indentation [m]
    x2: float         # permanent indentation [m]
    v: float          # striker velocity [m/s]


END_FIGURES = tuple(End.__dataclass_fields__)


@dataclass
class Run:
    """A run, as fraccontact-solve --json gives it: the figures of its first
    impact as attributes (NaN when no impact ended), every finished impact in
    per_impact, the FMU's outputs where it stopped in end, and why."""
    t_onset: float
    v_onset: float
    F_peak: float
    eps: float
    t_contact: float
    x2_end: float
    E_diss: float
    per_impact: list = field(default_factory=list)
    end: End = None
    stopped: str = ""  # impacts, t_end or receding
    impacts: int = 0   # finished impacts
    steps: int = 0     # internal steps
    k: float = 0.0     # the Hertz constant used [N/m1.5]


def _run(o, per_impact):
    first = [getattr(o.first, name) if o.impacts else math.nan for name in IMPACT_FIGURES]
    return Run(*first, per_impact=per_impact, end=End(*(getattr(o, name) for name in END_FIGURES)),
               stopped=_lib.STOPS[o.stop], impacts=o.impacts, steps=o.steps, k=o.k)


def _call_run(p, interval):
    r = _lib.Result()
    why = _lib.message_buffer()
    try:
        status = _lib.LIB.fc_run(ctypes.byref(p), interval, ctypes.byref(r), why, len(why))
        if status != _lib.FC_OK:
            raise (ValueError if status == _lib.FC_EINVAL else RuntimeError)(why.value.decode())
        per_impact = [_impact(r.per_impact[i]) for i in range(r.n_impacts)]
        rows = np.ctypeslib.as_array(r.rows, shape=(r.n_rows, len(_lib.COLUMNS))).copy() if r.n_rows else \
            np.zeros((0, len(_lib.COLUMNS)))
        return _run(r.outcome, per_impact), rows
    finally:
        _lib.LIB.fc_result_free(ctypes.byref(r))


def impact(**params):
    """One drop test or driven run; its first impact's figures and every
    impact in .per_impact."""
    return _call_run(_params(**params), _lib.NO_ROWS)[0]


def simulate(output_interval=None, **params):
    """The time series of a run: a row every output_interval seconds (None:
    about 250 rows per contact; 0: every internal step) and at every onset
    and separation. Returns a dict of NumPy arrays t, F, x, x1, x2, v, E_diss
    (SI units) and the run's figures under "run"."""
    p = _params(**params)
    interval = _lib.DEFAULT_ROWS if output_interval is None else float(output_interval)
    if not (interval == _lib.DEFAULT_ROWS or (math.isfinite(interval) and interval >= 0)):
        raise ValueError(f"output_interval = {output_interval} is invalid: it must be finite and >= 0 [s]")
    run, rows = _call_run(p, interval)
    series = {name: rows[:, i] for i, name in enumerate(_lib.COLUMNS)}
    series["run"] = run
    return series


def impacts(**params):
    """Many runs in one library call. Any parameter may be a NumPy array;
    they broadcast together. Returns a dict of arrays of the broadcast shape,
    named as Run's: the first impact's figures (NaN where none ended),
    impacts, steps, stopped, k, and "end", a dict of the end's arrays."""
    given = _given(params)
    names = list(given)
    values = np.broadcast_arrays(*[_words_to_numbers(name, given[name]) for name in names]) if names else []
    shape = values[0].shape if names else ()
    batch = np.empty(int(np.prod(shape)), dtype=np.dtype(_lib.Params))
    batch[:] = np.frombuffer(bytes(_default_params()), dtype=np.dtype(_lib.Params))[0]
    for name, value in zip(names, values):
        batch[name] = value.ravel()
    out = np.zeros(len(batch), dtype=np.dtype(_lib.Outcome))
    if _lib.LIB.fc_run_batch(len(batch), batch.ctypes.data, out.ctypes.data) != _lib.FC_OK:
        _raise_for_case(batch, out, shape)
    ended = out["impacts"] > 0
    result = {name: np.where(ended, out["first"][name], np.nan).reshape(shape) for name in IMPACT_FIGURES}
    result.update(impacts=out["impacts"].reshape(shape), steps=out["steps"].reshape(shape),
                  stopped=np.array([_lib.STOPS.get(s, "") for s in out["stop"]]).reshape(shape),
                  k=out["k"].reshape(shape), end={name: out[name].reshape(shape) for name in END_FIGURES})
    return result


def _words_to_numbers(name, value):
    if name in WORDS:
        words = np.asarray(value)
        if words.dtype.kind in "US":
            return np.vectorize(lambda w: _number(name, str(w)))(words)
    return np.asarray(value)


def _raise_for_case(batch, out, shape):
    """The first failed case's message, with its index in the broadcast shape."""
    i = int(np.flatnonzero(out["status"] != _lib.FC_OK)[0])
    index = np.unravel_index(i, shape) if shape else ()
    p = _lib.Params.from_buffer_copy(batch[i].tobytes())
    why = _lib.message_buffer()
    if _lib.LIB.fc_params_check(ctypes.byref(p), why, len(why)) != _lib.FC_OK:
        raise ValueError(f"case {tuple(int(j) for j in index)}: {why.value.decode()}")
    raise RuntimeError(f"case {tuple(int(j) for j in index)}: the run failed (status {out['status'][i]})")
