"""Timed actuator commands of a 3-UPU gait plan (Li et al. 2018 §6, Fig. 7), pure numpy.

`GaitSchedule` samples a `GaitPlan` at the control period: each platform step runs six phases,

| phase | what moves | ends when |
|---|---|---|
| unload | the moving legs retract by `GaitTiming.unload_retract`, slowly (1) | time |
| lift | the moving legs retract on to `swing_extension` (feet leave the ground) | time |
| unloaded | nothing (the robot settles on the supporting tripod) | gate: moving feet off |
| transfer | the limbs carry the moving platform along the quadratic path (eqs. 19-21) | time |
| settle | nothing | time |
| land | the moving legs extend to their landing extensions (the ditch depth in the ditch) | time |
| loaded | nothing (six-leg support) | gate: moving feet down |

(1) so that the robot's weight passes to the supporting tripod without rocking it.

Ramps use the quintic (minimum-jerk) profile 10a^3 - 15a^4 + 6a^5: zero velocity and
acceleration at both ends. The transfer's ends are where the CoG sits nearest a side of the
support triangle, so ending without acceleration keeps the inertial shift of the zero-moment
point away from the margin's minimum.

The command vector is `COMMAND_NAMES`: the three limb lengths [m] then the six leg extensions
[m] (``U1 U2 U3 L1 L2 L3``), the order of `UpuHandles.actuators`. The schedule itself is open
loop; the gates are checkpoints (`Checkpoint`) that a closed-loop executor (the gait policy)
waits at until the foot contacts confirm them. Used by the env's reference gait and by
`agents.upu_gait.UpuGaitPolicy`, so both play exactly the same commands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ...checks import check_number
from .gait_plan import GaitPlan
from .kinematics import inverse_kinematics
from .params import LEG_NAMES, LIMB_NAMES, PLATFORM_LEGS, UpuParams

COMMAND_NAMES: tuple[str, ...] = LIMB_NAMES + tuple(f"{leg}_extend" for leg in LEG_NAMES)
"""Order of a command vector: limb lengths l_1..l_3 [m], then leg extensions U1..L3 [m]."""

PHASES: tuple[str, ...] = ("unload", "lift", "unloaded", "transfer", "settle", "land", "loaded")
"""Phases of one platform step, in order (see the module docstring)."""

GATES: dict[str, str] = {"unloaded": "off", "loaded": "down"}
"""Phase -> the moving feet's required contact state before the next phase may start."""

_LEG_INDEX = {leg: 3 + i for i, leg in enumerate(LEG_NAMES)}


def quintic(a):
    """Minimum-jerk profile 10a^3 - 15a^4 + 6a^5 on [0, 1] (clipped outside)."""
    a = np.clip(a, 0.0, 1.0)
    return a * a * a * (10.0 - 15.0 * a + 6.0 * a * a)


@dataclass(frozen=True)
class GaitTiming:
    """Duration of each phase of a platform step [s] (see `PHASES`), and the unload stroke."""

    unload: float = 0.4
    lift: float = 0.8
    unloaded: float = 0.2
    transfer: float = 2.5
    settle: float = 0.3
    land: float = 0.6
    loaded: float = 0.3
    unload_retract: float = 0.005
    """How far the moving legs retract during 'unload' [m]: a few mm take the load off the
    feet (leg servo and contact compliance are < 2 mm); retracting them at the lift's pace
    drops the load within ~0.1 s and rocks the robot on its supporting tripod."""

    def __post_init__(self) -> None:
        for f in fields(self):
            check_number(f"GaitTiming.{f.name}", getattr(self, f.name), strict=True)

    @property
    def durations(self) -> tuple[float, ...]:
        """Phase durations in `PHASES` order [s]."""
        return tuple(getattr(self, name) for name in PHASES)

    @property
    def step_duration(self) -> float:
        """One platform step [s] (half a gait cycle)."""
        return sum(self.durations)


@dataclass(frozen=True)
class Checkpoint:
    """A gate of the schedule: the command row `tick` may only be played once the `legs` are
    `state` ('off' the ground or 'down' on it)."""

    tick: int
    step: int
    state: str
    legs: tuple[str, ...]


