"""The 3-3 gait of the 3-UPU hexapod (Li et al. 2018 §6-7) as a policy for HexapodDitchCrossing-v0.

The policy plans the walk the way the paper's robot does, knowing the ditch: it reads the
ditch geometry the env exposes (`env.unwrapped.ditch`, `terrain`, `start_x`; the robot's
`params`) and calls the planner of `hexapod_envs.robots.upu.gait_plan` (strides <= l_max1 =
160 mm, eq. 17; strides shortened so that no foot lands on a ditch edge; legs extended into
the ditch, §7). `hexapod_envs.robots.upu.gait_schedule` times the steps: the moving platform's
legs retract (lift), the platform travels along its quadratic path (eqs. 19-21), the legs
extend until the feet are down (land), and the platforms swap roles.

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

from .policy import ObservationReader

_LEG_INDEX = {leg: i for i, leg in enumerate(LEG_NAMES)}


class UpuGaitPolicy:
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
        for name in ("ditch", "terrain", "start_x", "params", "command_low", "command_high"):
            if not hasattr(base, name):
                raise ValueError(
                    f"UpuGaitPolicy needs a HexapodDitchCrossing env; {type(base).__name__} has "
                    f"no attribute {name!r}"
                )
        self.env = base
        self.settings = settings or base.gait_settings
        self.timing = timing or base.gait_timing
        self.read = ObservationReader(base.observation_structure)
        self._center = (base.command_low + base.command_high) / 2
        self._half = (base.command_high - base.command_low) / 2
        self._dtype = env.action_space.dtype
        self._planned_for: tuple | None = None
        self._cache: dict[tuple, tuple[GaitPlan, GaitSchedule]] = {}
        self._plan: GaitPlan | None = None
        self._schedule: GaitSchedule | None = None
        self.reset()

    # --- planning ----------------------------------------------------------------------
    def _course(self) -> tuple:
        e = self.env
        d = e.ditch
        return (e.terrain, d.start_x, d.width, d.depth, e.start_x, e.control_dt)

    def _ensure_plan(self) -> None:
        """(Re)plan when the env's course differs from the one planned for (ditch geometry is
        sampled at env.reset(), which may come before or after this policy's reset())."""
        course = self._course()
        if course == self._planned_for:
            return
        e = self.env
        terrain, start_x, width, depth, x0, control_dt = course
        ditch = Ditch(start_x, width, depth)
        if course not in self._cache:
            if terrain == "flat":
                plan = plan_flat_past(e.params, ditch.end_x, x0, self.settings)
            else:
                plan = plan_ditch_crossing(e.params, ditch, x0, self.settings)
            if len(self._cache) >= 64:  # randomised ditches: keep the cache bounded
                self._cache.clear()
            self._cache[course] = (plan, GaitSchedule(plan, e.params, control_dt, self.timing))
        self._plan, self._schedule = self._cache[course]
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
        if self.env.action_mode == "residual":
            e = self.env
            reference = self._center + self._half * obs["reference_action"]
            gain = e.residual_gain
            current = obs["residual_state"] * gain
            # The env filters: r <- r + alpha (gain a - r); choose a so that r becomes the wanted
            # offset (as far as |a| <= 1 allows).
            wanted = current + (command - reference - current) / e.residual_filter_alpha
            action = np.divide(wanted, gain, out=np.zeros_like(wanted), where=gain > 0)
        else:
            action = (command - self._center) / self._half
        return np.clip(action, -1.0, 1.0).astype(self._dtype)
