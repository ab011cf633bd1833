"""The 3-3 gait of the 3-UPU hexapod (Li et al. 2018 §6-7) as a policy for HexapodDitchCrossing-v0.

The policy plans the walk the way the paper's robot does, knowing the ditch: it reads the
env's declared task description (`env.unwrapped.task_description`: the course's terrain and
ditch geometry, the reference's start x, gait settings and timing, the robot's parameters) on
its first call of an episode and calls the planner of `hexapod_envs.robots.upu.gait_plan`
(strides <= l_max1 = 160 mm, eq. 17; strides shortened so that no foot lands on a ditch edge;
legs extended into the ditch, §7). `hexapod_envs.robots.upu.gait_schedule` times the steps:
the moving platform's legs retract (lift), the platform travels along its quadratic path
(eqs. 19-21), the legs extend until the feet are down (land), and the platforms swap roles.

Closed loop through the foot contact switches (observation piece ``foot_contact``, the
paper's per-leg pressure sensors): the transfer starts only once the moving feet are off the
ground, and the next platform lifts only once the landed feet are down; until then the policy
holds its command (`waiting`). It needs no simulator state.

A ditch the mechanism cannot cross gets no plan: `status` is "too_deep", "too_wide" or
"no_plan" (see `gait_plan.PLAN_STATUSES`), `reason` says why, and the policy holds the
standing pose instead of walking into the ditch.

Action modes: in ``"joint"`` mode the action is the command normalised over the actuator
ranges; in ``"residual"`` mode it is the action that moves the env's filtered residual
(observation piece ``residual_state``) toward the difference between the policy's command and
the env's reference gait (piece ``reference_action``). The reference is the same schedule, so
the action is zero while the gates pass on time. A wait at a gate puts the policy behind the
reference by more than the residual's few mm can make up, so use ``action_mode="joint"`` for
the full closed-loop behaviour.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from hexapod_envs.robots.upu.gait_plan import (
    Ditch,
    GaitPlan,
    GaitSettings,
    plan_ditch_crossing,
    plan_flat_past,
)
from hexapod_envs.robots.upu.gait_schedule import Checkpoint, GaitSchedule, GaitTiming
from hexapod_envs.robots.upu.params import LEG_NAMES

from .policy import EnvBound, ObservationReader

_LEG_INDEX = {leg: i for i, leg in enumerate(LEG_NAMES)}


class UpuGaitPolicy(EnvBound):
    """The paper's 3-3 gait planned for the env's ditch; `reset()`, `__call__(obs) -> action`.

    Args:
        env: a HexapodDitchCrossing-v0 env (wrapped or not); only public attributes are read.
        settings: planner settings (default: the env's `gait_settings`).
        timing: phase durations (default: the env's `gait_timing`, so that the policy plays the
            env's reference gait exactly when no gate has to wait).
    """

    def __init__(
        self,
        env: gym.Env,
        settings: GaitSettings | None = None,
        timing: GaitTiming | None = None,
    ):
        base = env.unwrapped
        task = getattr(base, "task_description", None)
        if task is None or "gait_settings" not in task.reference:
            raise ValueError(
                f"UpuGaitPolicy needs a HexapodDitchCrossing env; {type(base).__name__} declares "
                "no UPU gait in its task description"
            )
        if task.reference.get("stride_action"):
            raise ValueError(
                "UpuGaitPolicy plans every stride itself; an env with stride_action=True takes "
                "the strides as actions (make the env without it, in joint mode for the "
                "closed-loop gait)"
            )
        self.env = base
        self.task = task
        """The env's declared task description, read again on the first call of an episode."""
        self.settings = settings or task.reference["gait_settings"]
        self.timing = timing or task.reference["gait_timing"]
        self.read = ObservationReader(task.observation_structure)
        low, high = np.array(task.joint_low), np.array(task.joint_high)
        self._center = (low + high) / 2
        self._half = (high - low) / 2
        self._dtype = env.action_space.dtype
        self._planned_for: tuple | None = None
        self._cache: dict[tuple, tuple[GaitPlan, GaitSchedule]] = {}
        self._plan: GaitPlan | None = None
        self._schedule: GaitSchedule | None = None
        self.reset()

    # --- planning ----------------------------------------------------------------------
    def _course(self) -> tuple:
        """The episode's course from the env's task description (terrain, ditch, start x)."""
        self.task = task = self.env.task_description
        c = task.course
        geometry = (c["ditch_start_x"], c["ditch_width"], c["ditch_depth"])
        return (c["terrain"], *geometry, task.reference["start_x"], task.control_dt)

    def _ensure_plan(self) -> None:
        """Plan for the episode's course on the first call after reset() (the ditch geometry is
        sampled at env.reset(), which may come before or after this policy's reset())."""
        if self._planned_for is not None:
            return
        course = self._course()
        params = self.task.robot
        terrain, start_x, width, depth, x0, control_dt = course
        ditch = Ditch(start_x, width, depth)
        key = (course, self.settings)  # learned planner knobs change the settings per episode
        if key not in self._cache:
            if terrain == "flat":
                plan = plan_flat_past(params, ditch.end_x, x0, self.settings)
            else:
                plan = plan_ditch_crossing(params, ditch, x0, self.settings)
            if len(self._cache) >= 64:  # randomised ditches: keep the cache bounded
                self._cache.clear()
            self._cache[key] = (plan, GaitSchedule(plan, params, control_dt, self.timing))
        self._plan, self._schedule = self._cache[key]
        self._planned_for = course
        self.tick = 0

    @property
    def plan(self) -> GaitPlan:
        """The plan for the env's current course (made on first use after a change)."""
        self._ensure_plan()
        return self._plan

    @property
    def schedule(self) -> GaitSchedule:
        """The timed commands of `plan`."""
        self._ensure_plan()
        return self._schedule

    @property
    def status(self) -> str:
        """The planner's verdict: "ok", "too_deep", "too_wide" or "no_plan"."""
        return self.plan.status

    @property
    def reason(self) -> str:
        """Why the plan is what it is (number of steps, or what makes the ditch impassable)."""
        return self.plan.reason

    # --- the policy interface ----------------------------------------------------------
    def reset(self) -> None:
        self.tick = 0
        """Next row of the schedule to play."""
        self.waiting = False
        """True while the last call held its command at an unmet gate."""
        self.waits = 0
        """Control steps spent waiting at gates since reset()."""
        self._planned_for = None

    def _gate_met(self, gate: Checkpoint, contact: np.ndarray) -> bool:
        down = [bool(contact[_LEG_INDEX[leg]]) for leg in gate.legs]
        return all(down) if gate.state == "down" else not any(down)

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        sched = self.schedule
        obs = self.read(observation)
        contact = obs["foot_contact"] > 0.5
        gate = sched.gate(self.tick)
        self.waiting = gate is not None and not self._gate_met(gate, contact)
        if self.waiting:
            command = sched.command(self.tick - 1)  # hold (gates follow hold phases)
            self.waits += 1
        else:
            command = sched.command(self.tick)
            self.tick += 1
        if self.task.action_mode == "residual":
            ref = self.task.reference
            reference = self._center + self._half * obs["reference_action"]
            gain = np.array(ref["residual_gain"])
            current = obs["residual_state"] * gain
            # The env filters: r <- r + alpha (gain a - r); choose a so that r becomes the wanted
            # offset (as far as |a| <= 1 allows).
            wanted = current + (command - reference - current) / ref["residual_filter_alpha"]
            action = np.divide(wanted, gain, out=np.zeros_like(wanted), where=gain > 0)
        else:
            action = (command - self._center) / self._half
        return np.clip(action, -1.0, 1.0).astype(self._dtype)
