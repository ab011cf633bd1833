"""Gait-planning math of the 3-UPU hexapod's "3-3" gait (Li et al. 2018 §5-7), pure numpy.

The robot walks by moving one platform while the other stands on its three legs (duty factor
0.5, Fig. 6-7): stage I the upper platform lifts its legs, travels forward along a quadratic
path (eq. 19) and lands; stage II the lower platform does the same. This module plans those
steps: platform paths, stride limits (eq. 17), the static stability margin of the CoG
projection in the support triangle (eqs. 12-14), and a ditch-crossing planner that shortens
steps so that no foot lands on a ditch edge and extends legs into the ditch (§7, Fig. 13-14).
It knows nothing about MuJoCo or the env; `gait_schedule.GaitSchedule` turns a `GaitPlan` into
timed commands (limb lengths from the step's path, leg extensions from the step's fields) for
the env's reference gait and for `agents.upu_gait.UpuGaitPolicy`.

Conventions: SI units; world x forward along the walk, both platform centres stay on y = 0;
"extension" of a leg is its length beyond nominal (+ = longer, foot lower; see
`hexapod_envs.robots.upu.params`). Flat ground is at z = 0 and a ditch lowers it to -depth.

Deviation from the paper, stated once: eq. (21) moves the lower platform through
(-80, -283) mm relative to the upper one, which needs limb 1 = 305 mm < l_min = 365 mm (the
initial height 363 mm is already the bottom of the workspace on the z axis). So the lower
platform cannot rise relative to the upper; in stage II it travels at constant relative height
and its feet clear the ground by retracting the legs (`GaitSettings.lower_swing_retract`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ...checks import check_number
from ...stability import static_stability_margin
from ._compiled import fewest_steps
from .kinematics import inside_limits, inverse_kinematics
from .params import PLATFORM_LEGS, UpuParams, check_platform

PLAN_STATUSES: tuple[str, ...] = ("ok", "too_deep", "too_wide", "no_plan")
"""`GaitPlan.status` values: "too_deep": the bottom is beyond the legs' reach (depth >
`UpuParams.leg_extend`), so every foot must step over the ditch, and it is too wide for that;
"too_wide": the bottom is within reach but too narrow for a foot with its edge clearance, and
the ditch is too wide to step over; "no_plan": the search found no step sequence for another
reason (see `GaitPlan.reason`). A flat-bottomed ditch whose bottom is within reach is crossable
at any width (the robot walks through it, legs extended), so width alone never fails."""


# --- Paths and limits -----------------------------------------------------------------------
@dataclass(frozen=True)
class QuadraticPath:
    """Platform path z = a x^2 + b x + c (eq. 19) from x_start to x_end [m]."""

    a: float
    """[1/m]"""
    b: float
    """[-]"""
    c: float
    """[m]"""
    x_start: float
    x_end: float

    @classmethod
    def through(cls, start, apex, end) -> QuadraticPath:
        """The parabola through three (x, z) points [m] (eqs. 20-21 use start, apex, end)."""
        pts = np.array([start, apex, end], dtype=float)
        if pts.shape != (3, 2) or not np.all(np.isfinite(pts)):
            raise ValueError(f"start, apex, end must be finite (x, z) pairs [m], got {pts}")
        if len(set(pts[:, 0].tolist())) < 3:
            raise ValueError(f"the three points need distinct x values, got {pts[:, 0]}")
        a, b, c = np.linalg.solve(np.vander(pts[:, 0], 3), pts[:, 1])
        return cls(float(a), float(b), float(c), float(pts[0, 0]), float(pts[2, 0]))

    def z(self, x):
        """Path height at `x` [m] (scalar or array)."""
        x = np.asarray(x, dtype=float)
        return self.a * x**2 + self.b * x + self.c

    def sample(self, n: int = 21) -> np.ndarray:
        """(n, 2) evenly spaced (x, z) points from start to end [m]."""
        x = np.linspace(self.x_start, self.x_end, n)
        return np.stack([x, self.z(x)], axis=-1)


def step_path(x_start: float, x_end: float, height: float, lift: float) -> QuadraticPath:
    """Symmetric step: from (x_start, height) over the apex (midpoint, height + lift) to
    (x_end, height) [m]. lift = 0 gives the straight path at constant height."""
    if lift == 0:
        return QuadraticPath(0.0, 0.0, float(height), float(x_start), float(x_end))
    mid = (x_start + x_end) / 2
    return QuadraticPath.through((x_start, height), (mid, height + lift), (x_end, height))


def case_study_path(params: UpuParams | None = None) -> QuadraticPath:
    """Eq. (20): the upper platform from (0, 363) via (80, 443) to (160, 363) mm, in metres:
    z = -12.5 x^2 + 2 x + 0.363 (= -0.0125 x^2 + 2 x + 363 in mm)."""
    p = params or UpuParams()
    return step_path(
        0.0, max_stride(p.support_inradius, p.leg_radius), p.initial_height, p.step_lift
    )


def max_stride(support_inradius: float, leg_radius: float) -> float:
    """Eq. (17): l_max1 = 2 (x_G3 - R_T) [m], moving along x toward a triangle side.

    `support_inradius` is the paper's x_G3 = OJ, the distance from a platform centre to the
    side of its support triangle; `leg_radius` is R_T. Paper: 160 mm.
    """
    if not support_inradius > leg_radius > 0:
        raise ValueError(
            f"need support_inradius > leg_radius > 0 [m], got {support_inradius}, {leg_radius}"
        )
    return 2.0 * (support_inradius - leg_radius)


def max_stride_diagonal(support_inradius: float, leg_radius: float) -> float:
    """Eq. (18): l_max2 = x_G3 - R_T [m], moving along a triangle's side direction (LH)."""
    return max_stride(support_inradius, leg_radius) / 2


