"""sph: the SPH solid-dynamics solver from Python.

Pure Python over libsph.so through ctypes (no compiled extension); the
particle fields come back as numpy arrays. A run is the same loop as
`sph run`: every output the scene asks for (VTK, CSV, probes, PNG frames,
checkpoints, summary.json) is written unless no_files=True.

    import sph
    with sph.load("twisting_column", set={"time.end": 0.01}, no_files=True) as run:
        while run.time < run.end_time:
            run.advance(run.time + 0.001)
            f = run.fields()
            print(run.time, f["von_mises"].max(), run.energy().kinetic)
    print(run.summary.verdict)

The library is found through the environment variable SPH_LIBRARY (a path
to libsph.so), then beside the installed package, then by the system
loader. docs/python.md describes the API.
"""

import ctypes
import json
import weakref
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from . import _capi

__all__ = ["load", "Run", "Summary", "Energy", "Error", "version", "FIELDS"]

# the fields of docs/outputs.md: name -> components (1: an array of shape (n,))
# the stop flag's value for a stop no signal asked for (SPH_STOP_REQUEST)
STOP_REQUEST = 256

FIELDS = {
    "position": 3,
    "velocity": 3,
    "displacement": 3,
    "pressure": 1,
    "von_mises": 1,
    "J": 1,
    "body": 1,
    "id": 1,
}

Energy = namedtuple("Energy", ["kinetic", "strain"])
Energy.__doc__ = "Kinetic and strain energy of a state (J; J/m in 2D)."


def _str(b):
    return b.decode("utf-8", "replace")


class Error(Exception):
    """A failed library call: the sph_error record.

    Attributes: status (the code's name, "SPH_ERR_UNKNOWN_KEY"), code (its
    number), message, and where the input was at fault when there is one:
    file, line, col (1-based; 0 unknown) and key ("bodies[0].shape.box").
    str() gives "file:line:col: key: message" as the sph command prints it.
    """

    def __init__(self, code, status, message, file="", line=0, col=0, key="", text=None):
        self.code = code
        self.status = status
        self.message = message
        self.file = file
        self.line = line
        self.col = col
        self.key = key
        super().__init__(text if text is not None else message)

    @classmethod
    def _from(cls, lib, st, err):
        buf = ctypes.create_string_buffer(2048)
        lib.sph_error_format(ctypes.byref(err), buf, len(buf))
        text = _str(buf.value)
        message = _str(err.message) or _str(lib.sph_status_message(st))
        return cls(
            st,
            _str(lib.sph_status_name(st)),
            message,
            _str(err.file),
            err.line,
            err.col,
            _str(err.key),
            text or message,
        )


def _check(lib, st, err):
    if st != 0:
        raise Error._from(lib, st, err)


def version():
    """The library's version, "MAJOR.MINOR.PATCH"."""
    return _str(_capi.library().sph_version())


@dataclass(frozen=True)
class Summary:
    """What sph_run_close reports (the numbers of summary.json).

    state: "completed", "unstable", "stopped" or "failed"; t: time reached
    (s); steps; wall: s, set-up excluded; particle_steps: per wall second;
    verdict: "stable" or "UNSTABLE - <indicator> ..."; method ("tl-jst");
    reference: the method's paper and equations; out_dir: the output folder
    ("" with no_files).
    """

    state: str
    t: float
    steps: int
    wall: float
    particle_steps: float
    verdict: str
    method: str
    reference: str
    out_dir: str

    @property
    def stable(self):
        return self.verdict == "stable"


def _set_value(value):
    # overrides are YAML values: JSON is YAML's flow style
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, np.generic):
        return repr(value.item())
    return json.dumps(value.tolist() if isinstance(value, np.ndarray) else value)


def _sets(set):
    if set is None:
        return []
    if isinstance(set, dict):
        return ["%s=%s" % (k, _set_value(v)) for k, v in set.items()]
    if isinstance(set, str):
        return [set]
    return list(set)


def _release(lib, run, scene):
    # the finalizer of a Run that was not closed (or whose close failed)
    if run:
        lib.sph_run_destroy(run)
    if scene:
        lib.sph_scene_destroy(scene)


