"""OMSimulator, OpenModelica's SSP and FMI master, as a master of this
project's SSPs (build/drop_test.ssp, build/headform.ssp, build/bumper.ssp):
its C API (libOMSimulator.so, through ctypes, as its own Python package
calls it) imports the SSP as it is, SSV bindings and all, and steps it with
its fixed-step master (oms-ma: every FMU from the last communication point,
Jacobi), which the SSD's OpenModelica annotation names. Built from source
where it is wanted (docs/ssp.md); where it is absent, available() is False.

    trace = simulate("build/headform.ssp", 1e-5, grid(1e-5, 0.035), start, ("head.v", "skin.F"))

The library: $FRACCONTACT_OMSIMULATOR, else the one installed beside the
OMSimulator executable on PATH (<prefix>/bin/OMSimulator, <prefix>/lib/).
"""

import contextlib
import ctypes
import functools
import os
import pathlib
import shutil
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile

import numpy as np

VARIABLE = "FRACCONTACT_OMSIMULATOR"
LIBRARY = "libOMSimulator.so"
SSD = "{http://ssp-standard.org/SSP1/SystemStructureDescription}"
OK, WARNING = 0, 1  # oms_status_enu_t
ERROR_MESSAGE = 2   # oms_message_type_enu_t: oms_message_error
# OMSimulator's messages since the last call (its callback's), for the error a failed call raises.
_messages = []


def library_path():
    """The library to load, or None where OMSimulator is not installed."""
    named = os.environ.get(VARIABLE)
    if named:
        path = pathlib.Path(named)
        if not path.is_file():
            raise ValueError(f"{VARIABLE} = {named} is invalid: it must name OMSimulator's library, {LIBRARY}")
        return path
    executable = shutil.which("OMSimulator")
    if executable is None:
        return None
    prefix = pathlib.Path(executable).resolve().parent.parent
    found = [p for p in (prefix / "lib" / LIBRARY, prefix / "lib" / "x86_64-linux-gnu" / LIBRARY) if p.is_file()]
    return found[0] if found else None


def available():
    return library_path() is not None


@ctypes.CFUNCTYPE(None, ctypes.c_int, ctypes.c_char_p)
def _collect(kind, message):
    if kind == ERROR_MESSAGE:
        _messages.append(message.decode(errors="replace"))


@contextlib.contextmanager
def quiet():
    """OMSimulator's log muted: it writes every message to stdout or stderr
    (a command's output, its JSON, is stdout), and its count of warnings and
    errors at exit, which are reset here; its errors reach the exceptions
    call() raises."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        load().oms_setLogFile(b"")  # resets the counts
        ctypes.CDLL(None).fflush(None)  # what C++ streams left in C's buffers goes to /dev/null
        for fd, copy in zip((1, 2), saved):
            os.dup2(copy, fd)
            os.close(copy)
        os.close(null)


@functools.lru_cache(maxsize=None)
def load():
    """The library, its functions typed and its errors collected."""
    path = library_path()
    if path is None:
        raise RuntimeError(f"OMSimulator is not installed: put OMSimulator on PATH or set {VARIABLE} to its "
                           f"{LIBRARY} (docs/ssp.md)")
    lib = ctypes.CDLL(str(path))
    text, real, integer = ctypes.c_char_p, ctypes.c_double, ctypes.c_int
    for name, args in (("oms_setLogFile", [text]), ("oms_setTempDirectory", [text]),
                       ("oms_importFile", [text, ctypes.POINTER(text)]), ("oms_setResultFile", [text, text, integer]),
                       ("oms_setFixedStepSize", [text, real]), ("oms_setStartTime", [text, real]),
                       ("oms_setStopTime", [text, real]), ("oms_setReal", [text, real]),
                       ("oms_setInteger", [text, integer]), ("oms_instantiate", [text]),
                       ("oms_initialize", [text]), ("oms_stepUntil", [text, real]),
                       ("oms_getReal", [text, ctypes.POINTER(real)]), ("oms_getTime", [text, ctypes.POINTER(real)]),
                       ("oms_terminate", [text]), ("oms_delete", [text])):
        getattr(lib, name).argtypes = args
        getattr(lib, name).restype = integer
    lib.oms_getVersion.argtypes, lib.oms_getVersion.restype = [], text
    lib.oms_setLoggingCallback.argtypes, lib.oms_setLoggingCallback.restype = [type(_collect)], None
    lib.oms_setLoggingCallback(_collect)
    return lib


def version():
    """The build that runs, as OMSimulator names itself (its git description)."""
    lib = load()
    with quiet():
        return lib.oms_getVersion().decode()


def call(lib, name, *args):
    """lib.name(*args), a failure raised with OMSimulator's message."""
    _messages.clear()
    status = getattr(lib, name)(*args)
    if status not in (OK, WARNING):
        shown = [a.decode() if isinstance(a, bytes) else a for a in args if isinstance(a, (bytes, int, float))]
        said = _messages[-1] if _messages else f"status {status}"
        raise RuntimeError(f"OMSimulator: {name}{tuple(shown)} failed: {said}")


def system_name(ssp):
    with zipfile.ZipFile(ssp) as z:
        return ET.fromstring(z.read("SystemStructure.ssd")).find(f"{SSD}System").get("name")


def simulate(ssp, H, t, start, recorded):
    """A trace of the SSP in OMSimulator's fixed-step master at step H: t
    (its communication points n H from 0, ssp.grid) and each
    recorded variable ("component.variable") at them; start ({component:
    {variable: value}}) overrides the SSV bindings."""
    lib = load()
    trace = {name: np.empty(len(t)) for name in recorded}
    value = ctypes.c_double()
    with quiet(), tempfile.TemporaryDirectory(prefix="fraccontact-omsimulator-") as folder:
        call(lib, "oms_setTempDirectory", folder.encode())  # where it unpacks the SSP
        cref = ctypes.c_char_p()
        call(lib, "oms_importFile", str(ssp).encode(), ctypes.byref(cref))
        model = cref.value
        try:
            system = model + b"." + system_name(ssp).encode()
            call(lib, "oms_setResultFile", model, b"", 0)  # none: the trace is read here
            call(lib, "oms_setFixedStepSize", system, H)
            call(lib, "oms_setStartTime", model, 0.0)
            call(lib, "oms_setStopTime", model, t[-1])
            for component, values in start.items():
                for name, v in values.items():
                    setter = "oms_setInteger" if isinstance(v, int) else "oms_setReal"
                    call(lib, setter, system + f".{component}.{name}".encode(), v)
            call(lib, "oms_instantiate", model)
            call(lib, "oms_initialize", model)
            crefs = [(trace[name], system + b"." + name.encode()) for name in recorded]
            for i in range(len(t)):
                if i:
                    # It steps while its time, a sum of steps, is short of the target: half a
                    # step short of the point makes it one step, whatever the sum's rounding.
                    call(lib, "oms_stepUntil", model, t[i] - 0.5 * H)
                    call(lib, "oms_getTime", model, ctypes.byref(value))
                    if abs(value.value - t[i]) > 1e-6 * H:
                        raise RuntimeError(f"OMSimulator stepped to t = {value.value!r}, not to {t[i]!r}")
                for series, name in crefs:
                    call(lib, "oms_getReal", name, ctypes.byref(value))
                    series[i] = value.value
            call(lib, "oms_terminate", model)
        finally:
            lib.oms_delete(model)
    return dict(trace, t=t)
