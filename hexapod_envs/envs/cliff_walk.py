"""HexapodCliffWalk-v0 / -v1: the heavy-duty hexapod walks a tripod gait beside a unilateral cliff.

## Description
Zhang et al. 2024 §5.1: after 3 s of standing the robot walks on flat ground that, ahead of it,
drops away on one side; a leg on that side steps into the void, the FASM falls below ξ_f = 20°
and, without a recovery controller, the robot tips over.

## Action Space
18 values in [-1, 1] (J_x, J_z, J_theta per leg in LF LM LR RF RM RR order): joint targets in
``action_mode="joint"``, or offsets from the reference tripod gait in ``"residual"`` (default;
see `HeavyDutyEnv`). ``clock_action=True`` (residual mode) adds a 19th: the reference gait's
clock rate, 1 + min(a, 0), so that a policy can slow or hold the gait; ``clock_action="stop"``
makes it a one-way stop (the first walking step at -1 stops the gait for the episode).

## Observation Space

| Observation piece | size | unit |
|---|---|---|
| joint_pos | 18 | J_x, J_z [m], J_theta [rad] per leg (LF LM LR RF RM RR) |
| joint_vel | 18 | m/s, rad/s |
| foot_force | 18 | ground reaction on each foot, world frame [N] |
| foot_contact | 6 | 1 when the foot carries > contact_threshold of the weight |
| fasm_margin_deg | 1 | FASM from the measured foot forces [deg] (0 without a support polygon) |
| imu_gyro | 3 | body angular velocity [rad/s] |
| imu_accel | 3 | accelerometer [m/s²] |
| imu_quat | 4 | body orientation (w, x, y, z) |
| gait_phase | 3 | sin, cos of the gait clock, 1 once walking (0 again after a stop) |

## Rewards

| Reward term (info key) | meaning |
|---|---|
| reward_forward | forward_weight x clip(CoG speed along x / gait speed, -1, forward_cap) |
| reward_stability | stability_weight x clip(FASM, -ξ, 45) / 45 (ξ = tipping_threshold_deg, 20) |
| reward_alive | the largest cost of a step, paid while the robot is up (see below) |
| reward_tip_over | -tip_over_penalty on the step the robot tips over (episode ends) |
| reward_effort | -effort_weight x min(sum of |joint power| / (weight x gait speed), 20) |

Every term is bounded and the alive term (forward_weight + stability_weight x ξ/45 +
effort_weight x 20) makes an upright step's reward >= 0, so an episode that ends by tipping over
returns less than staying up, however badly the robot moves.

## Starting State
The robot stands in the gait's first posture, its joints perturbed by up to
``reset_noise_scale`` of their half range, and settles for ``settle_time``. Task distributions
(``task_distribution=``): "paper" (default) is the scenario above; "train" / "test" draw cliff
distance, side, edge offset, drop, ground friction and a payload (mass, CoG offset) at every
reset from the ``train_ranges`` / ``test_ranges`` settings (defaults `CLIFF_TRAIN` /
`CLIFF_TEST`; held out: farther, deeper, nearer the centre line, lower friction, heavier
payload). ``info["task"]`` holds the values and their ``difficulty``.

## Episode End
Terminated on a tip-over: the body tilts past ``tip_over_angle_deg`` (-v0: 20°; -v1: 15°), or
(-v1) the FASM stays at or below 0 for ``tip_over_margin_time`` (1 s). Truncated at 1500 steps
(30 s). ``info["is_success"]`` at the last step: no tip-over and at least ``min_progress`` of the
reference gait's distance (``info["behind_pace"]`` while it is short of that share of the
distance the reference covers in the walking time so far); -v1 also needs the tilt within 8°
and at most 10 % of the episode below ξ_f (docs/benchmark.md).

## Arguments
`CliffWalkSettings` and `HeavyDutySettings` (``gym.make(id, **kwargs)``; unknown keys are an
error that lists the valid ones).

## Version History
- v1: termination at 15° or 1 s at FASM <= 0; success bounded in tilt (8°) and time below ξ_f
  (10 %); cliffs 0.33-2.53 m ahead of the front feet (`hexapod_envs.benchmark`).
- v0: the papers' reproduction.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np

from ..robots.heavy_duty.gait import TripodGait, TripodGaitParams
from ..terrain.cliff import CLIFF_SIDES, add_cliff
from ..terrain.flat import add_flat
from .difficulty import DifficultySpan
from .heavy_duty import (
    TEST_PAYLOAD,
    TRAIN_PAYLOAD,
    HeavyDutyEnv,
    HeavyDutySettings,
    HeavyDutyTaskRanges,
)
from .settings import bounded, choice, number, option

TERRAINS = ("cliff", "flat")


def front_foot_x(gait: TripodGaitParams | None = None) -> float:
    """x of the farthest foot at the start [m]: the body starts at x = 0
    and the gait clock at 0, where the paper's gait has RF 0.07 m ahead of its neutral foothold
    (its stroke lies mostly behind it, see `TripodGaitParams.stance_offset`)."""
    feet = TripodGait(gait=gait).feet_at_phase(0.0)
    return max(float(foot[0]) for foot in feet.values())


FRONT_FEET_X = round(front_foot_x(), 3)
"""x of the farthest foot at the start with the paper's gait (RF, 2.471 m) [m]: the bound of
the task ranges' cliff x (a settings' own gait is checked against its own front foot)."""


@dataclasses.dataclass(frozen=True)
class CliffTaskRanges(HeavyDutyTaskRanges):
    """Ranges of one task distribution (uniform draws; `side` is drawn from `sides`).

    Held-out test ranges (the defaults of `CLIFF_TEST`) extrapolate beyond training: the cliff
    farther ahead and deeper, the edge nearer the centre line, lower friction, heavier payload.
    """

    cliff_x: tuple[float, float] = bounded(FRONT_FEET_X, strict=True)
    edge_y: tuple[float, float] = bounded(None)
    drop: tuple[float, float] = bounded(strict=True)
    friction: tuple[float, float] = bounded()
    sides: tuple[str, ...] = CLIFF_SIDES


CLIFF_TRAIN = CliffTaskRanges(
    cliff_x=(2.8, 3.4), edge_y=(-1.3, -0.9), drop=(1.0, 3.0), friction=(0.8, 1.2), **TRAIN_PAYLOAD
)
CLIFF_TEST = CliffTaskRanges(
    cliff_x=(3.4, 4.0), edge_y=(-0.9, -0.7), drop=(3.0, 5.0), friction=(0.6, 0.8), **TEST_PAYLOAD
)


@dataclasses.dataclass(frozen=True)
class CliffWalkSettings(HeavyDutySettings):
    """Settings of HexapodCliffWalk-v0 (the cliff of the "paper" task, and the ranges)."""

    terrain: str = choice("cliff", TERRAINS)
    cliff_x: float = number(2.8, low=None)
    """x of the cliff's near edge [m] (ahead of the front feet)."""
    cliff_side: str = choice("right", CLIFF_SIDES)
    cliff_drop: float = number(3.0, strict=True)
    """Depth of the drop [m]."""
    cliff_edge_y: float = number(-1.0, low=None)
    """y of the cliff's side edge [m] (signed: toward the cliff side)."""
    friction: float = number(1.0)
    """Ground friction coefficient."""
    train_ranges: CliffTaskRanges = option(CLIFF_TRAIN, kind=CliffTaskRanges, optional=False)
    test_ranges: CliffTaskRanges = option(CLIFF_TEST, kind=CliffTaskRanges, optional=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.terrain != "cliff":
            return
        front = front_foot_x(self.gait)  # with this gait (the reset's joint noise settles out)
        for name, x in (
            ("cliff_x", self.cliff_x),
            ("train_ranges.cliff_x", self.train_ranges.cliff_x[0]),
            ("test_ranges.cliff_x", self.test_ranges.cliff_x[0]),
        ):
            if x <= front:
                raise ValueError(
                    f"{name}={x} m places the cliff at or behind the robot's front feet "
                    f"(x <= {front:.3f} m at the start); the robot walks along +x, put the "
                    "cliff ahead of it"
                )


class CliffWalkEnv(HeavyDutyEnv):
    """Tripod walking toward a unilateral cliff (set ``terrain="flat"`` for plain ground)."""

    Settings = CliffWalkSettings
    difficulty_spans = {
        "cliff_x": DifficultySpan(easy=5.0, hard=2.8),
        "cliff_edge_y": DifficultySpan(easy=-1.3, hard=-0.7),
        "cliff_drop": DifficultySpan(easy=1.0, hard=5.0),
        "friction": DifficultySpan(easy=1.2, hard=0.6),
        "payload_mass": DifficultySpan(easy=0.0, hard=800.0),
    }
    """What makes a cliff task hard: the edge near (the robot meets it early and must go on
    walking beside it), cutting deep into the walking path (the outer feet are at |y| = 1.9 m),
    a deep drop, a slippery ground, a heavy payload."""

    def _setup(self) -> None:
        s = self.settings
        self.terrain = s.terrain
        self.cliff = {
            "start_x": s.cliff_x,
            "side": s.cliff_side,
            "drop": s.cliff_drop,
            "edge_y": s.cliff_edge_y,
        }
        self.friction = s.friction
        self.task_ranges = {"train": s.train_ranges, "test": s.test_ranges}
        super()._setup()

    def _add_terrain(self, spec: mujoco.MjSpec) -> None:
        if self.terrain == "flat":
            add_flat(spec, friction=self.friction)
        else:
            add_cliff(spec, friction=self.friction, **self.cliff)

    # --- task distribution -----------------------------------------------------------------
    def paper_task(self) -> dict:
        s = self.settings
        return {
            "terrain": self.terrain,
            "cliff_x": float(s.cliff_x),
            "cliff_side": s.cliff_side,
            "cliff_drop": float(s.cliff_drop),
            "cliff_edge_y": float(s.cliff_edge_y),
            "friction": float(s.friction),
            **self.NO_PAYLOAD,
        }

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict:
        r = self.task_ranges[distribution]
        return {
            "terrain": self.terrain,
            "cliff_x": float(rng.uniform(*r.cliff_x)),
            "cliff_side": str(r.sides[int(rng.integers(len(r.sides)))]),
            "cliff_drop": float(rng.uniform(*r.drop)),
            "cliff_edge_y": float(rng.uniform(*r.edge_y)),
            "friction": float(rng.uniform(*r.friction)),
            **self._sample_payload(rng, r),
        }

    def _set_terrain(self, task: dict) -> bool:
        cliff = {
            "start_x": task["cliff_x"],
            "side": task["cliff_side"],
            "drop": task["cliff_drop"],
            "edge_y": task["cliff_edge_y"],
        }
        if cliff == self.cliff and task["friction"] == self.friction:
            return False
        self.cliff, self.friction = cliff, task["friction"]
        return True
