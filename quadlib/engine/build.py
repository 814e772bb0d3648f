"""Each filter's engine, generated from its own kernels and compiled the first time it runs.

A filter declares its maths once, as :class:`~quadlib.engine.kernel.Kernel` objects in its model's
and sensors' fields. :func:`filter_loops` writes a copy of :mod:`quadlib.engine.template` in which
the template's names (``model_g``, ``sensor_h`` …) are that filter's kernels and its flags say which
optional steps exist, and imports it; numba compiles it on its first call and keeps the machine code
beside it. The copy's file name is a hash of everything it is made of — the template, the filter's
kernels and flags, and the source of every module those kernels come from (with the modules of
``quadlib`` they import) — so a copy is never stale: editing a model makes a new copy for the filters
that use it, and leaves every other filter's compiled code as it was. :func:`smoother_loops` does the
same for the RTS backward pass, which depends on the model alone.

The copies live in ``quadlib/engine/__pycache__/filters`` when the package's folder is writable, else
in ``$XDG_CACHE_HOME/quadlib/filters`` (``~/.cache``); ``QUADLIB_CACHE_DIR`` overrides both. A kernel
may come from anywhere — a user's module, a script, a notebook — as long as numba compiled it
(``@njit``): it is bound into the copy by reference, not imported by name.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import os
import sys
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType

import numba
import numpy as np

from quadlib.engine.defaults import DEFAULTS, sigma_difference, sigma_mean
from quadlib.engine.kernel import MODEL_ROLES
from quadlib.numba_cache import module_digest
from quadlib.progress import progress_enabled

__all__ = ["CompileError", "Compiled", "cache_dir", "filter_loops", "is_compiled", "smoother_loops"]

_TEMPLATE = Path(__file__).with_name("template.py")
_HEADER_START, _HEADER_END = "# >>> the filter's kernels", "# <<<"
_QUADLIB = Path(__file__).resolve().parent.parent

ABOUT_S = {"EKF": 20, "UKF": 30, "RTS": 10}
"""About how long [s] numba takes to compile one filter's loop on a 2-core machine (the notice says it;
``benchmarks/engine_compile.py`` measures 18 s for the orientation MEKF, 28 s for the fixed-wing UKF)."""


OPT_LEVEL = int(os.environ.get("QUADLIB_ENGINE_OPT", "1"))
"""LLVM's optimisation level for a filter's loop (``QUADLIB_ENGINE_OPT``, 1 unless set): -O1 compiles
in about half the time of numba's default -O3, and the loop runs as fast
(``benchmarks/engine_compile.py`` measures both)."""


@contextmanager
def _optimized_at(level: int):
    """numba's LLVM optimisation level set to ``level`` for the compiles inside (numba compiles under
    one lock, so no other compile sees it)."""
    saved = numba.core.config.OPT
    numba.core.config.OPT = type(saved)(level)
    try:
        yield
    finally:
        numba.core.config.OPT = saved


class CompileError(RuntimeError):
    """numba could not compile a filter's kernels into its loop; the message says why."""


def cache_dir() -> Path:
    """Where the filters' compiled copies are kept (see the module's docstring)."""
    if "QUADLIB_CACHE_DIR" in os.environ:
        return Path(os.environ["QUADLIB_CACHE_DIR"]) / "filters"
    here = Path(__file__).resolve().parent / "__pycache__"
    if os.access(here if here.exists() else here.parent, os.W_OK):
        return here / "filters"
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "quadlib" / "filters"


def _function_digest(f) -> str:
    """What a kernel is made of: its module's source (and, in ``quadlib``, the modules it imports), or
    its own source when its module has no file (a script's ``__main__``, a notebook)."""
    py = f.py_func
    module = sys.modules.get(py.__module__)
    path = getattr(module, "__file__", None)
    if path and Path(path).resolve().is_relative_to(_QUADLIB):
        return module_digest(Path(path).resolve())
    try:
        text = Path(path).read_bytes() if path and Path(path).is_file() else inspect.getsource(py).encode()
    except (OSError, TypeError):
        text = py.__code__.co_code
    return hashlib.sha256(text).hexdigest()


def is_compiled(f) -> bool:
    """Whether ``f`` is a function numba compiled (``@njit``)."""
    return isinstance(f, numba.core.registry.CPUDispatcher)