def raise_to_limb_min(poses, params: UpuParams, moving: str) -> np.ndarray:
    """`poses` (..., 3) with |z| raised just enough that no limb is shorter than l_min [m].

    The paper's gait height (363 mm, eqs. 20-21) leaves limbs 2 and 3 up to 0.7 mm short of
    l_min near x = Delta/2 (see `UpuParams.initial_height`). Clipping those lengths instead
    would move the platform along x, by ~10x the clipped amount because the limbs are nearly
    vertical: ~5 mm per step, which adds up over a ditch crossing. Raising the pose keeps x.
    """
    q = np.array(poses, dtype=float)
    sign = 1.0 if moving == "upper" else -1.0
    v = q[..., None, :] * sign + params.upper_hooke_points - params.lower_hooke_points
    horizontal_sq = v[..., 0] ** 2 + v[..., 1] ** 2
    z_min = np.sqrt(np.maximum(params.limb_min**2 - horizontal_sq, 0.0).max(axis=-1))
    q[..., 2] = np.sign(q[..., 2]) * np.maximum(np.abs(q[..., 2]), z_min)
    return q


def walking_height(params: UpuParams) -> float:
    """Relative platform height the schedule walks at [m]: the paper's 363 mm raised to the
    lowest height at which no limb is shorter than l_min anywhere on the gait's level path
    (relative x in [0, l_max1] for the upper platform). Limbs 2 and 3 are shortest at
    x = Delta/2, where they are sqrt(3)/2 Delta off vertical, so the height is
    sqrt(l_min^2 - 3/4 Delta^2) = 363.74 mm for the paper's numbers (0.74 mm above its 363 mm,
    which the paper rounds; see `UpuParams.initial_height`). Walking at one fixed height
    keeps every step's start and end at the same relative height, so the legs' level offsets
    do not drift from step to step."""
    shortest = math.sqrt(max(params.limb_min**2 - 0.75 * params.delta**2, 0.0))
    return max(params.initial_height, shortest)


def standing_command(params: UpuParams) -> np.ndarray:
    """Command vector of the initial stance: the upper platform straight above the lower one at
    `walking_height`, the lower legs at nominal length and the upper legs longer by the
    height's excess over the paper's 363 mm, so that all six feet stand on level ground (a
    six-leg stance on stiff legs shares its load by sub-mm differences: 0.3 mm is ~15 N at
    the legs' 5e4 N/m)."""
    pose = raise_to_limb_min([0.0, 0.0, walking_height(params)], params, "upper")
    limbs = np.clip(inverse_kinematics(pose, params), params.limb_min, params.limb_max)
    rise = float(pose[2]) - params.initial_height
    return np.concatenate([limbs, np.full(3, rise), np.zeros(3)])