# --- Centre of gravity and static margin ----------------------------------------------------
def combined_cog(upper_cog, lower_cog, upper_mass: float, lower_mass: float) -> np.ndarray:
    """G3 on the segment G1 G2 (eqs. 12-13): (m1 G1 + m2 G2) / (m1 + m2) [m]."""
    if not (upper_mass > 0 and lower_mass > 0):
        raise ValueError(f"masses must be > 0 kg, got {upper_mass}, {lower_mass}")
    g1 = np.asarray(upper_cog, dtype=float)
    g2 = np.asarray(lower_cog, dtype=float)
    return (upper_mass * g1 + lower_mass * g2) / (upper_mass + lower_mass)


def foot_positions(params: UpuParams, x_upper: float, x_lower: float, legs=None):
    """Leg name -> (x, y) of its foot [m] for platform centres at world x_upper, x_lower."""
    legs = PLATFORM_LEGS["upper"] + PLATFORM_LEGS["lower"] if legs is None else legs
    out = {}
    for leg in legs:
        centre = x_upper if leg in PLATFORM_LEGS["upper"] else x_lower
        out[leg] = np.array([centre, 0.0]) + params.foot_offset(leg)
    return out


def support_margin(feet_xy, cog_xy) -> float:
    """Static stability margin d = min_i d_i (eq. 14 and Fig. 5) [m]: distance from the CoG
    projection to the nearest side of the support polygon, negative outside.

    Uses `hexapod_envs.stability.static_stability_margin` with gravity along -z.
    """
    feet = np.asarray(feet_xy, dtype=float)
    if feet.ndim != 2 or feet.shape[1] != 2:
        raise ValueError(f"feet_xy must have shape (k, 2) [m], got {feet.shape}")
    feet3 = np.column_stack([feet, np.zeros(len(feet))])
    cog = np.asarray(cog_xy, dtype=float)
    if cog.shape != (2,):
        raise ValueError(f"cog_xy must have shape (2,) [m], got {cog.shape}")
    return static_stability_margin(feet3, np.array([cog[0], cog[1], 0.0]))


def stance_margin(params: UpuParams, x_upper: float, x_lower: float, support: str) -> float:
    """Static margin [m] with the CoG of eq. (13) and support on 'upper', 'lower' or 'all'
    legs, platform centres at world x_upper, x_lower (y = 0)."""
    if support == "all":
        legs = PLATFORM_LEGS["upper"] + PLATFORM_LEGS["lower"]
    else:
        legs = PLATFORM_LEGS[check_platform(support, "support")]
    feet = foot_positions(params, x_upper, x_lower, legs)
    cog_x = (params.upper_half_mass * x_upper + params.lower_half_mass * x_lower) / (
        params.total_mass
    )
    return support_margin(np.array(list(feet.values())), np.array([cog_x, 0.0]))


