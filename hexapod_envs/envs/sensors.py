"""Named accessors for what a real hexapod measures: joint encoders, 3-D foot force sensors, IMU.

Every robot follows the same naming contract (see robots/*/model.py): per leg `L` a force sensor
`L_foot_force` on site `L_foot`, actuators named after their joints, and IMU sensors `imu_gyro`,
`imu_accel`, `imu_quat`. Addresses and views of the data's arrays are resolved once; reading
is a few array copies, and the per-step measurements and the observation's sensor pieces are
one compiled call each.
"""

from __future__ import annotations

from typing import NamedTuple

import mujoco
import numpy as np

from hexapod_envs.envs import _compiled
from hexapod_envs.stability import _compiled as _stability
from hexapod_envs.stability.zmp import DEFAULT_MIN_FORCE


def _sensor_slice(model: mujoco.MjModel, name: str) -> slice:
    sid = model.sensor(name).id
    adr, dim = model.sensor_adr[sid], model.sensor_dim[sid]
    return slice(adr, adr + dim)


class SupportReading(NamedTuple):
    """What an env derives from the feet's sensors each step (see RobotSensors.support). The
    arrays are the sensors' buffers, overwritten by the next `support` call: copy to keep."""

    forces: np.ndarray
    """(n_legs, 3) ground reaction on each foot, world frame [N]."""
    loaded: np.ndarray
    """(n_legs,) the foot's force exceeds the contact threshold."""
    cog: np.ndarray
    """(3,) whole-robot centre of gravity, world frame [m]."""
    fasm_deg: float
    """FASM over the loaded feet [deg]; 0 without a support polygon."""
    fasm_edge: tuple[int, int] | None
    """Its edge as leg indices, None without a support polygon."""
    power: float
    """Σ |actuator force x actuator velocity| [W]."""


