"""ctypes declarations of libsph.so's public C API (include/sph/sph.h and
include/sph/status.h), and how the library is found.

The structures mirror the C ones field for field, in order; the test
tests/python/test_layout.py compares their sizes and offsets with the C
compiler's. The library is looked for, in order: the path in the environment
variable SPH_LIBRARY; the libsph.so installed beside this package (cmake
--install writes its relative path into _install.py); the system loader
(libsph.so.MAJOR on the library path).
"""

import ctypes
import ctypes.util
import os

# the library's major version: the SONAME is libsph.so.<major>
MAJOR = 0


class Error_t(ctypes.Structure):
    """sph_error (status.h)."""

    _fields_ = [
        ("code", ctypes.c_int),
        ("file", ctypes.c_char * 256),
        ("line", ctypes.c_int),
        ("col", ctypes.c_int),
        ("key", ctypes.c_char * 128),
        ("message", ctypes.c_char * 768),
    ]


class RunOptions_t(ctypes.Structure):
    """sph_run_options (sph.h)."""

    _fields_ = [
        ("out_dir", ctypes.c_char_p),
        ("overwrite", ctypes.c_int),
        ("resume", ctypes.c_int),
        ("threads", ctypes.c_int),
        ("quiet", ctypes.c_int),
        ("stop", ctypes.POINTER(ctypes.c_int)),
        ("no_files", ctypes.c_int),
    ]


class Summary_t(ctypes.Structure):
    """sph_summary (sph.h)."""

    _fields_ = [
        ("state", ctypes.c_int),
        ("t", ctypes.c_double),
        ("steps", ctypes.c_ulong),
        ("wall", ctypes.c_double),
        ("particle_steps", ctypes.c_double),
        ("verdict", ctypes.c_char * 512),
        ("method", ctypes.c_char * 64),
        ("reference", ctypes.c_char * 256),
        ("out_dir", ctypes.c_char * 1024),
    ]


# sph_run_state, in the enum's order
STATES = ("going", "completed", "unstable", "stopped", "failed")

_status = ctypes.c_int
_p = ctypes.c_void_p
_err = ctypes.POINTER(Error_t)

# name: (result type, argument types)
_PROTOTYPES = {
    "sph_version": (ctypes.c_char_p, []),
    "sph_status_message": (ctypes.c_char_p, [ctypes.c_int]),
    "sph_status_name": (ctypes.c_char_p, [ctypes.c_int]),
    "sph_error_clear": (None, [_err]),
    "sph_error_format": (None, [_err, ctypes.c_char_p, ctypes.c_size_t]),
    "sph_scene_load": (
        _status,
        [
            ctypes.POINTER(_p),
            ctypes.c_char_p,
            ctypes.POINTER(ctypes.c_char_p),
            ctypes.c_size_t,
            _err,
        ],
    ),
    "sph_scene_destroy": (None, [_p]),
    "sph_scene_name": (ctypes.c_char_p, [_p]),
    "sph_scene_end_time": (ctypes.c_double, [_p]),
    "sph_run_create": (
        _status,
        [ctypes.POINTER(_p), _p, ctypes.POINTER(RunOptions_t), _err],
    ),
    "sph_run_advance": (_status, [_p, ctypes.c_double, _err]),
    "sph_run_state_of": (ctypes.c_int, [_p]),
    "sph_run_time": (ctypes.c_double, [_p]),
    "sph_run_steps": (ctypes.c_ulong, [_p]),
    "sph_run_particles": (ctypes.c_size_t, [_p]),
    "sph_run_field": (
        _status,
        [
            _p,
            ctypes.c_char_p,
            ctypes.POINTER(ctypes.POINTER(ctypes.c_double)),
            ctypes.POINTER(ctypes.c_int),
            _err,
        ],
    ),
    "sph_run_energy": (
        _status,
        [_p, ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double), _err],
    ),
    "sph_run_close": (_status, [_p, ctypes.POINTER(Summary_t), _err]),
    "sph_run_destroy": (None, [_p]),
}

_lib = None


def scenes_dirs():
    """Where shipped scenes are looked for by name: $SPH_SCENES_DIR, the
    scenes installed with the package, the source tree's scenes/."""
    here = os.path.dirname(os.path.abspath(__file__))
    dirs = []
    if os.environ.get("SPH_SCENES_DIR"):
        dirs.append(os.environ["SPH_SCENES_DIR"])
    try:
        from . import _install

        dirs.append(os.path.normpath(os.path.join(here, _install.SCENES)))
    except ImportError:
        pass
    dirs.append(os.path.normpath(os.path.join(here, "..", "..", "scenes")))
    return dirs


def scene_path(scene):
    """A scene argument as a path: an existing file or anything with a
    slash as it is, else a shipped scene's name ("punch", "punch.yaml")
    found in scenes_dirs(); unknown names are returned as they are (the
    loader then reports the missing file)."""
    scene = os.fspath(scene)
    if os.path.exists(scene) or "/" in scene:
        return scene
    name = scene if scene.endswith(".yaml") else scene + ".yaml"
    for d in scenes_dirs():
        path = os.path.join(d, name)
        if os.path.isfile(path):
            return path
    return scene


def _candidates():
    env = os.environ.get("SPH_LIBRARY")
    if env:
        # an explicit choice: no fall-back to another library
        return [env], True
    found = []
    try:
        from . import _install

        here = os.path.dirname(os.path.abspath(__file__))
        found.append(os.path.normpath(os.path.join(here, _install.LIBRARY)))
    except ImportError:
        pass
    found.append("libsph.so.%d" % MAJOR)
    name = ctypes.util.find_library("sph")
    if name:
        found.append(name)
    return found, False


def library():
    """The loaded libsph.so (a ctypes.CDLL with its prototypes declared)."""
    global _lib
    if _lib is not None:
        return _lib
    paths, explicit = _candidates()
    tried = []
    for path in paths:
        if "/" in path and not os.path.exists(path):
            tried.append("%s (no such file)" % path)
            continue
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
            continue
        missing = [n for n in _PROTOTYPES if not hasattr(lib, n)]
        if missing:
            tried.append("%s (lacks %s: an older or another library)" % (path, ", ".join(missing)))
            continue
        for name, (res, args) in _PROTOTYPES.items():
            fn = getattr(lib, name)
            fn.restype = res
            fn.argtypes = args
        _lib = lib
        return lib
    hint = "" if explicit else "; set SPH_LIBRARY to the path of libsph.so"
    raise OSError("sph: libsph.so not found: %s%s" % ("; ".join(tried), hint))
