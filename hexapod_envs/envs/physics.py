"""The physics side of an env: MuJoCo's solver options by the names of the settings
(`set_physics_options`, `SOLVER_IDS`, `INTEGRATOR_IDS`), the physics steps per control period
(`substeps_for`), stepping with the sensors evaluated in the last step only
(`step_sensing_last`, `step_without_sensors`) and the MuJoCo warnings that count as instability
(`UNSTABLE_WARNINGS`)."""

from __future__ import annotations

import mujoco

__all__ = [
    "INTEGRATOR_IDS",
    "SENSORS_OFF",
    "SOLVER_IDS",
    "UNSTABLE_WARNINGS",
    "set_physics_options",
    "step_sensing_last",
    "step_without_sensors",
    "substeps_for",
]

SENSORS_OFF = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
"""``opt.disableflags`` bit that skips the sensors in a MuJoCo step."""

SOLVER_IDS = {
    "newton": mujoco.mjtSolver.mjSOL_NEWTON,
    "cg": mujoco.mjtSolver.mjSOL_CG,
    "pgs": mujoco.mjtSolver.mjSOL_PGS,
}
"""MuJoCo constraint solvers by the names of the ``solver`` setting."""

INTEGRATOR_IDS = {
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
}
"""MuJoCo integrators by the names of the ``integrator`` setting."""


def set_physics_options(
    spec: mujoco.MjSpec,
    timestep: float,
    integrator: str = "implicitfast",
    iterations: int | None = None,
    ls_iterations: int | None = None,
    tolerance: float | None = None,
    solver: str = "newton",
    midphase: bool = True,
) -> None:
    """The solver options of an env: `timestep` [s], the `integrator` (`INTEGRATOR_IDS`), the
    constraint `solver` (`SOLVER_IDS`) and its `iterations`, `ls_iterations` and `tolerance`
    (None: MuJoCo's 100, 50 and 1e-8), and elliptic friction cones with a high impedance ratio
    (the default pyramidal cone lets a loaded foot creep down a slope at several cm/s, far
    below its friction limit). `midphase` False disables the collision midphase. The envs pass
    their settings of the same names (``physics_dt``, ``integrator``, ``solver``, ``solver_*``,
    ``midphase``)."""
    spec.option.timestep = timestep
    spec.option.integrator = INTEGRATOR_IDS[integrator]
    spec.option.solver = SOLVER_IDS[solver]
    for name, value in (
        ("iterations", iterations),
        ("ls_iterations", ls_iterations),
        ("tolerance", tolerance),
    ):
        if value is not None:
            setattr(spec.option, name, value)
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10.0
    if not midphase:
        spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_MIDPHASE)


def substeps_for(control_dt: float, physics_dt: float) -> int:
    """Physics steps per control step; the ratio must be a whole number."""
    if control_dt <= 0 or physics_dt <= 0:
        raise ValueError(f"control_dt and physics_dt must be > 0, got {control_dt}, {physics_dt}")
    n = round(control_dt / physics_dt)
    if n < 1 or abs(n * physics_dt - control_dt) > 1e-9 * max(1.0, control_dt):
        raise ValueError(
            f"control_dt={control_dt} s is not a whole multiple of physics_dt={physics_dt} s"
        )
    return n


def step_sensing_last(model: mujoco.MjModel, data: mujoco.MjData, nstep: int) -> None:
    """`nstep` MuJoCo steps, evaluating the sensors in the last one only.

    Sensors never act on the dynamics, and the envs read `data.sensordata` only after the
    steps, so the state and the final readings are bit-identical to evaluating them every step,
    while the skipped evaluations (the foot-force and accelerometer sensors need an extra
    dynamics pass, ATHENA's rangefinders cast rays) cost 5-10 % of a physics step.
    """
    if nstep > 1:
        step_without_sensors(model, data, nstep - 1)
        nstep = 1
    mujoco.mj_step(model, data, nstep=nstep)


def step_without_sensors(model: mujoco.MjModel, data: mujoco.MjData, nstep: int) -> None:
    """`nstep` MuJoCo steps with the sensors disabled (`data.sensordata` keeps its values)."""
    opt = model.opt
    flags = opt.disableflags
    opt.disableflags = flags | SENSORS_OFF
    try:
        mujoco.mj_step(model, data, nstep=nstep)
    finally:
        opt.disableflags = flags


_W = mujoco.mjtWarning
if {_W.mjWARN_BADQPOS, _W.mjWARN_BADQVEL, _W.mjWARN_BADQACC, _W.mjWARN_BADCTRL} != set(
    range(_W.mjWARN_BADQPOS, _W.mjWARN_BADCTRL + 1)
):  # pragma: no cover - MuJoCo's enum order; UNSTABLE_WARNINGS relies on it
    raise ImportError("this MuJoCo orders mjtWarning differently; update UNSTABLE_WARNINGS")

UNSTABLE_WARNINGS = slice(
    int(mujoco.mjtWarning.mjWARN_BADQPOS), int(mujoco.mjtWarning.mjWARN_BADCTRL) + 1
)
"""MuJoCo warnings that count as instability (`info["sim_unstable"]`, truncation): bad
qpos, qvel, qacc and ctrl, adjacent in `mjtWarning` (checked at import)."""