class RobotSensors:
    """Reads one robot's sensors from `data` (foot forces in the world frame, SI units)."""

    OBSERVED = (
        "joint_pos",
        "joint_vel",
        "foot_force",
        "foot_contact",
        "fasm_margin_deg",
        "imu_gyro",
        "imu_accel",
        "imu_quat",
    )
    """The observation pieces `write_observation` fills, in this order (sizes:
    `observed_sizes`)."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        legs: tuple[str, ...],
        actuators: tuple[str, ...],
        torso: str = "torso",
    ):
        self.model, self.data, self.legs = model, data, legs
        self.n_legs = len(legs)
        force_adr = [model.sensor_adr[model.sensor(f"{leg}_foot_force").id] for leg in legs]
        self._force_idx = np.array([[a, a + 1, a + 2] for a in force_adr])
        self._foot_site = np.array([model.site(f"{leg}_foot").id for leg in legs])
        self._act = np.array([model.actuator(name).id for name in actuators])
        self._gyro = _sensor_slice(model, "imu_gyro")
        self._accel = _sensor_slice(model, "imu_accel")
        self._quat = _sensor_slice(model, "imu_quat")
        self._imu = np.concatenate(
            [np.arange(sl.start, sl.stop) for sl in (self._gyro, self._accel, self._quat)]
        )
        self.torso_id = model.body(torso).id
        # `support`'s output buffers and scratch, reused every step.
        self._forces = np.empty((self.n_legs, 3))
        self._loaded = np.empty(self.n_legs, dtype=bool)
        self._cog = np.empty(3)
        self._feet = np.empty((self.n_legs, 3))
        self._bind_views()

    def _bind_views(self) -> None:
        """Views of `data`'s arrays that the compiled calls read, built once: MjData's buffers
        never move, and building a view per call costs more than some calls' arithmetic. Their
        names are kept in `_view_names` (a deep or unpickled copy rebinds them)."""
        d = self.data
        views = {
            "_sensordata": d.sensordata,
            "_site_xmat": d.site_xmat,
            "_site_xpos": d.site_xpos,
            "_subtree_com": d.subtree_com,
            "_actuator_length": d.actuator_length,
            "_actuator_velocity": d.actuator_velocity,
            "_actuator_force": d.actuator_force,
            "_torso_xpos": d.xpos[self.torso_id],
            "_torso_xmat": d.xmat[self.torso_id],
            "_torso_up": d.xmat[self.torso_id, 2::3],
        }
        self.__dict__.update(views)
        self._view_names = frozenset(views)

    def __getstate__(self) -> dict:
        """The state without the views of `data`: a deep copy or an unpickled copy rebinds
        them to its own data (copied as views, they would be arrays frozen at the copy)."""
        return {k: v for k, v in self.__dict__.items() if k not in self._view_names}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._bind_views()

    # --- encoders -------------------------------------------------------------------------
    def joint_positions(self) -> np.ndarray:
        """Actuator-side joint positions (the robot's joint units), actuator order."""
        return self._actuator_length[self._act]

    def joint_velocities(self) -> np.ndarray:
        return self._actuator_velocity[self._act]

    def actuator_forces(self) -> np.ndarray:
        return self._actuator_force[self._act]

    # --- feet -----------------------------------------------------------------------------
    def foot_forces(self) -> np.ndarray:
        """(n_legs, 3) ground reaction force on each foot, world frame [N].

        MuJoCo's force sensor reports, in the site frame, the force the parent exerts on the foot
        body; with a light foot that is minus the ground reaction.
        """
        local = self._sensordata[self._force_idx]
        rot = self._site_xmat[self._foot_site].reshape(-1, 3, 3)
        return -(rot @ local[:, :, None])[:, :, 0]

    def support(self, contact_force_sq: float) -> SupportReading:
        """Foot forces, contacts (|f|² > ``contact_force_sq`` [N²]), CoG, FASM and actuator power
        in one compiled call: the arithmetic of `foot_forces`, `cog`, `foot_positions`,
        `hexapod_envs.stability.fasm_from_feet` and Σ|F v| (see hexapod_envs.envs._compiled).
        The reading's arrays are this object's buffers, overwritten by the next call; they are
        also the env's measurements of the step, so a call from outside the env's step (with
        another threshold, say) changes what the env reports for that step."""
        forces, loaded, cog = self._forces, self._loaded, self._cog
        status, margin, i, j, power = _compiled.heavy_duty_measure(
            self._sensordata,
            self._force_idx,
            self._site_xmat,
            self._site_xpos,
            self._foot_site,
            self._subtree_com,
            self.torso_id,
            self._actuator_force,
            self._actuator_velocity,
            self._act,
            contact_force_sq,
            forces,
            loaded,
            cog,
            self._feet,
        )
        if status == _stability.NOT_FINITE:
            raise ValueError("foot forces, feet or CoG contain NaN or infinite values")
        edge = (i, j) if status == _stability.OK else None
        return SupportReading(forces, loaded, cog, margin, edge, power)

    def observed_sizes(self) -> dict[str, int]:
        """Name -> size of the observation pieces `write_observation` fills (`OBSERVED`)."""
        n_act, n_legs = len(self._act), self.n_legs
        sizes = (n_act, n_act, 3 * n_legs, n_legs, 1, 3, 3, 4)
        return dict(zip(self.OBSERVED, sizes, strict=True))

    def write_observation(
        self, out: np.ndarray, forces: np.ndarray, loaded: np.ndarray, fasm_deg: float
    ) -> None:
        """Fill `out` (size: the sum of `observed_sizes`) with the `OBSERVED` pieces in one
        compiled call: `joint_positions`, `joint_velocities`, the measured foot `forces`
        (n_legs, 3) [N] row by row, the `loaded` flags as 0 / 1, `fasm_deg` and `gyro`,
        `accelerometer`, `orientation`."""
        _compiled.sensor_observation(
            out,
            self._actuator_length,
            self._actuator_velocity,
            self._act,
            forces,
            loaded,
            fasm_deg,
            self._sensordata,
            self._imu,
        )

    def torso_frame_zmp(
        self, forces: np.ndarray, loaded: np.ndarray, min_force: float = DEFAULT_MIN_FORCE
    ) -> tuple[np.ndarray, float]:
        """The ZMP estimate (2,) [m] and its margin [m] in the torso frame (Coelho et al. 2024
        eqs. 32-33, the paper's relative foot coordinates): the `loaded` feet weighted by the
        vertical component of their world-frame ground reaction `forces` (n_legs, 3) [N]
        (clipped at 0). One compiled call with the arithmetic of
        ``(foot_positions() - torso_position()) @ torso_rotation()`` and
        `hexapod_envs.stability.zmp_margin`; NaN and 0 without a loaded foot."""
        return _compiled.torso_frame_zmp(
            self._site_xpos,
            self._foot_site,
            self._torso_xpos,
            self._torso_xmat,
            forces,
            loaded,
            min_force,
        )

    def foot_positions(self) -> np.ndarray:
        """(n_legs, 3) foot (sole) points in the world frame [m] (FK of the encoders + IMU)."""
        return self._site_xpos[self._foot_site]

    # --- body -----------------------------------------------------------------------------
    def gyro(self) -> np.ndarray:
        return self._sensordata[self._gyro]

    def accelerometer(self) -> np.ndarray:
        return self._sensordata[self._accel]

    def orientation(self) -> np.ndarray:
        """Torso orientation quaternion (w, x, y, z), world frame."""
        return self._sensordata[self._quat]

    def torso_rotation(self) -> np.ndarray:
        """3x3 rotation matrix body -> world."""
        return self._torso_xmat.reshape(3, 3)

    def torso_up(self) -> np.ndarray:
        """(3,) the torso's up axis in the world frame (a view: read it before the next step)."""
        return self._torso_up

    def tilt_cos(self) -> float:
        """Cosine of the torso's tilt from vertical: the world z component of its up axis."""
        return float(self._torso_up[2])

    def cog(self) -> np.ndarray:
        """Whole-robot centre of gravity, world frame [m]: what the kinematic model computes from
        the known link masses and the encoders."""
        return self._subtree_com[self.torso_id]

    def torso_position(self) -> np.ndarray:
        return self._torso_xpos
