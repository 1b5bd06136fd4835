"""ctypes binding of libfraccontact (solver/fraccontact.h).

The parameter struct is built from the library's own parameter table (names,
kinds, offsets), so its layout has one home, in C; the result structs mirror
the header and are checked against the sizes the library reports."""

import ctypes
import os
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
SUFFIX = {"win32": ".dll", "darwin": ".dylib"}.get(sys.platform, ".so")
PREFIX = "" if sys.platform == "win32" else "lib"

FC_OK, FC_EINVAL, FC_EFAIL, FC_ENOMEM, FC_ESTOPPED = 0, 1, 2, 3, 4
STOPS = {1: "impacts", 2: "t_end", 3: "receding", 4: "resting"}
NO_ROWS, EVERY_STEP, DEFAULT_ROWS = -1.0, 0.0, -2.0
COLUMNS = ("t", "F", "x", "x1", "x2", "v", "E_diss")
MESSAGE_SIZE = 512


def library_path():
    """$FRACCONTACT_LIBRARY (a build folder's library, for the tests), else
    the one installed in the package."""
    return pathlib.Path(os.environ.get("FRACCONTACT_LIBRARY") or HERE / f"{PREFIX}fraccontact{SUFFIX}")


class Parameter(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("kind", ctypes.c_int), ("offset", ctypes.c_size_t),
                ("unit", ctypes.c_char_p), ("help", ctypes.c_char_p), ("words", ctypes.c_char_p)]


class Impact(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double)
                for name in ("t_onset", "v_onset", "F_peak", "eps", "t_contact", "x2_end", "E_diss")]


class Outcome(ctypes.Structure):
    _fields_ = [("status", ctypes.c_int), ("stop", ctypes.c_int), ("impacts", ctypes.c_int64),
                ("steps", ctypes.c_int64), ("first", Impact)] + [
        (name, ctypes.c_double) for name in ("F_peak", "eps", "t_contact", "E_diss", "t", "x", "x1", "x2", "v", "k")]


def _load():
    path = library_path()
    try:
        lib = ctypes.CDLL(str(path))
    except OSError as e:
        raise ImportError(f"fraccontact: cannot load its C library {path} ({e}); install the package with "
                          "'pip install .' or point FRACCONTACT_LIBRARY at a build's libfraccontact") from e
    lib.fc_parameter_count.restype = ctypes.c_size_t
    lib.fc_parameter_at.restype = ctypes.POINTER(Parameter)
    lib.fc_parameter_at.argtypes = [ctypes.c_size_t]
    lib.fc_params_size.restype = ctypes.c_size_t
    lib.fc_outcome_size.restype = ctypes.c_size_t
    lib.fc_drop_velocity.restype = ctypes.c_double
    lib.fc_drop_velocity.argtypes = [ctypes.c_double]
    lib.fc_default_output_interval.restype = ctypes.c_double
    lib.fc_step_limit.restype = ctypes.c_double
    return lib


LIB = _load()


def _parameter_table():
    table = []
    for i in range(LIB.fc_parameter_count()):
        p = LIB.fc_parameter_at(i).contents
        table.append(dict(name=p.name.decode(), kind="real" if p.kind == 0 else "integer", offset=p.offset,
                          unit=p.unit.decode(), help=p.help.decode(), words=p.words.decode().split()))
    return table


PARAMETERS = _parameter_table()


def _params_struct():
    """fc_params from the library's table, its members in offset order."""
    fields = [(p["name"], ctypes.c_double if p["kind"] == "real" else ctypes.c_int)
              for p in sorted(PARAMETERS, key=lambda p: p["offset"])]
    struct = type("Params", (ctypes.Structure,), {"_fields_": fields})
    for p in PARAMETERS:
        if getattr(struct, p["name"]).offset != p["offset"]:
            raise ImportError(f"fraccontact: the layout of fc_params ({p['name']}) differs from the library's")
    return struct


Params = _params_struct()


class Result(ctypes.Structure):
    _fields_ = [("outcome", Outcome), ("per_impact", ctypes.POINTER(Impact)), ("n_impacts", ctypes.c_size_t),
                ("rows", ctypes.POINTER(ctypes.c_double)), ("n_rows", ctypes.c_size_t)]


for _struct, _size in ((Params, LIB.fc_params_size()), (Outcome, LIB.fc_outcome_size())):
    if ctypes.sizeof(_struct) != _size:
        raise ImportError(f"fraccontact: {_struct.__name__} has {ctypes.sizeof(_struct)} bytes, the library's "
                          f"{_size}: the library and the package are of different versions")

LIB.fc_params_default.argtypes = [ctypes.POINTER(Params)]
LIB.fc_params_check.argtypes = [ctypes.POINTER(Params), ctypes.c_char_p, ctypes.c_size_t]
# by address: a batch's cases are looked at in place
LIB.fc_params_warning.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t]
LIB.fc_run_check.argtypes = [ctypes.POINTER(Params), ctypes.c_double, ctypes.c_char_p, ctypes.c_size_t]
LIB.fc_default_output_interval.argtypes = [ctypes.POINTER(Params)]
LIB.fc_run.argtypes = [ctypes.POINTER(Params), ctypes.c_double, ctypes.POINTER(Result), ctypes.c_char_p,
                       ctypes.c_size_t]
# Called now and then during a run (fc_progress) or a batch (fc_batch_progress); nonzero stops it.
PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double, ctypes.c_int64, ctypes.c_int64)
BATCH_PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)
LIB.fc_run_with_progress.argtypes = [ctypes.POINTER(Params), ctypes.c_double, PROGRESS, ctypes.c_void_p,
                                     ctypes.POINTER(Result), ctypes.c_char_p, ctypes.c_size_t]
LIB.fc_run_batch_with_progress.argtypes = [ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p, BATCH_PROGRESS,
                                           ctypes.c_void_p]
LIB.fc_result_free.argtypes = [ctypes.POINTER(Result)]
LIB.fc_run_batch.argtypes = [ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
LIB.fc_method_name.restype = ctypes.c_char_p
LIB.fc_method_name.argtypes = [ctypes.c_void_p]  # by address, as fc_params_warning
LIB.fc_memory_kernel.restype = ctypes.c_size_t
LIB.fc_memory_kernel.argtypes = [ctypes.POINTER(Params), ctypes.c_size_t, ctypes.POINTER(ctypes.c_double),
                                 ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double), ctypes.c_char_p,
                                 ctypes.c_size_t]


def message_buffer():
    return ctypes.create_string_buffer(MESSAGE_SIZE)