# --- Steps and plans ------------------------------------------------------------------------
@dataclass(frozen=True)
class GaitSettings:
    """Tunable choices of the planner (SI units)."""

    lift: float | None = None
    """Apex of the upper platform's path above its start [m]; None: `UpuParams.step_lift` (the
    paper's 80 mm, eq. 20). Reduced automatically where the workspace does not allow it (steps
    that end far from the lower platform's centre)."""
    upper_swing_retract: float = 0.02
    """The upper legs retract by this much before their transfer [m], so their feet clear the
    ground at the path ends where the path itself has no lift."""
    lower_swing_retract: float = 0.08
    """The lower legs retract by this much before their transfer [m]: the lower platform cannot
    rise (see module doc), so retraction gives the paper's 80 mm foot clearance."""
    edge_clearance: float = 0.02
    """Minimum gap between a foot's edge and a ditch edge when it lands [m]."""
    min_margin: float = 0.01
    """Required static margin during every three-leg support phase [m]."""
    max_stride: float | None = None
    """Longest platform step [m]; None: eq. (17) from the robot's parameters (0.16 m)."""
    grid: float = 0.005
    """Resolution of the step lengths searched by the ditch planner [m]."""

    def __post_init__(self) -> None:
        for name in (
            "upper_swing_retract",
            "lower_swing_retract",
            "edge_clearance",
            "min_margin",
        ):
            check_number(f"GaitSettings.{name}", getattr(self, name))
        check_number("GaitSettings.grid", self.grid, strict=True)
        if self.lift is not None and not (math.isfinite(self.lift) and self.lift >= 0):
            raise ValueError(
                f"GaitSettings.lift must be a finite number >= 0 m or None, got {self.lift}"
            )
        if self.max_stride is not None and not self.max_stride > 0:
            raise ValueError(
                f"GaitSettings.max_stride must be > 0 m or None, got {self.max_stride}"
            )


@dataclass(frozen=True)
class Ditch:
    """A ditch across the walking direction: ground at z = -depth for start_x < x < start_x +
    width, z = 0 elsewhere [m] (as `hexapod_envs.terrain.ditch.add_ditch` builds it)."""

    start_x: float
    width: float
    depth: float

    def __post_init__(self) -> None:
        if not math.isfinite(self.start_x):
            raise ValueError(f"ditch start_x must be finite, got {self.start_x}")
        for name in ("width", "depth"):
            check_number(f"ditch {name}", getattr(self, name), strict=True)

    @property
    def end_x(self) -> float:
        return self.start_x + self.width

    def ground_height(self, x: float) -> float:
        """Terrain height at x [m]."""
        return -self.depth if self.start_x < x < self.end_x else 0.0


@dataclass(frozen=True)
class PlatformStep:
    """One step of the 3-3 gait: the `moving` platform's legs retract (lift-off), the platform
    travels from start_x to end_x along `path`, and its legs extend to `landing_extension`
    until they touch down. The other platform stands still on its legs throughout."""

    moving: str
    """'upper' or 'lower'."""
    start_x: float
    """World x of the moving platform's centre before the step [m]."""
    end_x: float
    """World x of the moving platform's centre after the step [m]."""
    support_x: float
    """World x of the supporting platform's centre [m]."""
    lift: float
    """Apex of the moving platform's relative path above its start height [m]."""
    swing_extension: float
    """Extension the moving legs hold during the transfer [m] (negative: retracted)."""
    landing_extension: dict[str, float]
    """Moving leg -> extension at touchdown [m] (the ditch depth for a foot in the ditch)."""
    support_extension: dict[str, float]
    """Supporting leg -> its (unchanged) extension [m]."""
    min_margin: float
    """Smallest static margin while the moving legs are off the ground [m]."""

    @property
    def stride(self) -> float:
        """Distance travelled by the moving platform [m]."""
        return self.end_x - self.start_x

    @property
    def support(self) -> str:
        """The platform standing on its legs during this step."""
        return _other(self.moving)

    def path(self, params: UpuParams) -> QuadraticPath:
        """Relative path of the moving centre in the supporting platform's frame (x, z) [m]:
        the upper in the lower frame (eqs. 6, 19-20) or the lower in the upper frame (eq. 8)."""
        x0 = self.start_x - self.support_x
        x1 = self.end_x - self.support_x
        h = params.initial_height if self.moving == "upper" else -params.initial_height
        return step_path(x0, x1, h, self.lift)

    def relative_poses(self, params: UpuParams, n: int = 21) -> np.ndarray:
        """(n, 3) moving-platform positions along the path in the supporting frame [m]."""
        xz = self.path(params).sample(n)
        return np.column_stack([xz[:, 0], np.zeros(n), xz[:, 1]])

    def limb_lengths(self, params: UpuParams, n: int = 21) -> np.ndarray:
        """(n, 3) limb-length commands along the path [m] (eq. 15 or 16, Fig. 10)."""
        return inverse_kinematics(self.relative_poses(params, n), params, moving=self.moving)