class Run:
    """One scene's run (made by sph.load).

    Advance it with advance(t); read the current state with fields(),
    field(name) and energy(); close() finishes the outputs, judges the
    errors against the reference and returns the Summary (also in
    .summary). A Run is a context manager: leaving the with block closes it
    (a run not advanced to its end is closed as stopped).
    """

    def __init__(self, lib, scene, run, opts, stop):
        self._lib = lib
        self._scene = scene
        self._run = run
        # what the options point to lives as long as the run
        self._opts = opts
        self._stop = stop  # the c_int the library polls (options.stop)
        self._summary = None
        self._name = _str(lib.sph_scene_name(scene))
        self._end = lib.sph_scene_end_time(scene)
        self._finalizer = weakref.finalize(self, _release, lib, run, scene)

    # --- the state -------------------------------------------------------
    def _handle(self):
        if self._run is None:
            raise Error(3, "SPH_ERR_ARG", "sph: the run is closed")
        return self._run

    @property
    def name(self):
        """The scene's name (its file's stem)."""
        return self._name

    @property
    def end_time(self):
        """The scene's end time (s), time.end after the overrides."""
        return self._end

    @property
    def time(self):
        """The simulated time reached (s)."""
        return self._lib.sph_run_time(self._handle())

    @property
    def steps(self):
        """Time steps taken so far."""
        return self._lib.sph_run_steps(self._handle())

    @property
    def state(self):
        """ "going", "completed", "unstable", "stopped" or "failed"."""
        return _capi.STATES[self._lib.sph_run_state_of(self._handle())]

    @property
    def particles(self):
        """The number of particles (over MPI ranks: this rank's own)."""
        return self._lib.sph_run_particles(self._handle())

    @property
    def summary(self):
        """The Summary once the run is closed; None before."""
        return self._summary

    @property
    def closed(self):
        return self._run is None

    # --- stepping --------------------------------------------------------
    def advance(self, t=None):
        """Advances to time t (s; None: the end time), clamped to the end
        time, through every output time on the way, writing the outputs.
        Returns the state: "going" or "completed", or "unstable" when an
        indicator of the verdict tripped and "stopped" after request_stop()
        (the run then stays where it stopped). Raises sph.Error when a step
        or an output fails. Invalidates the arrays of earlier fields()."""
        run = self._handle()
        err = _capi.Error_t()
        st = self._lib.sph_run_advance(run, self._end if t is None else float(t), ctypes.byref(err))
        _check(self._lib, st, err)
        return self.state

    def request_stop(self, signo=None):
        """Asks a running advance() (in another thread) to stop at the next
        step boundary with its outputs finished and a checkpoint written;
        the run's state becomes "stopped". summary.json's stopped_by says
        "request", or names the signal `signo` when one is given (a handler
        that forwards a signal)."""
        self._stop.value = int(signo) if signo else STOP_REQUEST

    # --- fields ----------------------------------------------------------
    def field(self, name, copy=False):
        """One particle field of the current state as a numpy float64 array:
        shape (n, 3) for position, velocity, displacement (m, m/s, m),
        (n,) for pressure (Pa, positive in compression), von_mises (Pa),
        J (det F), body (body index) and id.

        Without copy the array is a read-only view of the library's memory,
        valid until the next advance() or close() of the run (after which
        its contents are undefined and reading it may crash); pass
        copy=True, or call .copy(), to keep the values. Raises sph.Error
        (status SPH_ERR_UNSUPPORTED) for a field the method does not fill.
        """
        run = self._handle()
        err = _capi.Error_t()
        data = ctypes.POINTER(ctypes.c_double)()
        comps = ctypes.c_int(0)
        st = self._lib.sph_run_field(
            run, name.encode(), ctypes.byref(data), ctypes.byref(comps), ctypes.byref(err)
        )
        _check(self._lib, st, err)
        n = self._lib.sph_run_particles(run)
        c = comps.value
        shape = (n,) if c == 1 else (n, c)
        if n == 0 or not data:
            return np.zeros(shape)
        a = np.ctypeslib.as_array(data, shape=shape)
        if copy:
            return a.copy()
        a.flags.writeable = False
        return a

    def fields(self, copy=False):
        """Every field the method fills (FIELDS' names that are not
        unsupported) as a dict name -> array; see field() for shapes, units
        and how long the views stay valid."""
        out = {}
        for name in FIELDS:
            try:
                out[name] = self.field(name, copy=copy)
            except Error as e:
                if e.status != "SPH_ERR_UNSUPPORTED":
                    raise
        return out

    def energy(self):
        """Kinetic and strain energy of the current state (J; J/m in 2D),
        as Energy(kinetic, strain)."""
        run = self._handle()
        err = _capi.Error_t()
        k = ctypes.c_double()
        s = ctypes.c_double()
        st = self._lib.sph_run_energy(run, ctypes.byref(k), ctypes.byref(s), ctypes.byref(err))
        _check(self._lib, st, err)
        return Energy(k.value, s.value)

    # --- the end ---------------------------------------------------------
    def close(self):
        """Finishes the outputs, judges the errors against the scene's
        reference, writes summary.json (unless no_files) and returns the
        Summary. Frees the run and its scene: field arrays taken without
        copy are invalid after it. Closing again returns the same Summary."""
        if self._run is None:
            return self._summary
        lib = self._lib
        err = _capi.Error_t()
        s = _capi.Summary_t()
        st = lib.sph_run_close(self._run, ctypes.byref(s), ctypes.byref(err))
        self._finalizer()
        self._run = None
        self._scene = None
        _check(lib, st, err)
        self._summary = Summary(
            state=_capi.STATES[s.state],
            t=s.t,
            steps=s.steps,
            wall=s.wall,
            particle_steps=s.particle_steps,
            verdict=_str(s.verdict),
            method=_str(s.method),
            reference=_str(s.reference),
            out_dir=_str(s.out_dir),
        )
        return self._summary

    def __enter__(self):
        return self

    def __exit__(self, kind, value, tb):
        if kind is None:
            self.close()
        else:
            # an exception on the way: close still (outputs finished), but
            # let the first error be the one raised
            try:
                self.close()
            except Error:
                pass
        return False

    def __repr__(self):
        if self._run is None:
            return "<sph.Run %s closed: %s>" % (self._name, self._summary)
        return "<sph.Run %s t=%g s of %g, %s>" % (self._name, self.time, self._end, self.state)


