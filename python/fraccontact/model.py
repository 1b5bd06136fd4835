"""The contact model in-process: one run, a batch of runs, a time series.

Parameters: the FMU's variable names (parameters() lists them with units
and defaults: v, m, v2, m2, R, E_i, nu_i, E_s, nu_s, k, c, law, g1_nodes,
dt_max, scene, g, gap0, ...), the scheme, the stops t_end and impacts, and
height as a convenience for v (v = sqrt(2 g h)). v2 and m2, the second
body's velocity and mass, make the striker the two bodies' relative motion
(the approach speed v - v2, the reduced mass m m2/(m + m2)); the FMU's
co-simulation inputs a, a2 and coupling are no parameters of a run
(TypeError says why). impacts() takes arrays for any of
them, broadcast together. An integer parameter takes a whole number (2 or
2.0, not 2.5 or True), and an enumerated one also the words of the solver's
--help and the FMU's modelDescription: law g1/hertz/g1x, scene drop/driven,
scheme gradient/central, damper dashpot/springpot, memory full/compressed.
A bad value raises ValueError naming the parameter, its value and the rule
(in a batch, the case's index too); a value without effect (E_s beside a
given k, damper_order with the dashpot) warns (ParameterWarning) with the
library's message, once per call.

Results, one shape for all three: dataclasses read by attribute or by key
alike (r.F_peak is r["F_peak"]; dict(r) and dataclasses.asdict(r) work), as
scipy's OptimizeResult.
  Run      what impact() returns, and impacts() with every figure an array of
           the broadcast shape:
             t_onset, v_onset, F_peak, eps, t_contact, x2_end, E_diss: the
               first impact's figures (NaN when none ended; a striker that
               never reaches the specimen warns, ParameterWarning);
             per_impact: every finished impact, a list of Impact (None from
               impacts(), whose library call keeps the first only);
             end: an End, the FMU's outputs where the run stopped (t, F_peak,
               eps, t_contact, E_diss, x, x1, x2, v);
             stopped: why, "impacts", "t_end" or "receding";
             impacts, steps, k: finished impacts, internal steps, the spring
               constant used;
             method: the method that ran, as the model names it (gradient,
               esdirk54, radau_iia, g1_history, central; docs/model.md §16).
  Series   what simulate() returns: the columns t, F, x, x1, x2, v, E_diss
           (arrays, SI units), and run, the Run impact() gives for the same
           parameters.

A library call stops at Ctrl-C (KeyboardInterrupt) and, on a terminal,
shows how far it has come when it runs longer than a few seconds."""

import collections.abc
import ctypes
import math
import numbers
import signal
import sys
import threading
import time
import warnings
from dataclasses import dataclass

import numpy as np

from . import _lib

# The words an enumerated parameter also takes, {word: code}, from the library's table.
WORDS = {p["name"]: {word: code for code, word in enumerate(p["words"], 1)} for p in _lib.PARAMETERS if p["words"]}
IMPACT_FIGURES = ("t_onset", "v_onset", "F_peak", "eps", "t_contact", "x2_end", "E_diss")
NAMES = tuple(p["name"] for p in _lib.PARAMETERS)
INTEGERS = frozenset(p["name"] for p in _lib.PARAMETERS if p["kind"] == "integer")
UNITS = dict({p["name"]: p["unit"] for p in _lib.PARAMETERS}, height="m")
C_INT = np.iinfo(np.intc)
# The FMU's variables that are no parameters of a library run, and why (docs/python.md).
CO_SIMULATION_ONLY = ("a", "a2", "coupling")
NO_MASTER = ("the FMU's inputs a, a2 and coupling are what a co-simulation master feeds at each communication "
             "step (docs/two_bodies.md); a library run has no master: its striker feels the contact and g only")
SHOW_AFTER = 3.0  # s: a library call longer than this shows its progress on a terminal
REDRAW = 0.5      # s between two drawings of that line