def _switch(name: str, args: str, cases: list[str]) -> str:
    """A function ``name(s, args)`` that returns ``cases[s]`` (each a return expression)."""
    lines = ["@njit(cache=True)", f"def {name}(s, {args}):"]
    for s, case in enumerate(cases[:-1]):
        lines += [f"    if s == {s}:", f"        return {case}"]
    lines.append(f"    return {cases[-1]}")
    return "\n".join(lines)


class _Copy:
    """The source of one filter's copy of the template and the functions bound into it."""

    def __init__(self, label: str, kind: str):
        self.label, self.kind = label, kind
        self.bound: dict[str, object] = {}
        self.lines = ["# one filter's copy of quadlib/engine/template.py, its names bound to its kernels by "
                      "quadlib.engine.build"]

    def bind(self, name: str, f) -> None:
        self.bound[name] = f
        py = getattr(f, "py_func", f)
        self.lines.append(f"#   {name} = {py.__module__}.{py.__qualname__}")

    def source(self) -> str:
        template = _TEMPLATE.read_text()
        start, end = template.index(_HEADER_START), template.index(_HEADER_END)
        return template[:start] + "\n".join(self.lines) + "\n" + template[end:]


def _model_copy(copy: _Copy, model_kernels: dict, error_state: bool) -> None:
    """Bind a model's kernels (role → numba function or None) and set the flags."""
    for role in MODEL_ROLES:
        f = model_kernels.get(role)
        copy.bind(f"model_{role}", f if f is not None else DEFAULTS.get(role, DEFAULTS["G"]))
    has = {role: model_kernels.get(role) is not None for role in MODEL_ROLES}
    flags = {"ERROR_STATE": error_state, "G_IDENTITY": bool(model_kernels.get("G_identity")),
             "INPUT_NOISE": has["input_noise"], "NORMALIZE": has["normalize"],
             "NORMALIZE_JACOBIAN": has["normalize_jacobian"] and not error_state,
             "ADD_JACOBIAN": has["add_jacobian"] and error_state}
    copy.lines += [f"{flag} = {value}" for flag, value in flags.items()]


def _sensor_switches(copy: _Copy, sensors: list[dict]) -> None:
    """The switches ``sensor_h(s, …)``, ``sensor_H``, ``sensor_residual``, ``sensor_mean`` over the
    sensors' kernels (role → numba function or None: a plain difference, a plain mean, no ``H``)."""
    h, H, residual, mean = [], [], [], []
    for s, kernels in enumerate(sensors):
        for role in ("h", "H", "residual", "mean"):
            if kernels.get(role) is not None:
                copy.bind(f"sensor_{s}_{role}", kernels[role])
        h.append(f"sensor_{s}_h(x, c, p)")
        H.append(f"sensor_{s}_H(x, c, p)" if kernels.get("H") is not None else "np.zeros((0, 0))")
        residual.append(f"sensor_{s}_residual(z, z_hat, p)" if kernels.get("residual") is not None else "z - z_hat")
        mean.append(f"sensor_{s}_mean(Z, w, p)" if kernels.get("mean") is not None else "weighted_mean(Z, w)")
    if not sensors:
        h, H, residual, mean = ["np.zeros(0)"], ["np.zeros((0, 0))"], ["z - z_hat"], ["weighted_mean(Z, w)"]
    copy.lines += ["", "", _switch("sensor_h", "x, c, p", h), "", "", _switch("sensor_H", "x, c, p", H), "", "",
                   _switch("sensor_residual", "z, z_hat, p", residual), "", "",
                   _switch("sensor_mean", "Z, w, p", mean), "", ""]


def _key(copy: _Copy) -> str:
    digest = hashlib.sha256(copy.source().encode())
    digest.update(f"numba {numba.__version__} numpy {np.__version__} {sys.version}".encode())
    for name in sorted(copy.bound):
        digest.update(name.encode() + _function_digest(copy.bound[name]).encode())
    return digest.hexdigest()[:20]


_LOADED: dict[str, ModuleType] = {}


