"""ATHENA's tripod gait and posture controller (Coelho et al. 2024, Section 4), pure numpy.

It lives in the robot package because ``HexapodIrregularTerrain-v0`` runs it as the reference
gait of its "residual" and "gains" action modes (and `hexapod_envs` must not import `agents`);
`agents.athena_policy` wraps it as a policy.

Gait (Section 4.1). A tripod gait in phases of t_g = 1 s at 20 Hz: in each phase one tripod swings
along a cubic Bezier curve (eqs. 19-22, stride s, height h) while the other tripod's feet move
linearly backwards by s (eq. 23). All foot paths are in the body frame and start where the foot
is at the start of the phase (p_{i,0}, eq. 12 on the measured joint angles, or see `START_FROM`);
joint targets come from the analytic inverse kinematics.

Posture control (Section 4.2), evaluated at the start of every phase:
  1. contacts from the foot force sensors; the ground plane (eq. 24) through three feet in
     contact (exactly three normally; more -> choose three; fewer -> the legs that should be in
     contact are extended downwards until they touch, then the plane is fitted; see
     `GROUND_SEARCH` for when this search runs);
  2. pitch and roll of the torso relative to that plane, delta_alpha and delta_beta
     (eqs. 25-26), and the height deviation delta_z = torso-height reading - standing height;
  3. swing end point p_{i,3} = p_{i,0} + (s, 0, k_z delta_z) (eq. 27) and stance end point
     p_{i,f} = R_y(k_alpha delta_alpha) R_x(k_beta delta_beta) (p_{i,0} + (-s, 0, k_z delta_z))
     reached linearly (eqs. 28-31); k_z = k_alpha = k_beta = 0 is the paper's "simple control".
As the paper says, the controller needs only contact forces, joint angles and the torso height
(no IMU).

Reading of the garbled or ambiguous equations (all choices documented here, once):
  * Frames: the paper's stride axis is its y; ours is x (x forward, y left, z up), so the paper's
    (0, s, .) is our (s, 0, .) and its R_x (pitch, about the lateral axis) is our R_y.
  * Eq. (19) lacks the binomial coefficients and the normalisation by t_g^n; we use the standard
    cubic Bezier B(u) = sum_j C(3, j) (1-u)^(3-j) u^j p_j with u = t / t_g. With eqs. (20)-(21)'s
    control points at height h/3 the curve's apex is h/4 above the chord (`swing_apex`).
  * Eqs. (25)-(26) give unsigned angles (arccos); we use the signed angles of the plane normal g
    (body frame) projected on the x-z and y-z planes: delta_alpha = atan2(-g_x, g_z) (torso pitch
    relative to the ground, positive nose down, right-hand rule about y) and delta_beta =
    atan2(g_y, g_z) (roll relative to the ground, positive left side up). Rotating the stance feet
    by R_y(k delta_alpha) turns the torso by -k delta_alpha relative to the ground, so k = 1 makes
    the torso parallel to the estimated ground plane (the paper: with large k_alpha "the torso
    has the same inclination as the ground").
  * Eqs. (28)-(31): t_r is a transform; applied as a pure displacement it could not turn the
    torso, so we apply it to the foot position (rotation about the torso centre) and move the foot
    linearly from p_{i,0} to p_{i,f}.
  * "More than three legs in contact -> a random subset of three": with an `rng` we do exactly
    that (among non-degenerate triples); without one (default) we take the expected stance
    tripod if all three touch, else the contact triple with the largest support triangle, which
    is deterministic and never nearly collinear.
  * Start-up: the first phase moves half a stride, so that afterwards the feet oscillate
    symmetrically about the standing footholds (the paper does not say how it starts).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ...checks import check_number
from ...stability.plane_fit import fit_plane, plane_normal
from . import _compiled
from .kinematics import feet_closed_form, forward_kinematics_all, leg_ik
from .params import ATHENA, LEG_NAMES, TRIPODS, AthenaParams

START_FROM = ("measured", "commanded", "measured_height")
"""Choices of `AthenaPostureController(start_from=...)`. With compliant servos, "measured" makes
the stance feet, which lag behind their targets while they push the robot, start every phase a
little further forward: on the 10° ramp with 8 N·m/rad servos the feet wander by ~4 mm per cycle
in x until the legs reach their limits after ~15 cycles. "measured_height" keeps the paper's
measured heights (terrain following and the sag that the height control corrects) without that
horizontal drift."""

GROUND_SEARCH = ("auto", "always", "never")
"""Choices of `AthenaPostureController(ground_search=...)`: when the landing legs that found no
ground are extended until they touch. The paper describes this search as a step of the ground
plane estimate (Section 4.2, Fig. 6: "after that, there are sufficient supporting limbs to
estimate the terrain's characteristic plane"), and calls its baseline a "non-adaptive
controller" whose "foothold positions were not properly adjusted to the terrain topology"
(Sections 1 and 6). "auto" (default) therefore searches only in phases that use the plane, i.e.
with k_alpha or k_beta > 0, so that all gains 0 is the paper's simple control; "always" and
"never" force it on or off (with "always" and k = 0, legs that land early on a block push the
torso up and nothing lowers it again: the torso rides on the tallest blocks)."""

_TRIPOD_INDICES = tuple(tuple(LEG_NAMES.index(leg) for leg in tripod) for tripod in TRIPODS)
_TRIPOD_ROWS = tuple(np.array(tripod) for tripod in _TRIPOD_INDICES)
"""The tripods' rows as index arrays, shared by the phase plans (never written)."""
_MIN_TRIANGLE_AREA = 1e-4  # m², a triple of feet closer to collinear gives no usable plane


# ----- pure geometry (eqs. 19-31) ------------------------------------------------------------
def cubic_bezier(control_points: np.ndarray, u: float) -> np.ndarray:
    """Point of the cubic Bezier curve with (4, 3) `control_points` at u in [0, 1]."""
    p = np.asarray(control_points, dtype=float)
    v = 1.0 - u
    return v**3 * p[0] + 3 * v * v * u * p[1] + 3 * v * u * u * p[2] + u**3 * p[3]


def cubic_bezier_derivative(control_points: np.ndarray, u: float) -> np.ndarray:
    """dB/du of the cubic Bezier curve at u (divide by t_g for a velocity in m/s)."""
    p = np.asarray(control_points, dtype=float)
    v = 1.0 - u
    return 3 * (v * v * (p[1] - p[0]) + 2 * v * u * (p[2] - p[1]) + u * u * (p[3] - p[2]))


def swing_control_points(
    p0: np.ndarray, stride: float, height: float, height_correction: float = 0.0
) -> np.ndarray:
    """(4, 3) control points of eqs. (20)-(22) and (27) in our frame (stride along +x), m.

    `height_correction` is k_z delta_z of eq. (27): it moves only the end point.
    """
    p0 = np.asarray(p0, dtype=float)
    offsets = np.array(
        [
            [0.0, 0.0, 0.0],
            [stride / 4, 0.0, height / 3],
            [3 * stride / 4, 0.0, height / 3],
            [stride, 0.0, height_correction],
        ]
    )
    return p0 + offsets


def rotation_xyz(axis: str, angle: float) -> np.ndarray:
    """3x3 right-handed rotation about body axis `axis` ('x' or 'y') by `angle` rad."""
    c, s = math.cos(angle), math.sin(angle)
    if axis == "x":
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    if axis == "y":
        return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    raise ValueError(f"axis must be 'x' or 'y', got {axis!r}")


def posture_rotation(pitch: float, roll: float) -> np.ndarray:
    """R_y(pitch) R_x(roll): eq. (29)'s rotations in our frame (pitch about y, roll about x)."""
    return rotation_xyz("y", pitch) @ rotation_xyz("x", roll)


def stance_end_point(
    p0: np.ndarray, stride: float, height_correction: float, rotation: np.ndarray
) -> np.ndarray:
    """Eqs. (28)-(30): p_f = R (p0 + (-stride, 0, k_z delta_z)), body frame, m."""
    return np.asarray(rotation) @ (np.asarray(p0, dtype=float) + [-stride, 0.0, height_correction])


def torso_deviation_from_plane(normal: np.ndarray) -> tuple[float, float]:
    """(delta_alpha, delta_beta) of eqs. (25)-(26), signed, from the ground normal g in the body
    frame: torso pitch (positive nose down) and roll (positive left side up) relative to the
    plane, rad."""
    g = np.asarray(normal, dtype=float)
    if g[2] <= 0:
        raise ValueError(f"ground normal must point up in the body frame (g_z > 0), got {g}")
    return math.atan2(-g[0], g[2]), math.atan2(g[1], g[2])


def triangle_area_xy(points: np.ndarray) -> float:
    """Area of the triangle of three points projected on the body x-y plane, m²."""
    a, b, c = np.asarray(points, dtype=float)[:, :2]
    return 0.5 * abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


# ----- controller ------------------------------------------------------------------------------
@dataclass(frozen=True)
class AthenaSensors:
    """What the controller reads at each control tick (the paper's sensors).

    joint_angles: (6, 3) encoder angles, rows `LEG_NAMES`, columns (TC, CTr, FTi), rad.
    foot_forces: (6,) normal contact forces or (6, 3) force vectors (their norm is used), N.
    torso_height: infrared torso-height reading, m; NaN or negative means "no reading".
    """

    joint_angles: np.ndarray
    foot_forces: np.ndarray
    torso_height: float


@dataclass(frozen=True)
class PostureEstimate:
    """The posture controller's evaluation at the start of one phase (for logs and `info`)."""

    phase_index: int
    stance_legs: tuple[str, ...]
    contact_legs: tuple[str, ...]
    plane_legs: tuple[str, ...]
    """The three legs whose feet defined the ground plane (empty: no plane, no tilt correction)."""
    ground_normal: np.ndarray
    """Unit normal of the fitted ground plane in the body frame (+z if no plane)."""
    delta_pitch: float
    """delta_alpha, rad (positive: torso nose down relative to the ground)."""
    delta_roll: float
    """delta_beta, rad (positive: torso left side up relative to the ground)."""
    delta_z: float
    """Torso-height reading minus the standing reference, m (0 without a reading)."""
    gains: tuple[float, float, float]
    """(k_z, k_alpha, k_beta) used in this phase."""
    extension: float
    """How far the landing legs were extended to find the ground before this phase, m."""


@dataclass
class _Plan:
    """One phase's foot paths: Bezier control points of the swing legs, lines of the stance legs."""

    swing: np.ndarray  # rows of the swing legs
    swing_points: np.ndarray  # (3, 4, 3) control points per swing leg
    stance: np.ndarray  # rows of the stance legs
    stance_start: np.ndarray  # (3, 3) p_{i,0}
    stance_delta: np.ndarray  # (3, 3) p_{i,f} - p_{i,0}


class AthenaPostureController:
    """Coelho et al. 2024's tripod gait with height/pitch/roll posture control; joint targets at 20
    Hz.

    Call `step(sensors)` once per control tick; it returns (6, 3) joint-angle targets (rad,
    rows `LEG_NAMES`, columns TC, CTr, FTi) for the position servos. A phase lasts
    `phase_time` (t_g); the tripod {LF, LR, RM} swings first. Gains set with `set_gains` take
    effect at the start of the next phase (the env's "gains" action mode sets them once per gait
    cycle). Parameters (SI units):

    stride: s, foot travel per phase along body x, m (not given in the paper).
    swing_height: h of eqs. (20)-(21), m; the swing apex is h/4 (see `swing_apex`).
    phase_time: t_g, s. control_dt: control period, s (20 Hz in the paper).
    kz, k_alpha, k_beta: posture gains in [0, 1]; all 0 = "simple control".
    reference_height: torso-height reading of the standing posture, m (default from params).
    contact_threshold: force above which a foot counts as in contact, N.
    touchdown_wait: ticks to hold a landing leg that has not touched yet before extending it.
    extend_step: downward extension per tick of a landing leg that has not found the ground, m.
    max_extension: give up extending after this much, m.
    ground_search: when to extend landing legs that found no ground, one of `GROUND_SEARCH`.
    start_from: where each phase starts, p_{i,0}: "measured" (the paper: eq. 12 on the
        encoders), "commanded" (the previous phase's commanded end points, immune to servo
        tracking errors) or "measured_height" (x, y commanded, z measured: the feet follow the
        terrain and the servos' sag in height as with "measured", but the stride pattern does not
        wander horizontally with the servos' lag; see `START_FROM`).
    rng: optional generator; if given, the plane's three legs are a random choice among the
        feet in contact, as in the paper; otherwise deterministic (see the module docstring).
    """

    def __init__(
        self,
        params: AthenaParams = ATHENA,
        *,
        stride: float = 0.06,
        swing_height: float = 0.16,
        phase_time: float = 1.0,
        control_dt: float = 0.05,
        kz: float = 0.0,
        k_alpha: float = 0.0,
        k_beta: float = 0.0,
        reference_height: float | None = None,
        contact_threshold: float = 0.5,
        touchdown_wait: int = 1,
        extend_step: float = 0.002,
        max_extension: float = 0.06,
        start_from: str = "measured",
        ground_search: str = "auto",
        rng: np.random.Generator | None = None,
    ):
        ticks = phase_time / control_dt
        if control_dt <= 0 or phase_time <= 0 or abs(ticks - round(ticks)) > 1e-9 or ticks < 1:
            raise ValueError(
                f"phase_time / control_dt must be a positive whole number, got "
                f"{phase_time} / {control_dt} = {ticks}"
            )
        if start_from not in START_FROM:
            raise ValueError(f"start_from must be one of {START_FROM}, got {start_from!r}")
        if ground_search not in GROUND_SEARCH:
            raise ValueError(f"ground_search must be one of {GROUND_SEARCH}, got {ground_search!r}")
        for label, value in (
            ("stride", stride),
            ("swing_height", swing_height),
            ("contact_threshold", contact_threshold),
            ("touchdown_wait", touchdown_wait),
            ("extend_step", extend_step),
            ("max_extension", max_extension),
        ):
            check_number(label, value)
        if rng is not None and not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator or None, got {type(rng)}")
        self.params = params
        self.stride = float(stride)
        self.swing_height = float(swing_height)
        self.phase_time = float(phase_time)
        self.control_dt = float(control_dt)
        self.ticks_per_phase = round(ticks)
        self.reference_height = (
            params.standing_torso_height if reference_height is None else float(reference_height)
        )
        self.contact_threshold = float(contact_threshold)
        self.touchdown_wait = int(touchdown_wait)
        self.extend_step = float(extend_step)
        self.max_extension = float(max_extension)
        self.start_from = start_from
        self.ground_search = ground_search
        self.rng = rng
        self._ik_constants = np.array([leg_ik(leg, params).packed_constants for leg in LEG_NAMES])
        self._gains = _checked_gains(kz, k_alpha, k_beta)
        self.reset()

    # ----- public state -------------------------------------------------------------------
    @property
    def gains(self) -> tuple[float, float, float]:
        """(k_z, k_alpha, k_beta) that the next phase will use."""
        return self._gains

    @property
    def swing_apex(self) -> float:
        """Lift of the swing foot above its start at mid-swing for a level end point (k_z delta_z
        = 0): h/4 with eqs. (20)-(21)'s control points, m."""
        return self.swing_height / 4

    @property
    def ticks_per_cycle(self) -> int:
        """Control ticks of one gait cycle (both tripods swing once: 2 t_g)."""
        return 2 * self.ticks_per_phase

    @property
    def phase_index(self) -> int:
        """Number of phases started so far minus one (-1 before the first step)."""
        return self._phase_index

    @property
    def at_phase_start(self) -> bool:
        """True if the next `step` begins a new phase (and so uses newly set gains)."""
        return self._tick == 0

    @property
    def next_phase_index(self) -> int:
        """Index of the phase that the next `step` belongs to (a new one at a phase start)."""
        return self._phase_index + (1 if self._tick == 0 else 0)

    @property
    def at_cycle_start(self) -> bool:
        """True if the next `step` begins a gait cycle (a phase start with an even index).

        A gait cycle is two phases (each tripod swings once); cycle k holds phases 2k, 2k+1.
        """
        return self._tick == 0 and self.next_phase_index % 2 == 0

    @property
    def cycle_phase(self) -> float:
        """Position of the next `step` in its gait cycle, in [0, 1) (ticks / ticks per cycle)."""
        in_cycle = (self.next_phase_index % 2) * self.ticks_per_phase + self._tick
        return in_cycle / self.ticks_per_cycle

    @property
    def stance_legs(self) -> tuple[str, ...]:
        """Legs in stance in the current (or, at a phase start, the coming) phase."""
        return TRIPODS[(self._phase_index + (1 if self._tick == 0 else 0) + 1) % 2]

    @property
    def last_estimate(self) -> PostureEstimate | None:
        """The posture evaluation of the current phase (None before the first phase)."""
        return self._estimate

    @property
    def commanded_feet(self) -> np.ndarray:
        """(6, 3) foot positions (body frame, m) of the last command, before IK clamping."""
        return self._command.copy()

    def set_gains(self, kz: float, k_alpha: float, k_beta: float) -> None:
        """Set (k_z, k_alpha, k_beta) in [0, 1] for the next phase."""
        self._gains = _checked_gains(kz, k_alpha, k_beta)

    def reset(self, joint_angles: np.ndarray | None = None) -> None:
        """Start again from the standing posture (or `joint_angles`), before the first phase."""
        q = (
            np.tile(self.params.standing_posture, (6, 1))
            if joint_angles is None
            else np.asarray(joint_angles, dtype=float)
        )
        self._command = forward_kinematics_all(q, self.params)
        self._phase_index = -1
        self._tick = 0
        self._extension = 0.0
        self._waited = 0
        self._plan: _Plan | None = None
        self._estimate: PostureEstimate | None = None
        self.clamped_legs: tuple[str, ...] = ()

    # ----- the control tick ----------------------------------------------------------------
    def step(self, sensors: AthenaSensors) -> np.ndarray:
        """One control tick: (6, 3) joint-angle targets from the current sensor readings."""
        return self.step_readings(*_checked_sensors(sensors))

    def step_readings(self, q: np.ndarray, forces: np.ndarray, height: float) -> np.ndarray:
        """`step` on readings already in the checked form, for a caller that makes them so at
        every tick (the env): joint angles ``q`` (6, 3) [rad] and foot ``forces`` (6,) or (6, 3)
        [N] as float64 arrays, the torso ``height`` [m] a float. Nothing is checked here."""
        if self._tick == 0:  # forces only matter at a phase start
            forces = _normal_forces(forces)
            contact = forces > self.contact_threshold
            stance = _TRIPOD_INDICES[(self._phase_index + 2) % 2]
            missing = [i for i in stance if not contact[i]]
            if missing and self._searches_ground() and self._extension < self.max_extension:
                # Fewer legs on the ground than planned: extend them until they touch. The first
                # `touchdown_wait` ticks only hold the command, so that a foot lagging behind its
                # servo target lands without being pushed into the ground.
                self._waited += 1
                if self._waited > self.touchdown_wait:
                    step = min(self.extend_step, self.max_extension - self._extension)
                    self._extension += step
                    self._command[missing, 2] -= step
                return self._joint_targets()
            self._waited = 0
            self._begin_phase(q, contact, forces, height)
        u = (self._tick + 1) / self.ticks_per_phase
        plan = self._plan
        # cubic_bezier for the three swing legs, eq. (31)'s straight stance lines and the IK, in
        # one compiled call.
        angles, solved = _compiled.tick_legs(
            self._ik_constants,
            self._command,
            u,
            plan.swing,
            plan.swing_points,
            plan.stance,
            plan.stance_start,
            plan.stance_delta,
        )
        self._tick = (self._tick + 1) % self.ticks_per_phase
        return self._note_clamped(angles, solved)

    def _begin_phase(
        self, q: np.ndarray, contact: np.ndarray, forces: np.ndarray, height: float
    ) -> None:
        self._phase_index += 1
        stance_tripod = (self._phase_index + 1) % 2  # the other tripod swings
        stance = _TRIPOD_INDICES[stance_tripod]
        kz, ka, kb = self._gains
        if self.start_from == "commanded":
            start = self._command.copy()
        else:
            # Eq. (12) on the encoder angles (the closed form of the DH chain: same numbers).
            measured = feet_closed_form(q, self.params)
            if self.start_from == "measured":
                start = measured
            else:
                start = self._command.copy()
                start[:, 2] = measured[:, 2]
        plane_legs, normal, d_pitch, d_roll = self.ground_deviation(start, contact, stance)
        d_z = self.height_error(height)

        stride = self.stride / 2 if self._phase_index == 0 else self.stride
        rotation = posture_rotation(ka * d_pitch, kb * d_roll)
        swing_rows, stance_rows = _TRIPOD_ROWS[1 - stance_tripod], _TRIPOD_ROWS[stance_tripod]
        # swing_control_points and stance_end_point of each leg, in one compiled call.
        swing_points, stance_start, stance_delta = _compiled.phase_plan(
            start, swing_rows, stance_rows, stride, self.swing_height, kz * d_z, rotation
        )
        self._plan = _Plan(swing_rows, swing_points, stance_rows, stance_start, stance_delta)
        self._command = start.copy()
        self._estimate = PostureEstimate(
            phase_index=self._phase_index,
            stance_legs=tuple(LEG_NAMES[i] for i in stance),
            contact_legs=tuple(LEG_NAMES[i] for i in np.flatnonzero(contact)),
            plane_legs=tuple(LEG_NAMES[i] for i in plane_legs),
            ground_normal=np.asarray(normal, dtype=float),
            delta_pitch=d_pitch,
            delta_roll=d_roll,
            delta_z=d_z,
            gains=(kz, ka, kb),
            extension=self._extension,
        )
        self._extension = 0.0

    def ground_deviation(
        self, feet: np.ndarray, contact: np.ndarray, stance: tuple[int, ...]
    ) -> tuple[tuple[int, ...], np.ndarray, float, float]:
        """(plane legs, ground normal, delta_pitch, delta_roll [rad]) of eqs. (24)-(26): the
        plane through three of the body-frame `feet` (6, 3) [m] in `contact` (the `stance`
        tripod when all of it touches) and the torso's deviation from it; without a usable
        triple, no plane: legs (), normal (0, 0, 1), no deviation."""
        feet, contact = np.asarray(feet, dtype=float), np.asarray(contact, dtype=bool)
        if feet.shape != (6, 3) or contact.shape != (6,):  # the compiled search reads 6 rows
            raise ValueError(
                f"feet must have shape (6, 3) and contact (6,) (rows {LEG_NAMES}), got "
                f"{feet.shape} and {contact.shape}"
            )
        plane_legs = self._choose_plane_legs(feet, contact, stance)
        if not plane_legs:
            return (), np.array([0.0, 0.0, 1.0]), 0.0, 0.0
        points = feet[list(plane_legs)]
        normal = plane_normal(points)
        if normal is None:  # a degenerate stance tripod: fit_plane says why
            normal = fit_plane(points).normal
        d_pitch, d_roll = torso_deviation_from_plane(normal)
        return plane_legs, normal, d_pitch, d_roll

    def height_error(self, height: float) -> float:
        """The torso-height reading minus the standing reference [m] (the Δz that k_z scales);
        0 without a reading (NaN or negative)."""
        return height - self.reference_height if np.isfinite(height) and height >= 0 else 0.0

    def in_contact(self, forces: np.ndarray) -> np.ndarray:
        """(6,) which feet touch: force magnitude above `contact_threshold` [N]."""
        return _normal_forces(np.asarray(forces, dtype=float)) > self.contact_threshold

    def _searches_ground(self) -> bool:
        """Whether the coming phase extends landing legs that found no ground (`GROUND_SEARCH`)."""
        if self.ground_search == "auto":
            return self._gains[1] > 0 or self._gains[2] > 0
        return self.ground_search == "always"

    def _choose_plane_legs(
        self, feet: np.ndarray, contact: np.ndarray, stance: tuple[int, ...]
    ) -> tuple[int, ...]:
        """Indices of the three feet that define the ground plane (eq. 24), () if none."""
        if self.rng is None and all(contact[i] for i in stance):
            return tuple(stance)
        # Every triple of contact legs with a usable triangle (`triangle_area_xy`), compiled.
        triples, areas = _compiled.plane_triples(feet, contact, _MIN_TRIANGLE_AREA)
        if not len(areas):
            return ()
        if self.rng is not None:
            return tuple(triples[int(self.rng.integers(len(areas)))].tolist())
        return tuple(triples[int(np.argmax(areas))].tolist())  # the first of the largest

    def _joint_targets(self) -> np.ndarray:
        """IK of the commanded feet; unreachable points get the nearest reachable pose. The six
        legs are solved in one compiled call (`_compiled.solve_legs`, `LegIK.solve`'s
        arithmetic)."""
        return self._note_clamped(*_compiled.solve_legs(self._ik_constants, self._command))

    def _note_clamped(self, angles: np.ndarray, solved: np.ndarray) -> np.ndarray:
        """The compiled IK's `angles` (a leg it could not solve holds `LegIK.solve`'s clamped
        pose); `clamped_legs` names those legs."""
        self.clamped_legs = () if solved.all() else tuple(itertools.compress(LEG_NAMES, ~solved))
        return angles


def _checked_gains(kz: float, k_alpha: float, k_beta: float) -> tuple[float, float, float]:
    gains = (float(kz), float(k_alpha), float(k_beta))
    for label, value in zip(("kz", "k_alpha", "k_beta"), gains, strict=True):
        if not 0.0 <= value <= 1.0:
            raise ValueError(f"{label} must be in [0, 1], got {value}")
    return gains


def _checked_sensors(sensors: AthenaSensors) -> tuple[np.ndarray, np.ndarray, float]:
    """(joint angles (6, 3), foot forces (6,) or (6, 3) as given, torso height), validated."""
    q = np.asarray(sensors.joint_angles, dtype=float)
    if q.shape != (6, 3):
        raise ValueError(f"joint_angles must have shape (6, 3) (rows {LEG_NAMES}), got {q.shape}")
    f = np.asarray(sensors.foot_forces, dtype=float)
    if f.shape != (6, 3) and f.shape != (6,):
        raise ValueError(f"foot_forces must have shape (6,) or (6, 3), got {f.shape}")
    return q, f, float(sensors.torso_height)


def _normal_forces(f: np.ndarray) -> np.ndarray:
    """(6,) force magnitudes from validated (6,) or (6, 3) foot forces: the vectors' norms
    (np.linalg.norm(f, axis=1), computed without its wrapper)."""
    return np.sqrt(np.add.reduce(f * f, axis=1)) if f.ndim == 2 else f
