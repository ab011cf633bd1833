"""The joint action map: normalised actions in [-1, 1] to joint targets and back."""

from __future__ import annotations

import numpy as np

__all__ = ["JointActionMap"]


class JointActionMap:
    """Maps normalised actions in [-1, 1] to joint targets in the robot's units and back."""

    def __init__(self, ranges: np.ndarray):
        ranges = np.asarray(ranges, dtype=float)
        self.low, self.high = ranges[:, 0], ranges[:, 1]
        self.center = (self.low + self.high) / 2
        self.half = (self.high - self.low) / 2

    def to_joints(self, action: np.ndarray) -> np.ndarray:
        return self.center + self.half * np.asarray(action)

    def to_action(self, joints: np.ndarray) -> np.ndarray:
        return np.clip((np.asarray(joints).reshape(-1) - self.center) / self.half, -1.0, 1.0)