@dataclass(frozen=True)
class GaitPlan:
    """A sequence of platform steps, or the reason there is none."""

    status: str
    """One of `PLAN_STATUSES`."""
    reason: str
    steps: tuple[PlatformStep, ...] = ()
    ditch: Ditch | None = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def min_margin(self) -> float:
        """Smallest three-leg-support margin over the plan [m] (nan without steps)."""
        return min((s.min_margin for s in self.steps), default=math.nan)

    @property
    def strides(self) -> np.ndarray:
        return np.array([s.stride for s in self.steps])


@dataclass(frozen=True)
class MarginProfile:
    """Static margin through a plan, sampled per phase (for plots like Fig. 12 and 14)."""

    step: np.ndarray
    """(n,) index of the step each sample belongs to."""
    phase: tuple[str, ...]
    """(n,) 'lift' (moving legs retracting), 'transfer', 'land' (legs extending), 'six' (all
    six legs down after landing)."""
    margin: np.ndarray
    """(n,) static margin [m]."""


def margin_profile(plan: GaitPlan, params: UpuParams, samples: int = 11) -> MarginProfile:
    """Static margin before, during and after each transfer of `plan` (`samples` per transfer).

    During 'lift' and 'land' the platforms stand still and only legs move, so the margin stays
    constant there, as in the paper's Fig. 14.
    """
    steps, phases, margins = [], [], []
    for k, s in enumerate(plan.steps):
        xs = np.linspace(s.start_x, s.end_x, samples)
        values = []
        for x in xs:
            xu, xl = (x, s.support_x) if s.moving == "upper" else (s.support_x, x)
            values.append(stance_margin(params, xu, xl, s.support))
        xu, xl = (s.end_x, s.support_x) if s.moving == "upper" else (s.support_x, s.end_x)
        six = stance_margin(params, xu, xl, "all")
        labels = ["lift"] + ["transfer"] * samples + ["land", "six"]
        vals = [values[0], *values, values[-1], six]
        steps += [k] * len(labels)
        phases += labels
        margins += vals
    return MarginProfile(np.array(steps, dtype=int), tuple(phases), np.array(margins))


def _other(platform: str) -> str:
    return "lower" if platform == "upper" else "upper"


def stride_limit(params: UpuParams, settings: GaitSettings) -> float:
    """The longest platform step [m]: eq. (17), or `settings.max_stride` where shorter."""
    limit = max_stride(params.support_inradius, params.leg_radius)
    return limit if settings.max_stride is None else min(limit, settings.max_stride)


def _swing_extension(moving: str, params: UpuParams, settings: GaitSettings) -> float:
    retract = settings.upper_swing_retract if moving == "upper" else settings.lower_swing_retract
    return -min(retract, params.leg_retract)


@lru_cache(maxsize=8192)
def _feasible_lift(params: UpuParams, settings: GaitSettings, moving: str, x0: float, x1: float):
    """Largest lift <= the target lift (1 mm steps) keeping the whole path inside the workspace;
    None if even the straight path leaves it. Relative coordinates [m]. Cached: the result
    depends only on its (hashable, frozen) arguments, and the planner asks for the same
    relative moves again and again."""
    h = params.initial_height if moving == "upper" else -params.initial_height
    target = params.step_lift if settings.lift is None else settings.lift
    candidates = np.zeros(1)
    if moving == "upper" and target > 0:
        candidates = np.linspace(target, 0.0, int(round(target / 0.001)) + 1)
    x = np.linspace(x0, x1, 21)
    mid = (x0 + x1) / 2
    half = (x1 - x0) / 2
    bump = 1.0 - ((x - mid) / half) ** 2 if half != 0 else np.zeros_like(x)

    def feasible(lifts: np.ndarray) -> np.ndarray:
        z = h + lifts[:, None] * bump[None, :]
        pts = np.stack([np.broadcast_to(x, z.shape), np.zeros_like(z), z], axis=-1)
        return np.all(inside_limits(pts, params, moving=moving), axis=-1)

    if feasible(candidates[:1])[0]:  # the usual case: the full lift fits
        return float(candidates[0])
    ok = feasible(candidates[1:])  # all smaller lifts in one workspace check
    first = np.flatnonzero(ok)
    return float(candidates[1 + first[0]]) if first.size else None


