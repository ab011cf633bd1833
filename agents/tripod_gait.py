"""The reference tripod gait of Zhang et al. 2024 §5.1 as a policy for the heavy-duty hexapod envs.

It reads the gait clock from the observation's ``gait_phase`` piece (sin, cos, walking flag), so it
is a pure function of the observation and needs no state of its own.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from hexapod_envs.envs.actions import JointActionMap
from hexapod_envs.robots.heavy_duty.gait import TripodGait

from .policy import ObservationReader


class TripodGaitPolicy:
    """Walks the env's reference tripod gait in either action mode."""

    def __init__(self, env: gym.Env):
        base = env.unwrapped
        task = base.task_description  # what the env declares a controller may know
        self.action_mode = task.action_mode
        self.action_map = JointActionMap(np.column_stack([task.joint_low, task.joint_high]))
        self.read = ObservationReader(task.observation_structure)
        self.gait = TripodGait(task.robot, task.reference["gait"])
        self._steps = task.reference["steps_per_cycle"]
        self._zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)

    def reset(self) -> None:
        pass

    def phase(self, observation: np.ndarray) -> float:
        """Gait-clock phase in [0, 1), quantised to the control period."""
        s, c, _ = self.read(observation)["gait_phase"]
        phase = (np.arctan2(s, c) / (2 * np.pi)) % 1.0
        return (round(phase * self._steps) % self._steps) / self._steps

    def joint_targets(self, observation: np.ndarray) -> np.ndarray:
        return self.gait.joints_at_phase(self.phase(observation)).reshape(-1)

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        if self.action_mode == "residual":
            return self._zero.copy()
        action = self.action_map.to_action(self.joint_targets(observation))
        return action.astype(self._zero.dtype)