def load(scene, set=None, out=None, threads=0, overwrite=False, quiet=True, no_files=False, resume=False):
    """Loads a scene and sets its run up (the output frame at t = 0 is
    written); returns a Run.

    scene: a YAML file's path or a shipped scene's name ("twisting_column",
    looked for in $SPH_SCENES_DIR, the installed scenes, the source tree's).
    set: overrides as `sph run --set` takes them, a dict {"time.end": 0.01,
    "method": {"name": "tl-bond"}} (values written as YAML/JSON) or a list
    of "key=value" strings, applied in order. out: the output folder (None:
    outputs/<scene name>); overwrite: replace an earlier run's files there;
    resume: continue from the checkpoint in out; threads: OpenMP threads (0:
    the library's default); quiet: no banner or progress line on stdout;
    no_files: write nothing, the run is only stepped and judged.

    Raises sph.Error naming the file, line, column and key of a bad scene
    or override.
    """
    lib = _capi.library()
    err = _capi.Error_t()
    sets = [s.encode() for s in _sets(set)]
    arr = (ctypes.c_char_p * max(len(sets), 1))(*sets)
    sc = ctypes.c_void_p()
    path = _capi.scene_path(scene)
    st = lib.sph_scene_load(ctypes.byref(sc), path.encode(), arr, len(sets), ctypes.byref(err))
    _check(lib, st, err)
    stop = ctypes.c_int(0)
    out_dir = None if out is None else ctypes.create_string_buffer(str(out).encode())
    opts = _capi.RunOptions_t(
        out_dir=None if out_dir is None else ctypes.cast(out_dir, ctypes.c_char_p),
        overwrite=int(bool(overwrite)),
        resume=int(bool(resume)),
        threads=int(threads),
        quiet=int(bool(quiet)),
        stop=ctypes.pointer(stop),
        no_files=int(bool(no_files)),
    )
    run = ctypes.c_void_p()
    st = lib.sph_run_create(ctypes.byref(run), sc, ctypes.byref(opts), ctypes.byref(err))
    if st != 0:
        lib.sph_scene_destroy(sc)
        raise Error._from(lib, st, err)
    return Run(lib, sc, run, (opts, out_dir), stop)