@lru_cache(maxsize=65536)
def _transfer_margin(params: UpuParams, moving: str, x0: float, x1: float) -> float:
    """Min static margin while the `moving` centre goes from x0 to x1 relative to the other [m].

    Cached like `_feasible_lift`: it depends on the robot and the relative step only, so the
    plans of different ditches share it (a reset on sampled ditches plans anew every time).

    The CoG moves on a straight line and the margin inside a convex polygon is the minimum of
    the distances to its sides, each linear in the CoG position: a concave function, so its
    minimum over the segment is at an end (and a negative end is caught there too).
    """
    support = _other(moving)
    values = []
    for x in (x0, x1):
        xu, xl = (x, 0.0) if moving == "upper" else (0.0, x)
        values.append(stance_margin(params, xu, xl, support))
    return min(values)


def platform_step(
    params: UpuParams,
    settings: GaitSettings,
    moving: str,
    start_x: float,
    end_x: float,
    support_x: float,
    landing_extension: dict[str, float] | None = None,
    support_extension: dict[str, float] | None = None,
) -> PlatformStep | str:
    """The step moving the `moving` platform's centre from world x `start_x` to `end_x` while
    the other stands at `support_x` [m], with the largest lift the workspace allows; or why
    there is none (a string: the path leaves the workspace, or the static margin falls below
    `settings.min_margin`). Extensions default to 0 (level ground) [m]."""
    x0, x1 = start_x - support_x, end_x - support_x
    lift = _feasible_lift(params, settings, moving, x0, x1)
    if lift is None:
        return f"the {moving} step from {start_x:.4f} to {end_x:.4f} m leaves the workspace"
    margin = _transfer_margin(params, moving, x0, x1)
    if margin < settings.min_margin:
        return (
            f"the {moving} step drops the static margin to {margin:.4f} m "
            f"< min_margin {settings.min_margin} m"
        )
    return PlatformStep(
        moving=moving,
        start_x=start_x,
        end_x=end_x,
        support_x=support_x,
        lift=lift,
        swing_extension=_swing_extension(moving, params, settings),
        landing_extension=landing_extension or dict.fromkeys(PLATFORM_LEGS[moving], 0.0),
        support_extension=support_extension or dict.fromkeys(PLATFORM_LEGS[_other(moving)], 0.0),
        min_margin=margin,
    )


def landing_extensions(
    params: UpuParams, moving: str, end_x: float, ditch: Ditch | None
) -> dict[str, float]:
    """Moving leg -> its extension at touchdown [m] for a step ending at world x `end_x`: the
    ditch's depth for a foot whose centre lands over the ditch, 0 elsewhere (§7, Fig. 13)."""
    landing = {}
    for leg in PLATFORM_LEGS[moving]:
        foot_x = end_x + float(params.foot_offset(leg)[0])
        below = ditch is not None and ditch.ground_height(foot_x) < 0
        landing[leg] = ditch.depth if below else 0.0
    return landing


def edge_clearance(feet_x, near: float, far: float, band: float, can_stand: bool) -> np.ndarray:
    """Each foot's clearance from a ditch's edges [m], signed: the distance of its centre `feet_x`
    [m] to the nearer edge (`near`, `far`: the ditch's edges in the same frame [m]); where no
    foot can stand on the bottom (`can_stand` False: too deep), a foot within `band` [m] of the
    ditch or over it counts that distance negative. A foothold is clear at `band` or more: the
    planner's criterion (foot radius + edge clearance), the clear-stride rule's and the ditch
    env's landing term's."""
    feet_x = np.asarray(feet_x, dtype=float)
    gap = np.minimum(np.abs(feet_x - near), np.abs(feet_x - far))
    if can_stand:
        return gap
    inside = (feet_x > near - band) & (feet_x < far + band)
    return np.where(inside, -gap, gap)


