"""Control periods of MuJoCo steps for many worlds in one compiled call that never holds the GIL
(`compiled_steps_available`, `run_control_periods`): what `BatchedPhysics` runs on its threads
for envs whose control period is plain MuJoCo steps (`HexapodEnv._run_physics`: the cliff walk,
the Stewart tilt and the ditch crossing).

Why: a thread that steps a world through ``mujoco.mj_step`` releases the GIL inside the call
but must take it back after each one, and while the calling thread runs the envs' Python it
waits for it (Python hands the GIL over every 5 ms), and a thread pool adds a future and two
wake-ups per world. One call of `run_control_periods` runs a whole share of worlds with the
GIL released from start to end, and sets each world's flag in an array once its period is
done.

How: numba calls libmujoco's own ``mj_step`` (the function the Python binding wraps, on the
same ``mjModel`` and ``mjData``, so the state is bit-identical) through ctypes. As
`hexapod_envs.envs.physics.step_sensing_last` does, a period's steps before the last run with
the sensors disabled: the kernel writes each model's ``opt.disableflags`` with MuJoCo's
``mju_copyInt``, at an offset in the ``mjModel`` struct found once per process by writing two
sentinel values through the binding and reading the struct's bytes (`_disableflags_offset`).
Where the library, that function or a unique offset is not found, `compiled_steps_available`
is False and `BatchedPhysics` steps the worlds through the binding on a thread pool instead.
A MuJoCo fatal error inside a compiled step (``mju_error``, which the binding raises as
`mujoco.FatalError`; instabilities are warnings, not errors) would end the process instead of
raising; ``nthread=0`` steps every world through the binding.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import os

import mujoco
import numpy as np

__all__ = ["compiled_steps_available", "run_control_periods"]

_STRUCT_SCAN_BYTES = 2048
"""Bytes of an ``mjModel`` searched for ``opt.disableflags``: the struct's sizes (8 bytes each,
about 130 in MuJoCo 3-4) come first, then ``opt``."""


def _library() -> ctypes.CDLL | None:
    """libmujoco as shipped in the mujoco package (None where it is not found)."""
    folder = os.path.dirname(mujoco.__file__)
    for pattern in ("libmujoco.so*", "libmujoco*.dylib", "mujoco.dll"):
        found = sorted(glob.glob(os.path.join(folder, pattern)))
        if found:
            try:
                return ctypes.CDLL(found[0])
            except OSError:
                return None
    return None


def _disableflags_offset() -> int | None:
    """The byte offset of ``opt.disableflags`` in an ``mjModel`` (None unless exactly one
    position holds each of two sentinel values written through the binding)."""
    model = mujoco.MjModel.from_xml_string("<mujoco/>")
    candidates = None
    for sentinel in (0x2B3C4D5E, 0x3D2E1F07):
        model.opt.disableflags = sentinel
        raw = np.frombuffer(ctypes.string_at(model._address, _STRUCT_SCAN_BYTES), np.int32)
        hits = set((4 * np.flatnonzero(raw == sentinel)).tolist())
        candidates = hits if candidates is None else candidates & hits
    if candidates is None or len(candidates) != 1:
        return None
    return candidates.pop()


@functools.cache
def _kernel():
    """The compiled kernel (the flags' offset built in), or None where it is not available.
    Built on first use (compiling takes about a second; numba cannot cache a function that calls
    ctypes pointers)."""
    try:  # the binding's private addresses and the library's symbols may change
        library = _library()
        offset = _disableflags_offset()
    except (AttributeError, OSError, ValueError):
        return None
    if library is None or offset is None:
        return None
    if not (hasattr(library, "mj_step") and hasattr(library, "mju_copyInt")):
        return None
    step = library.mj_step
    step.argtypes = [ctypes.c_int64, ctypes.c_int64]
    step.restype = None
    copy_int = library.mju_copyInt
    copy_int.argtypes = [ctypes.c_int64, ctypes.c_int64, ctypes.c_int32]
    copy_int.restype = None

    from numba import njit

    @njit(nogil=True)
    def periods(models, datas, flags, nsteps, done, start, stop):
        for i in range(start, stop):
            n = nsteps[i]
            if n > 1:
                copy_int(models[i] + offset, flags[i, 0:].ctypes.data, 1)
                for _ in range(n - 1):
                    step(models[i], datas[i])
                copy_int(models[i] + offset, flags[i, 1:].ctypes.data, 1)
            step(models[i], datas[i])
            done[i] = 1

    return periods


def compiled_steps_available() -> bool:
    """Whether `run_control_periods` can run here (libmujoco and the flags' offset found)."""
    return _kernel() is not None


def run_control_periods(
    models: np.ndarray,
    datas: np.ndarray,
    flags: np.ndarray,
    nsteps: np.ndarray,
    done: np.ndarray,
    start: int,
    stop: int,
) -> None:
    """Worlds ``start`` to ``stop - 1``'s control periods, without the GIL: ``nsteps[i]`` MuJoCo
    steps of the model and data at the addresses ``models[i]`` and ``datas[i]`` (int64), the
    steps before the last with ``opt.disableflags`` set to ``flags[i, 0]`` (the sensors off),
    the last with ``flags[i, 1]`` (the model's own flags, left in place); then ``done[i] = 1``
    (int8). The caller keeps every model and data alive and untouched until its flag is set
    (see `hexapod_envs.vector.batched` for when another thread may trust the flag alone)."""
    kernel = _kernel()
    if kernel is None:
        raise RuntimeError("compiled control periods are not available with this MuJoCo")
    kernel(models, datas, flags, nsteps, done, start, stop)
