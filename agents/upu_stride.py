"""A stride rule for the ditch crossing's stride action: each platform step as long as it can be
while every moving foot lands clear of the ditch's edges.

`HexapodDitchCrossing-v1(stride_action=True)` builds its reference gait one platform step at a
time; the 10th action value sets each step's stride as it begins (read when the observation's
``stride_decision`` says so). `ClearStridePolicy` chooses it from the observation alone
(``ditch_ahead``: the edges relative to both platform centres, the depth; ``stride_decision``:
which platform moves next) and the robot's constants: the longest stride, on the grid of the
paper's planner, that lands every foot of the moving platform at least the planner's band (the
foot radius plus the edge clearance) from both edges; where none does, the one that lands them
farthest from an edge (with ``values``, among those stride values only: the choices of a
categorical learner, `hexapod_envs.wrappers.StrideChoices`). A ditch deeper than a leg reaches
is stepped over: no foot may land in it. The nine residuals stay 0. It crosses 19 of 20 training
and 18 of 20 test ditches of the benchmark (``experiments/ditch_stride``; among the five values
full, 80, 60, 40 and 20 % of it, 20 and 20), the paper's planner's strides 18 and 17, and it is a
function of the observation, which makes it a teacher for a learner's warm start
(`agents.warm_start`).
"""

from __future__ import annotations

from collections.abc import Sequence

import gymnasium as gym
import numpy as np

from hexapod_envs.envs.ditch_crossing import STRIDE_ACTION
from hexapod_envs.robots.upu.stride_clearance import StrideClearance

from .policy import ObservationReader


def stride_value(stride: float, max_stride: float) -> float:
    """The action value whose stride is `stride` [m] (0 for the full stride)."""
    return min(stride / max_stride - 1.0, 0.0)


class ClearStridePolicy:
    """The clear-stride rule (module docstring) as a `Policy` of a ditch-crossing env with
    ``stride_action=True``."""

    def __init__(self, env: gym.Env, values: Sequence[float] | None = None):
        base = env.unwrapped
        if not getattr(base, "stride_action", False):
            raise ValueError(
                "ClearStridePolicy chooses the stride action of HexapodDitchCrossing-v1 with "
                "stride_action=True; this env has no stride action"
            )
        self.env = base
        self.read = ObservationReader(base.observation_structure)
        self.geometry = StrideClearance.of(base.params, base.gait_settings)
        """Where each candidate stride lands the moving feet."""
        self.n_actions = base.action_space.shape[0]
        self.values = None if values is None else np.asarray(values, dtype=np.float64)
        if self.values is not None and not (
            self.values.ndim == 1 and self.values.size and np.all(np.abs(self.values + 0.5) <= 0.5)
        ):
            raise ValueError(f"stride values must be a non-empty list in [-1, 0], got {values!r}")
        """The stride values it chooses among (None: every stride on the planner's grid)."""

    def reset(self) -> None:
        pass

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        action = np.zeros(self.n_actions, dtype=np.float32)
        obs = self.read(observation)
        upper_next, decides = obs["stride_decision"] > 0.5
        if decides:
            action[STRIDE_ACTION] = self.stride(obs["ditch_ahead"], upper_next)
        return action

    def stride(self, ahead: np.ndarray, upper_next: bool) -> float:
        """The stride value for the platform about to move, from ``ditch_ahead``."""
        strides, clear = self.geometry.candidates(ahead, upper_next, self.values)
        band = self.geometry.band
        ok = np.flatnonzero(clear >= band)
        best = ok[np.argmax(strides[ok])] if ok.size else int(np.argmax(clear))
        return stride_value(float(strides[best]), self.geometry.max_stride)
