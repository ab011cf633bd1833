"""The sensors every robot model carries, added to its `MjSpec` when the model is built, under the
names `hexapod_envs.envs.sensors.RobotSensors` reads at run time.

- IMU on site ``imu``: ``imu_gyro`` (angular velocity), ``imu_accel`` (accelerometer) and
  ``imu_quat`` (orientation of the site's body).
- Per leg ``L``: a 3-D force sensor ``L_foot_force`` on site ``L_foot``, which must sit on a foot
  body attached to its leg without a joint, so the sensor measures the whole contact force.
"""

from __future__ import annotations

import mujoco

IMU_SENSORS: tuple[tuple[str, mujoco.mjtSensor], ...] = (
    ("imu_gyro", mujoco.mjtSensor.mjSENS_GYRO),
    ("imu_accel", mujoco.mjtSensor.mjSENS_ACCELEROMETER),
    ("imu_quat", mujoco.mjtSensor.mjSENS_FRAMEQUAT),
)


def add_imu_sensors(spec: mujoco.MjSpec, site: str = "imu") -> None:
    """Gyro, accelerometer and orientation sensors on `site`."""
    for name, kind in IMU_SENSORS:
        spec.add_sensor(name=name, type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site)


def add_foot_force_sensor(spec: mujoco.MjSpec, leg: str) -> None:
    """The 3-D force sensor ``{leg}_foot_force`` on the foot site ``{leg}_foot``."""
    spec.add_sensor(
        name=f"{leg}_foot_force",
        type=mujoco.mjtSensor.mjSENS_FORCE,
        objtype=mujoco.mjtObj.mjOBJ_SITE,
        objname=f"{leg}_foot",
    )