class ParameterWarning(UserWarning):
    """A parameter's value has no effect (the library's fc_params_warning)."""


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


def _rule(name):
    """What a value of the parameter must be."""
    if name not in INTEGERS:
        return f"it must be a real number [{UNITS[name]}]"
    words = f" or one of {', '.join(WORDS[name])}" if name in WORDS else ""
    return f"it must be a whole number that fits a C int{words}"


def _element(name, x):
    """One value as the library takes it (a word as its code), or None when
    it breaks _rule(name): no truncation, no booleans, no text for numbers."""
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, str):
        return WORDS.get(name, {}).get(x)
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        return None
    try:
        number = float(x)
    except OverflowError:  # an integer beyond a double's range
        return None
    if name not in INTEGERS:
        return number
    return int(x) if math.isfinite(number) and x == math.floor(x) and C_INT.min <= x <= C_INT.max else None


def _converted(name, a):
    """The array a as the library's numbers for the parameter (float64, or C
    ints), and where they obey _rule(name)."""
    if a.dtype.kind in "iuf":  # numbers: checked as arrays
        x = a.astype(float)
        if name not in INTEGERS:
            return x, np.ones(a.shape, dtype=bool)
        ok = np.isfinite(x) & (x == np.floor(x)) & (x >= C_INT.min) & (x <= C_INT.max)
        return np.where(ok, x, 0).astype(np.intc), ok
    # words, booleans, objects: one by one
    values = [_element(name, x) for x in a.ravel()]
    ok = np.array([v is not None for v in values], dtype=bool).reshape(a.shape)
    x = np.array([0 if v is None else v for v in values], dtype=np.intc if name in INTEGERS else float)
    return x.reshape(a.shape), ok


def _require(name, a, ok, rule, shape):
    """ValueError for the first element of a where ok is False: the
    parameter, its value and the rule, and the case (its index in the batch's
    shape) when a is an array."""
    if ok.all():
        return
    index = tuple(int(i) for i in np.argwhere(~ok)[0])
    value = a[index]
    value = value.item() if isinstance(value, np.generic) else value
    raise ValueError(f"{_case(index, shape) if a.ndim else ''}{name} = {value!r} is invalid: {rule}")


def _case(index, shape):
    """'case (i, j): ' for an element of an array broadcast to shape ('' when
    the batch is one run)."""
    if not shape:
        return ""
    index = (0,) * (len(shape) - len(index)) + tuple(index)
    return f"case {tuple(int(i) for i in index)}: "


def _array(name, value):
    """value as an array, each element as given (numbers mixed with words
    stay numbers, not text)."""
    try:
        a = np.asarray(value)
        return np.asarray(value, dtype=object) if a.dtype.kind in "US" else a
    except ValueError:
        raise ValueError(f"{name} = {value!r} is invalid: not an array of one shape") from None


def _known(params):
    inputs = sorted(set(params) & set(CO_SIMULATION_ONLY))
    if inputs:
        raise TypeError(f"{', '.join(inputs)}: no parameter of a run; {NO_MASTER}")
    unknown = sorted(set(params) - set(NAMES) - {"height"})
    if unknown:
        raise TypeError(f"unknown parameter {', '.join(unknown)}; the parameters are {', '.join(NAMES)} and height")


def _shape(arrays):
    """The shape the arrays broadcast to."""
    try:
        return np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in arrays.items() if a.ndim)
        raise ValueError(f"the arrays do not broadcast together: {shapes}") from None


def _columns(arrays, shape):
    """{name: the library's numbers} of the given arrays, height turned into
    v; a bad value refused with its case."""
    columns = {}
    for name, a in arrays.items():
        x, ok = _converted(name, a)
        _require(name, a, ok, _rule(name), shape)
        columns[name] = x
    if "height" in columns:
        if "v" in columns:
            raise ValueError("give height or v, not both")
        h = columns.pop("height")
        _require("height", arrays["height"], np.isfinite(h) & (h >= 0),
                 "a drop height must be finite and >= 0 [m]", shape)
        columns["v"] = np.vectorize(drop_velocity, otypes=[float])(h)
    return columns


