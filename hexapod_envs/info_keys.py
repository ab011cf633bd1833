"""The `info` keys every hexapod env returns (from `reset` and every `step`), shared by the envs,
the evaluation pipeline and the tests, so that one list says what a consumer may rely on.

Env-specific keys (platform tilt, ZMP, planner status, ...) are documented in each env's module
docstring; the keys below are common to all four envs.
"""

from __future__ import annotations

FASM_MARGIN_DEG = "fasm_margin_deg"
"""Force-angle stability margin from the measured foot forces [deg]; 0 without a support
polygon (fewer than three loaded feet, or collinear ones), never NaN."""
FASM_EDGE = "fasm_edge"
"""(leg, leg): the support-polygon edge that sets the FASM, or None without a polygon."""
STANCE_LEGS = "stance_legs"
"""Tuple of the leg names whose foot carries more than the contact threshold."""
IS_TIPPING = "is_tipping"
"""True while the stability criterion fails (`env.unwrapped.stability_criterion`, e.g. FASM
below the robot's `tipping_threshold_deg`)."""
IS_TIPPED_OVER = "is_tipped_over"
"""True from the step the body leaned past the env's tip-over angle (sticky for the episode)."""
IS_SUCCESS = "is_success"
"""The env's success rule (see the env's docstring), False on an unstable simulation."""
SIM_UNSTABLE = "sim_unstable"
"""True when MuJoCo met a numerical problem (bad qacc/qvel/qpos/ctrl warning or a reset clock);
the step is then truncated with reward 0 and the last good observation."""
TIME = "time"
"""Episode time [s] (the settle phase in reset is not counted)."""
COG = "cog"
"""Centre of mass of the robot, world frame [m] (a fresh array every step)."""
DISTANCE = "distance"
"""CoG travel along +x since reset [m]."""
ACTUATOR_POWER_W = "actuator_power_w"
"""Sum over the actuators of |force x velocity| [W] (mechanical power the servos deliver or
absorb)."""
TASK = "task"
"""Flat dict of the episode's task parameters (plain floats, ints, strings): the paper
scenario's values with ``task_distribution="paper"``, the sampled ones with "train"/"test"."""

TILT_DEG = "tilt_deg"
"""The body's tilt now [deg]: the angle between its up axis and the vertical (on the Stewart
platform: the platform's up axis), the quantity of the tip-over angle."""
MAX_TILT_DEG = "max_tilt_deg"
"""The largest `tilt_deg` of the episode so far [deg] (a safety figure of the success rule)."""
TIPPING_TIME_S = "tipping_time_s"
"""Episode time so far during which the stability criterion failed (`is_tipping`) [s]."""
TIPPING_SHARE = "tipping_share"
"""`tipping_time_s` over the episode time so far (0 at reset): the share of the episode spent
tipping, the other safety figure of the success rule."""

COMMON_INFO_KEYS: tuple[str, ...] = (
    FASM_MARGIN_DEG,
    FASM_EDGE,
    STANCE_LEGS,
    IS_TIPPING,
    IS_TIPPED_OVER,
    IS_SUCCESS,
    SIM_UNSTABLE,
    TIME,
    COG,
    DISTANCE,
    ACTUATOR_POWER_W,
    TASK,
    TILT_DEG,
    MAX_TILT_DEG,
    TIPPING_TIME_S,
    TIPPING_SHARE,
)
"""Keys present in the info of every reset and step of every hexapod env."""

UNDEFINED_AS_NAN: tuple[str, ...] = ("zmp",)
"""Env-specific keys that are NaN by contract when undefined (the ZMP of HexapodIrregularTerrain
with no loaded foot); every other numeric info value is finite (e.g. ``zmp_margin`` is 0 then,
like ``fasm_margin_deg`` without a support polygon)."""

REWARD_PREFIX = "reward_"
"""Each reward term is reported as ``info["reward_<term>"]``; the reward is their sum."""