def plan_flat_walk(
    params: UpuParams,
    n_cycles: int,
    stride: float | None = None,
    x_start: float = 0.0,
    settings: GaitSettings | None = None,
) -> GaitPlan:
    """The paper's flat-ground gait: `n_cycles` x (upper step, lower step) of `stride` [m]
    (default: eq. 17's maximum), upper path eq. (20)."""
    settings = settings or GaitSettings()
    if not (isinstance(n_cycles, int | np.integer) and n_cycles >= 1):
        raise ValueError(f"n_cycles must be an integer >= 1, got {n_cycles!r}")
    limit = stride_limit(params, settings)
    stride = limit if stride is None else float(stride)
    if not 0 < stride <= limit + 1e-12:
        raise ValueError(f"stride must be in (0, {limit:.4f}] m (eq. 17), got {stride}")
    steps = []
    x_lower = x_upper = float(x_start)
    for _ in range(n_cycles):
        for moving in ("upper", "lower"):
            x0 = x_upper if moving == "upper" else x_lower
            support_x = x_lower if moving == "upper" else x_upper
            step = platform_step(params, settings, moving, x0, x0 + stride, support_x)
            if isinstance(step, str):
                return GaitPlan("no_plan", f"stride {stride} m: {step}")
            steps.append(step)
            if moving == "upper":
                x_upper += stride
            else:
                x_lower += stride
    return GaitPlan("ok", f"{n_cycles} cycles of {stride} m on flat ground", tuple(steps))


def plan_ditch_crossing(
    params: UpuParams,
    ditch: Ditch,
    x_start: float = 0.0,
    settings: GaitSettings | None = None,
) -> GaitPlan:
    """Plan 3-3 gait steps that carry the robot across `ditch` (§7, Fig. 13).

    The robot starts standing with both platform centres at world x = `x_start` (all six feet
    on the near ground) and ends standing the same way with every foot past the far edge.
    Feet must land either on the ground or on the ditch bottom, at least `edge_clearance` from
    an edge (so steps are shortened near the ditch); a foot on the bottom lands with its leg
    extended by the depth, and retracts again before its next transfer. Breadth-first search
    over step lengths on a `grid` finds the plan with the fewest steps (longest steps first on
    ties), subject to the stride limit (eq. 17), the workspace (the upper path's lift is
    reduced where needed) and `min_margin`.
    """
    settings = settings or GaitSettings()
    crossing = _Crossing(params, ditch, x_start, settings)
    if not crossing.can_stand and not crossing.can_step_over:
        return _unreachable(crossing, "")
    crossing.check_start()
    chain = _fewest_steps(crossing)
    if chain is None:
        return _unreachable(
            crossing,
            f"no sequence of steps <= {crossing.limit:.3f} m (eq. 17) keeps every foot "
            f"{crossing.band:.3f} m from the ditch edges with margin >= {settings.min_margin} m",
        )
    steps = _platform_steps(crossing, chain)
    how = "standing in the ditch" if crossing.can_stand else "stepping over it"
    return GaitPlan(
        "ok",
        f"{len(steps)} steps cross the {ditch.width} m x {ditch.depth} m ditch, {how}",
        steps,
        ditch,
    )


class _Crossing:
    """What the ditch planner's search works on: the grid of platform-centre positions
    (x_start + i grid, i < n_x), where each platform's feet may stand, and the goal."""

    def __init__(self, params: UpuParams, ditch: Ditch, x_start: float, settings: GaitSettings):
        self.params, self.ditch, self.x_start, self.settings = params, ditch, x_start, settings
        self.grid = g = settings.grid
        self.band = params.foot_radius + settings.edge_clearance
        """Closest a foot's centre may land to a ditch edge [m]."""
        self.limit = stride_limit(params, settings)
        self.can_stand = ditch.depth <= params.leg_extend and ditch.width >= 2 * self.band + g
        """A foot can stand on the bottom: within the legs' reach and wide enough."""
        self.can_step_over = ditch.width + 2 * self.band <= self.limit
        self.upper_offsets = _foot_offsets_x(params, "upper")
        self.lower_offsets = _foot_offsets_x(params, "lower")
        rear = min(self.upper_offsets + self.lower_offsets)
        goal_x = ditch.end_x + self.band - rear  # centre x putting the rearmost foot past it
        self.n_goal = int(math.ceil((goal_x - x_start) / g - 1e-9))
        """Both centres at grid index >= n_goal (and together): the crossing is done."""
        self.n_d = int(math.floor(self.limit / g + 1e-9))
        """Longest step in grid cells."""
        self.n_x = self.n_goal + self.n_d + 1
        """Grid positions the lower centre may take."""

    def check_start(self) -> None:
        front = self.x_start + max(self.upper_offsets + self.lower_offsets)
        if front > self.ditch.start_x - self.band:
            raise ValueError(
                f"the robot must start with every foot before the ditch: its front feet at "
                f"x = {front:.3f} m are within {self.band:.3f} m of (or past) the ditch start "
                f"{self.ditch.start_x} m"
            )

    def footholds_ok(self, offsets: tuple[float, ...]) -> np.ndarray:
        """(n_x + n_d + 1,) bool: a platform centred at grid index i has every foot on ground
        it may land on (not within `band` of an edge; not in the ditch when no foot can stand
        on its bottom)."""
        i = np.arange(self.n_x + self.n_d + 1)
        feet = self.x_start + i[:, None] * self.grid + np.asarray(offsets)[None, :]
        d = self.ditch
        if self.can_stand:
            ok = (np.abs(feet - d.start_x) >= self.band) & (np.abs(feet - d.end_x) >= self.band)
        else:
            ok = ~((d.start_x - self.band < feet) & (feet < d.end_x + self.band))
        return ok.all(axis=1)