def _checked(p):
    why = _lib.message_buffer()
    if _lib.LIB.fc_params_check(ctypes.byref(p), why, len(why)) != _lib.FC_OK:
        raise ValueError(why.value.decode())
    return p


def _params(**given):
    """fc_params of one run; every value one number (or word)."""
    _known(given)
    arrays = {name: _array(name, value) for name, value in given.items()}
    for name, a in arrays.items():
        if a.ndim:
            raise ValueError(f"{name} = {given[name]!r} is invalid: one run takes one value per parameter "
                             "(impacts() takes arrays)")
    p = _default_params()
    for name, x in _columns(arrays, ()).items():
        setattr(p, name, x.item())
    return _checked(p)


def _unused(p, why):
    """The library's message for a value without effect in the fc_params p
    (a byref or an address), or None; why holds it."""
    return why.value.decode() if _lib.LIB.fc_params_warning(p, why, len(why)) else None


def _warn_unused(p):
    """Warns (at the caller's caller) when a value of p has no effect."""
    message = _unused(ctypes.byref(p), _lib.message_buffer())
    if message:
        warnings.warn(message, ParameterWarning, stacklevel=3)


def warning(**params):
    """The library's warning for these parameters (a value without effect), or None."""
    return _unused(ctypes.byref(_params(**params)), _lib.message_buffer())


def memory_kernel(**params):
    """The compressed memory's kernel for these parameters (damper_order,
    memory_tolerance, dt_max, and whether error-controlled steps apply, which
    fit it from min(dt_max, 1e-9 s); docs/model.md §6): (a, b, eta) with
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


class _Record(collections.abc.Mapping):
    """A result's fields read by key too (r["F_peak"] is r.F_peak), as
    scipy's OptimizeResult."""

    def __getitem__(self, name):
        if name not in self.__dataclass_fields__:
            raise KeyError(name)
        return getattr(self, name)

    def __iter__(self):
        return iter(self.__dataclass_fields__)

    def __len__(self):
        return len(self.__dataclass_fields__)


@dataclass
class Impact(_Record):
    """One finished impact."""
    t_onset: float    # contact onset [s]
    v_onset: float    # striker velocity at onset [m/s]
    F_peak: float     # its largest force [N]
    eps: float        # restitution coefficient
    t_contact: float  # contact duration [s]
    x2_end: float     # permanent indentation when it ended (all impacts so far) [m]
    E_diss: float     # energy dissipated during it [J]


@dataclass
class End(_Record):
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
class Run(_Record):
    """A run, as fraccontact-solve --json gives it (numbers from impact(),
    arrays of the batch's shape from impacts())."""
    t_onset: float    # the first impact's figures, as Impact's (NaN when none ended)
    v_onset: float
    F_peak: float
    eps: float
    t_contact: float
    x2_end: float
    E_diss: float
    per_impact: list  # every finished impact, Impact's (None from impacts())
    end: End          # the FMU's outputs where the run stopped
    stopped: str      # why: impacts, t_end or receding
    impacts: int      # finished impacts
    steps: int        # internal steps
    k: float          # the spring constant used (given, or derived) [N/m^n]
    method: str       # the method that ran: gradient, esdirk54, radau_iia, g1_history or central


@dataclass
class Series(_Record):
    """A run's time series (arrays, SI units) and the run."""
    t: np.ndarray       # time [s]
    F: np.ndarray       # contact force [N]
    x: np.ndarray       # total indentation [m]
    x1: np.ndarray      # elastic indentation [m]
    x2: np.ndarray      # permanent indentation [m]
    v: np.ndarray       # striker velocity [m/s]
    E_diss: np.ndarray  # energy dissipated so far [J]
    run: Run            # what impact() gives for the same parameters