def _load(copy: _Copy, entry: str) -> tuple[ModuleType, bool]:
    """The copy as a module (written and imported once per process), and whether numba has no
    machine code for its ``entry`` on disk yet (the first call will compile it)."""
    for name, f in copy.bound.items():
        if not is_compiled(f):
            raise CompileError(f"{name} is {f!r}, not a numba function")
    key = _key(copy)
    name = f"quadlib_{copy.kind.lower()}_{key}"
    folder = cache_dir()
    path = folder / f"{name}.py"
    if name not in _LOADED:
        if not path.is_file():
            folder.mkdir(parents=True, exist_ok=True)
            partial = folder / f".{name}.{os.getpid()}.tmp"
            partial.write_text(copy.source())
            os.replace(partial, path)
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        module.__dict__.update(copy.bound)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        _LOADED[name] = module
    return _LOADED[name], not _cached_on_disk(getattr(_LOADED[name], entry))


def _cached_on_disk(f) -> bool:
    """Whether numba has an index of machine code for ``f`` on disk (wherever NUMBA_CACHE_DIR puts it)."""
    index = getattr(getattr(getattr(f, "_cache", None), "_cache_file", None), "_index_path", None)
    return index is not None and os.path.exists(index)


class Compiled:
    """A filter's compiled entry point: calling it compiles on the first call (saying so once, on
    stderr, when numba has nothing on disk yet, unless progress is switched off as in the tests and
    the book, :mod:`quadlib.progress`) and turns a failed compile into :class:`CompileError`."""

    def __init__(self, label: str, kind: str, function, fresh: bool):
        self.label, self.kind, self.function, self.fresh = label, kind, function, fresh
        self.failed = ""  # why numba could not compile it: tried once a process

    def __call__(self, *args):
        if self.failed:
            raise CompileError(self.failed)
        if self.fresh and not self.function.signatures and progress_enabled():
            print(f"quadlib: compiling the {self.label}, once (about {ABOUT_S[self.kind]} s)", file=sys.stderr,
                  flush=True)
        try:
            if self.function.signatures:
                out = self.function(*args)
            else:
                with _optimized_at(OPT_LEVEL):
                    out = self.function(*args)
        except (numba.core.errors.NumbaError, NotImplementedError) as err:
            self.failed = f"numba could not compile the {self.label}: {_reason(err)}"
            raise CompileError(self.failed) from err
        self.fresh = False
        return out


def _reason(err: Exception) -> str:
    """The line of numba's message that says what failed (not which pass it failed in)."""
    lines = [line.strip() for line in str(err).splitlines() if line.strip()]
    said = [line for line in lines if not line.startswith(("Failed in", "During:", "File ", "<source", "^"))]
    return (said or lines or [repr(err)])[0]


def filter_loops(label: str, kind: str, model_kernels: dict, error_state: bool, sensors: list[dict],
                 sigma_kernels: dict | None = None) -> Compiled:
    """The forward pass (:func:`~quadlib.engine.template.filter_pass`) of one filter.

    Parameters
    ----------
    label : str
        What the compile notice calls it ("orientation EKF").
    kind : {"EKF", "UKF"}
    model_kernels : dict
        Model role → numba function, or None where the model has none; ``"G_identity"`` True when
        ``G = I`` (its propagation is then skipped).
    error_state : bool
        Whether ``P`` is over an error state.
    sensors : list of dict
        For each sensor, role (``h``, ``H``, ``residual``, ``mean``) → numba function or None.
    sigma_kernels : dict, optional
        A UKF's ``residual_x`` and ``mean`` of an additive state (numba functions or None).
    """
    copy = _Copy(label, kind)
    _model_copy(copy, model_kernels, error_state)
    sigma_kernels = sigma_kernels or {}
    copy.bind("sigma_difference", sigma_kernels.get("residual_x") or sigma_difference)
    copy.bind("sigma_mean", sigma_kernels.get("mean") or sigma_mean)
    _sensor_switches(copy, sensors)
    module, fresh = _load(copy, "filter_pass")
    return Compiled(label, kind, module.filter_pass, fresh)


def smoother_loops(label: str, model_kernels: dict, error_state: bool) -> Compiled:
    """The RTS backward pass (:func:`~quadlib.engine.template.rts_pass`) of a model (see :func:`filter_loops`)."""
    copy = _Copy(label, "RTS")
    _model_copy(copy, model_kernels, error_state)
    copy.bind("sigma_difference", sigma_difference)
    copy.bind("sigma_mean", sigma_mean)
    _sensor_switches(copy, [])
    module, fresh = _load(copy, "rts_pass")
    return Compiled(label, "RTS", module.rts_pass, fresh)