def _foot_offsets_x(params: UpuParams, platform: str) -> tuple[float, ...]:
    """Distinct x offsets of a platform's feet from its centre, ascending [m]."""
    return tuple(sorted({float(params.foot_offset(leg)[0]) for leg in PLATFORM_LEGS[platform]}))


@lru_cache(maxsize=64)
def _relative_moves(params: UpuParams, settings: GaitSettings, n_d: int) -> _RelativeMoves:
    """The feasible steps from each relative offset j (x_upper - x_lower = j grid), for both
    movers. They depend on the robot, the settings and j only, not on the ditch or on where the
    robot stands, so every plan with these settings shares them."""
    g = settings.grid

    def move(moving: str, j0: int, j1: int):
        x0, x1 = j0 * g, j1 * g
        if moving == "lower":
            x0, x1 = -x0, -x1  # the lower centre relative to the upper one
        lift = _feasible_lift(params, settings, moving, x0, x1)
        if lift is None:
            return None
        margin = _transfer_margin(params, moving, x0, x1)
        return None if margin < settings.min_margin else (lift, margin)

    upper, lower = {}, {}
    for j in range(n_d + 1):
        for j1 in range(n_d, j, -1):  # longest first: the search's order on ties
            if (found := move("upper", j, j1)) is not None:
                upper[j, j1] = found
        for step in range(j, 0, -1):
            if (found := move("lower", j, j - step)) is not None:
                lower[j, j - step] = found
    return _RelativeMoves(upper, lower, _padded(upper, n_d), _padded(lower, n_d))


def _padded(moves: dict[tuple[int, int], tuple], n_d: int) -> np.ndarray:
    """(n_d + 1, k) the targets j1 of the moves from each j, in the search's order, padded with
    -1."""
    rows = [[j1 for (j0, j1) in moves if j0 == j] for j in range(n_d + 1)]
    table = np.full((n_d + 1, max(1, *map(len, rows))), -1, dtype=np.int64)
    for j, row in enumerate(rows):
        table[j, : len(row)] = row
    return table


@dataclass(frozen=True)
class _RelativeMoves:
    upper: dict[tuple[int, int], tuple[float, float]]
    """(j0, j1) -> (lift [m], min margin [m]) of a feasible upper-platform step."""
    lower: dict[tuple[int, int], tuple[float, float]]
    """The same for the lower platform (j0 - j1 > 0 grid cells forward)."""
    upper_targets: np.ndarray
    lower_targets: np.ndarray


def _fewest_steps(crossing: _Crossing) -> list[tuple[int, int, str]] | None:
    """The breadth-first search over states (i_lower, j = (x_upper - x_lower) / grid, next
    mover), starting standing with the upper platform first: the chain of states from the
    start to the first goal found, or None.

    A FIFO search that tries each state's moves longest first, so among the plans with the
    fewest steps it returns the one with the longest early steps. Compiled
    (`_compiled.fewest_steps`): a sampled ditch needs its own plan at every reset.
    """
    moves = _relative_moves(crossing.params, crossing.settings, crossing.n_d)
    chain = fewest_steps(
        moves.upper_targets,
        moves.lower_targets,
        crossing.footholds_ok(crossing.upper_offsets),
        crossing.footholds_ok(crossing.lower_offsets),
        crossing.n_x,
        crossing.n_goal,
    )
    if not len(chain):
        return None
    return [(int(i), int(j), _MOVERS[mover]) for i, j, mover in chain]


_MOVERS = ("upper", "lower")
"""The next mover's name by its code in the compiled search."""