STOP_WORDS = np.array([_lib.STOPS.get(i, "") for i in range(max(_lib.STOPS) + 1)])


def _method(address):
    """The method the fc_params at address runs, as the library names it."""
    return _lib.LIB.fc_method_name(address).decode()


def _run(o, per_impact, method, shape=None):
    """The Run of an array of fc_outcome: arrays of shape, or numbers (shape
    None, one outcome)."""
    form = (lambda a: a.item()) if shape is None else (lambda a: a.reshape(shape))
    ended = o["impacts"] > 0
    first = [form(np.where(ended, o["first"][name], np.nan)) for name in IMPACT_FIGURES]
    return Run(*first, per_impact=per_impact, end=End(*(form(o[name]) for name in END_FIGURES)),
               stopped=form(STOP_WORDS[o["stop"]]), impacts=form(o["impacts"]), steps=form(o["steps"]), k=form(o["k"]),
               method=method)


class _Watch:
    """A library call's progress callbacks, as a context around the call.
    In the main thread, Ctrl-C asks the library to stop: Python runs its
    SIGINT handler inside the next callback, which then returns nonzero, and
    KeyboardInterrupt is raised once the library has returned. On a terminal
    a line on stderr tells how far a call longer than SHOW_AFTER has come."""

    def __enter__(self):
        self.main = threading.current_thread() is threading.main_thread()
        self.stop = False
        self.drawn = False
        self.due = time.monotonic() + SHOW_AFTER
        self.handler = signal.getsignal(signal.SIGINT) if self.main else None
        if self.handler is signal.default_int_handler:  # a handler the user set stays
            signal.signal(signal.SIGINT, self._interrupted)
        return self

    def _interrupted(self, signum, frame):
        self.stop = True

    def __exit__(self, kind, error, trace):
        if self.handler is signal.default_int_handler:
            signal.signal(signal.SIGINT, self.handler)
        if self.drawn:
            print(file=sys.stderr, flush=True)
        if self.stop and kind is None:
            raise KeyboardInterrupt

    def poll(self, text):
        """What a callback returns: nonzero to stop. text() says how far the
        call has come."""
        try:
            if self.main and time.monotonic() >= self.due and sys.stderr.isatty():
                print(f"\rfraccontact: {text()} (Ctrl-C stops)", end="", file=sys.stderr, flush=True)
                self.drawn, self.due = True, time.monotonic() + REDRAW
        except KeyboardInterrupt:  # raised by a SIGINT handler of the user's
            self.stop = True
        return int(self.stop)

    def run(self):
        return _lib.PROGRESS(lambda ctx, t, steps, impacts: self.poll(
            lambda: f"t = {t:.6g} s, {steps} internal steps, {impacts} impacts"))

    def batch(self):
        return _lib.BATCH_PROGRESS(lambda ctx, done, n: self.poll(lambda: f"{done} of {n} runs"))


def _call_run(p, interval):
    r = _lib.Result()
    why = _lib.message_buffer()
    try:
        with _Watch() as watch:
            progress = watch.run()
            status = _lib.LIB.fc_run_with_progress(ctypes.byref(p), interval, progress, None, ctypes.byref(r), why,
                                                   len(why))
        if status != _lib.FC_OK:
            raise (ValueError if status == _lib.FC_EINVAL else RuntimeError)(why.value.decode())
        per_impact = [Impact(*(getattr(r.per_impact[i], name) for name in IMPACT_FIGURES))
                      for i in range(r.n_impacts)]
        rows = np.ctypeslib.as_array(r.rows, shape=(r.n_rows, len(_lib.COLUMNS))).copy() if r.n_rows else \
            np.zeros((0, len(_lib.COLUMNS)))
        return _run(np.frombuffer(bytes(r.outcome), dtype=np.dtype(_lib.Outcome)), per_impact,
                    _method(ctypes.addressof(p))), rows
    finally:
        _lib.LIB.fc_result_free(ctypes.byref(r))


