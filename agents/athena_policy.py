"""Coelho et al. 2024's tripod gait with posture control as a policy for
``HexapodIrregularTerrain-v0``.

`AthenaPosturePolicy(env, kz=..., ka=..., kb=...)` is the analytical controller of the env, in
any of its action modes, reading the observation by name (``joint_pos``, ``foot_force``,
``torso_height``) through the layout of the env's task description
(``env.unwrapped.task_description.observation_structure``):

- ``"gains"``: the env runs the controller itself; the policy just returns (k_z, k_α, k_β)
  (and a zero torso-height offset where the env has that fourth action: the standing height).
- ``"joint"``: the policy runs its own `AthenaPostureController` (same gait settings as the
  env, from the task description's ``reference["gait_config"]``) on the observed sensors and
  returns its joint targets, normalised to the action space.
- ``"residual"``: the env adds the action to its own reference gait (the same controller with the
  env's ``reference_gains``). The policy runs two controllers on the same observations, one with
  its gains and one with the env's reference gains, and returns the difference of their targets
  in residual units. Both are deterministic functions of the observations, so the reference
  copy reproduces the env's exactly; with equal gains the action is zero. This is exact only
  while the two targets differ by less than the residual range (``residual_scale`` x half
  range); on the blocks the posture gains move the feet further and the env clips the action,
  so use the "gains" or "joint" mode to run the paper's controller there.

k_z = k_α = k_β = 0 is the paper's "simple control".
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from hexapod_envs.envs.actions import JointActionMap
from hexapod_envs.robots.athena.gait import AthenaPostureController, AthenaSensors

from .policy import ObservationReader


class AthenaPosturePolicy:
    """The posture controller of Coelho et al. 2024 with gains (k_z, k_α, k_β) in [0, 1]."""

    def __init__(self, env: gym.Env, kz: float = 0.0, ka: float = 0.0, kb: float = 0.0):
        task = env.unwrapped.task_description  # what the env declares a controller may know
        ref = task.reference
        self.action_mode = task.action_mode
        self.read = ObservationReader(task.observation_structure)
        self.gains = (float(kz), float(ka), float(kb))
        self._dtype = env.action_space.dtype
        self._height_offset = (
            (0.0,) * (env.action_space.shape[0] - 3) if task.action_mode == "gains" else ()
        )
        self.action_map = JointActionMap(np.column_stack([task.joint_low, task.joint_high]))
        # Validates the gains (ValueError outside [0, 1]) in every mode.
        self.controller = AthenaPostureController(
            task.robot, **ref["gait_config"], kz=kz, k_alpha=ka, k_beta=kb
        )
        self.reference = None
        if self.action_mode == "residual":
            kz0, ka0, kb0 = ref["reference_gains"]
            self.reference = AthenaPostureController(
                task.robot, **ref["gait_config"], kz=kz0, k_alpha=ka0, k_beta=kb0
            )
            self._residual_gain = ref["residual_scale"] * self.action_map.half

    def reset(self) -> None:
        self.controller.reset()
        if self.reference is not None:
            self.reference.reset()

    def sensors(self, observation: np.ndarray) -> AthenaSensors:
        """The controller's inputs (the paper's sensors) read from the observation by name."""
        obs = self.read(observation)
        return AthenaSensors(
            joint_angles=obs["joint_pos"].reshape(6, 3),
            foot_forces=obs["foot_force"].reshape(6, 3),
            torso_height=float(obs["torso_height"][0]),
        )

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        if self.action_mode == "gains":
            return np.array(self.gains + self._height_offset, dtype=self._dtype)
        sensors = self.sensors(observation)
        targets = self.controller.step(sensors).reshape(-1)
        if self.action_mode == "joint":
            return self.action_map.to_action(targets).astype(self._dtype)
        reference = self.reference.step(sensors).reshape(-1)
        return ((targets - reference) / self._residual_gain).astype(self._dtype)


def simple_control(env: gym.Env) -> AthenaPosturePolicy:
    """The paper's "simple control": the gait without posture correction (all gains 0)."""
    return AthenaPosturePolicy(env)


def ramp_posture_control(env: gym.Env) -> AthenaPosturePolicy:
    """The paper's gains for the ramp (Section 5.2.3): (k_z, k_α, k_β) = (0.8, 0.6, 0.0)."""
    return AthenaPosturePolicy(env, kz=0.8, ka=0.6, kb=0.0)


def blocks_posture_control(env: gym.Env) -> AthenaPosturePolicy:
    """The paper's gains for the irregular terrain: (k_z, k_α, k_β) = (0.6, 0.4, 0.4)."""
    return AthenaPosturePolicy(env, kz=0.6, ka=0.4, kb=0.4)


PAPER_GAINS = {"ramp": (0.8, 0.6, 0.0), "blocks": (0.6, 0.4, 0.4), "flat": (0.0, 0.0, 0.0)}
"""The paper's tuned gains per terrain (flat ground: no correction needed)."""


def analytical_policy(env: gym.Env) -> AthenaPosturePolicy:
    """The registry's analytical controller: the paper's tuned gains for the env's terrain."""
    kz, ka, kb = PAPER_GAINS[env.unwrapped.task_description.reference["terrain"]]
    return AthenaPosturePolicy(env, kz=kz, ka=ka, kb=kb)