def _platform_steps(crossing: _Crossing, chain) -> tuple[PlatformStep, ...]:
    """The plan's steps along the searched chain of states: world x of each move, the legs'
    landing extensions (the depth where a foot lands on the bottom), and the support legs'
    extensions left from their own last landing."""
    params, settings, g, x0 = crossing.params, crossing.settings, crossing.grid, crossing.x_start
    moves = _relative_moves(params, settings, crossing.n_d)
    extension = {leg: 0.0 for leg in PLATFORM_LEGS["upper"] + PLATFORM_LEGS["lower"]}
    steps = []
    for (i0, j0, mover), (i1, j1, _) in zip(chain, chain[1:], strict=False):
        x_lower0, x_upper0 = x0 + i0 * g, x0 + (i0 + j0) * g
        x_lower1, x_upper1 = x0 + i1 * g, x0 + (i1 + j1) * g
        if mover == "upper":
            lift, margin = moves.upper[j0, j1]
            start_x, end_x, support_x = x_upper0, x_upper1, x_lower0
        else:
            lift, margin = moves.lower[j0, j1]
            start_x, end_x, support_x = x_lower0, x_lower1, x_upper0
        landing = landing_extensions(params, mover, end_x, crossing.ditch)
        steps.append(
            PlatformStep(
                moving=mover,
                start_x=start_x,
                end_x=end_x,
                support_x=support_x,
                lift=lift,
                swing_extension=_swing_extension(mover, params, settings),
                landing_extension=landing,
                support_extension={leg: extension[leg] for leg in PLATFORM_LEGS[_other(mover)]},
                min_margin=margin,
            )
        )
        extension.update(landing)
    return tuple(steps)


def _unreachable(crossing: _Crossing, search_note: str) -> GaitPlan:
    """The failed plan, with the reason: too deep to stand in and too wide to step over, too
    narrow to stand in and too wide to step over, or (with `search_note`, after a search) no
    step sequence."""
    ditch, settings, band = crossing.ditch, crossing.settings, crossing.band
    reach = crossing.params.leg_extend
    step_over_note = (
        f"stepping over needs a stride of width + 2 (foot radius + clearance) = "
        f"{ditch.width + 2 * band:.3f} m > {crossing.limit:.3f} m (eq. 17)"
    )
    if crossing.can_stand:
        return GaitPlan("no_plan", search_note, ditch=ditch)
    if not search_note:
        if ditch.depth > reach:
            reason = (
                f"the ditch is {ditch.depth:.3f} m deep but a leg extends at most {reach:.3f} "
                f"m, so no foot can stand on its bottom; {step_over_note}"
            )
            return GaitPlan("too_deep", reason, ditch=ditch)
        reason = (
            f"the ditch ({ditch.width:.3f} m) is too narrow for a foot with "
            f"{settings.edge_clearance} m clearance on each side, and {step_over_note}"
        )
        return GaitPlan("too_wide", reason, ditch=ditch)
    if ditch.depth > reach:
        reason = (
            f"the ditch is {ditch.depth:.3f} m deep but a leg extends at most {reach:.3f} m, "
            f"so no foot can stand on its bottom, and at {ditch.width:.3f} m it is too wide "
            f"to step over: {search_note}"
        )
        return GaitPlan("too_deep", reason, ditch=ditch)
    reason = (
        f"the ditch ({ditch.width:.3f} m) is too narrow for a foot with "
        f"{settings.edge_clearance} m clearance on each side and too wide to step "
        f"over: {search_note}"
    )
    return GaitPlan("too_wide", reason, ditch=ditch)


def plan_flat_past(
    params: UpuParams,
    goal_x: float,
    x_start: float = 0.0,
    settings: GaitSettings | None = None,
) -> GaitPlan:
    """Flat-ground gait (full strides, eq. 17) until every foot, sphere included, is past the
    line x = `goal_x` [m]: the same finish line as a ditch ending at `goal_x`, without the
    ditch."""
    settings = settings or GaitSettings()
    if not (math.isfinite(goal_x) and math.isfinite(x_start)):
        raise ValueError(f"goal_x and x_start must be finite [m], got {goal_x}, {x_start}")
    rear = min(float(params.foot_offset(leg)[0]) for leg in PLATFORM_LEGS["lower"])
    rear = min(rear, *(float(params.foot_offset(leg)[0]) for leg in PLATFORM_LEGS["upper"]))
    distance = goal_x + params.foot_radius + settings.edge_clearance - rear - x_start
    if distance <= 0:
        raise ValueError(
            f"goal_x = {goal_x} m is already behind the robot's rear feet (start x = {x_start} m)"
        )
    stride = stride_limit(params, settings)
    return plan_flat_walk(
        params, int(math.ceil(distance / stride - 1e-9)), x_start=x_start, settings=settings
    )