def impact(**params):
    """One drop test or driven run: a Run, its first impact's figures and
    every impact in .per_impact."""
    p = _params(**params)
    _warn_unused(p)
    return _call_run(p, _lib.NO_ROWS)[0]


def simulate(output_interval=None, **params):
    """The time series of a run: a row every output_interval seconds (None:
    about 250 rows per contact; 0: every internal step) and at every onset
    and separation. A Series: arrays t, F, x, x1, x2, v, E_diss (SI units)
    and the Run under .run."""
    p = _params(**params)
    if output_interval is None:
        interval = _lib.DEFAULT_ROWS
    elif isinstance(output_interval, numbers.Real) and not isinstance(output_interval, bool) \
            and math.isfinite(output_interval) and output_interval >= 0:
        interval = float(output_interval)
    else:
        raise ValueError(f"output_interval = {output_interval!r} is invalid: it must be a finite number >= 0 [s]")
    _warn_unused(p)
    run, rows = _call_run(p, interval)
    return Series(*(rows[:, i] for i in range(len(_lib.COLUMNS))), run=run)


def impacts(**params):
    """Many runs in one library call: any parameter may be an array, and
    they broadcast together. A Run whose figures are arrays of the broadcast
    shape (per_impact None)."""
    _known(params)
    arrays = {name: _array(name, value) for name, value in params.items()}
    shape = _shape(arrays)
    batch = np.empty(math.prod(shape), dtype=np.dtype(_lib.Params))
    batch[:] = np.frombuffer(bytes(_default_params()), dtype=np.dtype(_lib.Params))[0]
    for name, x in _columns(arrays, shape).items():
        batch[name] = np.broadcast_to(x, shape).ravel()
    _warn_unused_in(batch, shape)
    out = np.zeros(len(batch), dtype=np.dtype(_lib.Outcome))
    with _Watch() as watch:
        progress = watch.batch()
        status = _lib.LIB.fc_run_batch_with_progress(len(batch), batch.ctypes.data, out.ctypes.data, progress, None)
    if status != _lib.FC_OK:
        _raise_for_case(batch, out, shape)
    methods = np.array([_method(batch.ctypes.data + i * batch.itemsize) for i in range(len(batch))], dtype=str)
    return _run(out, None, methods.reshape(shape), shape)


def _index(i, shape):
    """The index in shape of the i-th case."""
    return np.unravel_index(i, shape) if shape else ()


def _case_params(batch, i):
    return ctypes.cast(batch.ctypes.data + i * batch.itemsize, ctypes.POINTER(_lib.Params))


def _warn_unused_in(batch, shape):
    """One warning for the cases with a value without effect: the first one's
    message, and how many."""
    why, start = _lib.message_buffer(), batch.ctypes.data
    found = [(i, message) for i in range(len(batch)) if (message := _unused(start + i * batch.itemsize, why))]
    if found:
        i, message = found[0]
        more = f" ({len(found)} of {len(batch)} cases have a value without effect)" if len(found) > 1 else ""
        warnings.warn(f"{_case(_index(i, shape), shape)}{message}{more}", ParameterWarning, stacklevel=3)


def _raise_for_case(batch, out, shape):
    """The first failed case's message, with its index in the broadcast shape."""
    i = int(np.flatnonzero(out["status"] != _lib.FC_OK)[0])
    case = _case(_index(i, shape), shape)
    why = _lib.message_buffer()
    if _lib.LIB.fc_run_check(_case_params(batch, i), _lib.NO_ROWS, why, len(why)) != _lib.FC_OK:
        raise ValueError(f"{case}{why.value.decode()}")
    raise RuntimeError(f"{case}the run failed (status {out['status'][i]})")