class GaitSchedule:
    """The commands of `plan` at every control step (row k is played during control step k).

    A plan that is not ``ok`` (or has no steps) gives a one-row schedule that stands still.
    After the last row the robot holds the last command (`command` clamps the tick).
    """

    def __init__(
        self,
        plan: GaitPlan,
        params: UpuParams,
        control_dt: float,
        timing: GaitTiming | None = None,
    ):
        if not (math.isfinite(control_dt) and control_dt > 0):
            raise ValueError(f"control_dt must be a finite number > 0 s, got {control_dt}")
        self.plan, self.params, self.control_dt = plan, params, control_dt
        self.timing = timing or GaitTiming()
        ticks = [max(1, int(round(d / control_dt))) for d in self.timing.durations]
        self.phase_ticks: tuple[int, ...] = tuple(ticks)
        ramps = [quintic(np.arange(1, n + 1) / n)[:, None] for n in ticks]  # per phase, 0 -> 1
        blocks, steps, phases, checkpoints = [], [], [], []
        n_rows = 0
        current = standing_command(params)
        # Level offsets: extension each platform's legs need on level ground, beyond nominal,
        # because the executed relative height differs from the paper's 363 mm (see
        # `raise_to_limb_min`): upper - lower = relative height - initial_height.
        level = {"upper": float(current[3]), "lower": 0.0}
        lo, hi = params.extension_range
        if plan.ok:
            transfers = _transfer_limbs(plan.steps, params, ticks[PHASES.index("transfer")])
            for k, step in enumerate(plan.steps):
                legs = PLATFORM_LEGS[step.moving]
                cols = [_LEG_INDEX[leg] for leg in legs]
                start_ext = current[cols].copy()
                swing = np.full(3, step.swing_extension)
                unloaded = np.maximum(start_ext - self.timing.unload_retract, swing)
                limbs, end_z = transfers[k]
                rise = abs(end_z) - params.initial_height
                other = "lower" if step.moving == "upper" else "upper"
                level[step.moving] = level[other] + (rise if step.moving == "upper" else -rise)
                landing = np.clip(
                    [step.landing_extension[leg] + level[step.moving] for leg in legs], lo, hi
                )
                for p, (name, n, a) in enumerate(zip(PHASES, ticks, ramps, strict=True)):
                    block = np.repeat(current[None, :], n, axis=0)
                    if name == "unload":
                        block[:, cols] = start_ext + (unloaded - start_ext) * a
                    elif name == "lift":
                        block[:, cols] = unloaded + (swing - unloaded) * a
                    elif name == "transfer":
                        block[:, :3] = limbs
                    elif name == "land":
                        block[:, cols] = swing + (landing - swing) * a
                    current = block[-1].copy()
                    if name in GATES and not (name == "loaded" and k == len(plan.steps) - 1):
                        checkpoints.append(Checkpoint(n_rows + n, k, GATES[name], legs))
                    blocks.append(block)
                    n_rows += n
                    steps.append(np.full(n, k))
                    phases.append(np.full(n, p))
        if not blocks:
            blocks, steps, phases = [current[None, :]], [[-1]], [[-1]]
        self.commands = np.concatenate(blocks)
        """(n_ticks, 9) command rows [m], columns `COMMAND_NAMES`."""
        self.step_index = np.concatenate(steps).astype(int)
        """(n_ticks,) plan step of each row (-1: standing without a plan)."""
        self.phase_index = np.concatenate(phases).astype(int)
        """(n_ticks,) index into `PHASES` of each row (-1: standing without a plan)."""
        self.checkpoints: tuple[Checkpoint, ...] = tuple(checkpoints)
        self._gate_at = {c.tick: c for c in checkpoints}

    @property
    def n_ticks(self) -> int:
        return len(self.commands)

    @property
    def duration(self) -> float:
        """Length of the schedule [s] (without gate waits)."""
        return self.n_ticks * self.control_dt

    def command(self, tick: int) -> np.ndarray:
        """Command row of control step `tick` (the last row after the end; read-only view)."""
        return self.commands[min(max(tick, 0), self.n_ticks - 1)]

    def gate(self, tick: int) -> Checkpoint | None:
        """The checkpoint that must hold before row `tick` is played, if any."""
        return self._gate_at.get(tick)

    def phase(self, tick: int) -> tuple[int, str]:
        """(plan step, phase name) of control step `tick`; (-1, 'stand') without a plan and
        (last step, 'done') after the end."""
        if tick >= self.n_ticks:
            last = int(self.step_index[-1])
            return (last, "done" if last >= 0 else "stand")
        i = int(self.phase_index[max(tick, 0)])
        return (int(self.step_index[max(tick, 0)]), PHASES[i] if i >= 0 else "stand")

    def support(self, tick: int) -> str:
        """Legs carrying the robot at control step `tick` by the plan: 'upper' or 'lower' (the
        supporting tripod, from the moving legs' lift-off until they touch down at the end of
        'land') or 'all' (six legs: 'loaded', standing, done)."""
        step, phase = self.phase(tick)
        if step < 0 or phase in ("done", "stand", "loaded"):
            return "all"
        return self.plan.steps[step].support


def _transfer_poses(steps, params: UpuParams, n: int) -> np.ndarray:
    """(len(steps), n, 3) relative poses of the moving platforms along their paths (eqs.
    19-21, `QuadraticPath.z` for all steps at once), quintic in x, shifted from the paper's
    height to `walking_height` [m]. The steps must move the same platform."""
    paths = [step.path(params) for step in steps]

    def per_step(name: str) -> np.ndarray:  # (len(steps), 1): broadcasts against the n ticks
        return np.array([[getattr(path, name)] for path in paths])

    x_start, x_end, a, b, c = map(per_step, ("x_start", "x_end", "a", "b", "c"))
    x = x_start + (x_end - x_start) * quintic(np.arange(1, n + 1) / n)
    shift = walking_height(params) - params.initial_height
    z = a * x**2 + b * x + c + (shift if steps[0].moving == "upper" else -shift)
    return np.stack([x, np.zeros_like(x), z], axis=-1)


def _transfer_limbs(steps, params: UpuParams, n: int) -> list[tuple[np.ndarray, float]]:
    """Per step, the (n, 3) limb lengths of its transfer phase [m] (poses raised to l_min,
    lengths clipped to the limbs' range) and the final relative height of the moving platform
    [m]. Computed for all steps of each moving platform at once: the same numbers as step by
    step, since every operation is elementwise or over the last axis."""
    found: list[tuple[np.ndarray, float]] = [None] * len(steps)  # type: ignore[list-item]
    for moving in ("upper", "lower"):
        which = [k for k, step in enumerate(steps) if step.moving == moving]
        if not which:
            continue
        poses = raise_to_limb_min(
            _transfer_poses([steps[k] for k in which], params, n), params, moving
        )
        limbs = np.clip(
            inverse_kinematics(poses, params, moving=moving), params.limb_min, params.limb_max
        )
        for j, k in enumerate(which):
            found[k] = (limbs[j], float(poses[j, -1, 2]))
    return found
