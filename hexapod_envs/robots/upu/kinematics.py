"""Kinematics of the 3-UPU translational parallel mechanism (Li et al. 2018 §3-4), pure numpy.

Positions are of one platform centre relative to the other, in metres, in the paper's frames
(x forward, z up; see `params`):

- upper moving, eq. (6): p = OO', the upper centre in the lower-platform frame;
- lower moving, eq. (8): p = O'O, the lower centre in the upper-platform frame. Since the
  platforms stay parallel this is the point reflection of the first case: eq. (8) at p equals
  eq. (6) at -p.

Hooke-joint angles (eqs. 10-11, written in the paper for limb 1 only) are generalised to every
limb in the limb's own frame at A_i: u_i the outward radial unit vector, t_i = z x u_i the
tangent (the axis of the fork fixed to the platform, paper §2), v_i = A_iB_i:

- theta_1,i = asin((v_i . t_i) / l_i): the limb's tilt out of its radial-vertical plane
  (eq. 10: asin(|y| / l_1) for limb 1, where t_1 = -y);
- theta_2,i = atan2(v_i . u_i, v_i . z): the tilt within that plane from the vertical,
  positive leaning outward (eq. 11: acos(z / sqrt(l_1^2 - y^2)) in magnitude).

The platforms are parallel, so the joints on the other platform turn by the same angles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .params import HOOKE_AZIMUTHS, LIMB_NAMES, PLATFORMS, UpuParams, check_platform

_RADIAL = np.array([[math.cos(a), math.sin(a), 0.0] for a in HOOKE_AZIMUTHS])
_TANGENT = np.array([[-math.sin(a), math.cos(a), 0.0] for a in HOOKE_AZIMUTHS])


def _as_positions(p, name: str = "position") -> np.ndarray:
    arr = np.asarray(p, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (3,) or (..., 3) [m], got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return arr


def upper_position(p, moving: str = "upper") -> np.ndarray:
    """The upper centre in the lower frame, given `p` of the `moving` platform (see module doc)."""
    arr = _as_positions(p)
    return arr if check_platform(moving, "moving") == "upper" else -arr


def limb_vectors(p, params: UpuParams, moving: str = "upper") -> np.ndarray:
    """(..., 3, 3) limb vectors A_iB_i (rows i = 1..3), eq. (5), lower frame [m].

    For moving='lower' these are the vectors of eq. (7) negated (B_iA_i = -A_iB_i).
    """
    q = upper_position(p, moving)
    return q[..., None, :] + params.upper_hooke_points - params.lower_hooke_points


def inverse_kinematics(p, params: UpuParams, moving: str = "upper") -> np.ndarray:
    """Limb lengths (l_1, l_2, l_3) [m] of eq. (6) (moving='upper', p = OO') or eq. (8)
    (moving='lower', p = O'O). Accepts one position (3,) or an array (..., 3)."""
    return np.linalg.norm(limb_vectors(p, params, moving), axis=-1)


def inverse_kinematics_lower(p_lower, params: UpuParams) -> np.ndarray:
    """Eq. (8) written out term by term: lower centre at `p_lower` in the upper frame [m].

    Equal to `inverse_kinematics(p_lower, params, moving="lower")`; kept literal so a test can
    check the reflection argument against the paper's own equation.
    """
    x, y, z = np.moveaxis(_as_positions(p_lower, "p_lower"), -1, 0)
    d = params.delta
    s = math.sqrt(3.0) / 2 * d
    return np.stack(
        [
            np.sqrt((x - d) ** 2 + y**2 + z**2),
            np.sqrt((x + d / 2) ** 2 + (y + s) ** 2 + z**2),
            np.sqrt((x + d / 2) ** 2 + (y - s) ** 2 + z**2),
        ],
        axis=-1,
    )


@dataclass(frozen=True)
class FkSolution:
    """Result of the numeric forward kinematics."""

    position: np.ndarray
    """(3,) upper centre in the lower frame (or lower in upper for moving='lower') [m]."""
    converged: bool
    """True when the limb-length residual fell below the tolerance."""
    iterations: int
    residual: float
    """max_i |l_i(position) - l_i| [m] at the returned position."""


def solve_forward_kinematics(
    lengths,
    params: UpuParams,
    moving: str = "upper",
    guess=None,
    tol: float = 1e-10,
    max_iter: int = 30,
) -> FkSolution:
    """Newton's method on eq. (6) (or (8)): limb lengths [m] -> platform translation [m].

    The residual F_i(p) = |A_iB_i(p)|^2 - l_i^2 has the Jacobian rows 2 A_iB_i, so each step
    solves a 3x3 system. Default initial guess: straight above (below for moving='lower') at the
    mean limb length, which selects the assembly with the upper platform above the lower one.
    Never raises for non-convergence: check `converged` (or use `forward_kinematics`).
    """
    lengths = np.asarray(lengths, dtype=float)
    if lengths.shape != (3,) or not np.all(np.isfinite(lengths)) or np.any(lengths <= 0):
        raise ValueError(f"lengths must be 3 finite positive limb lengths [m], got {lengths}")
    check_platform(moving, "moving")
    sign = 1.0 if moving == "upper" else -1.0
    if guess is None:
        q = np.array([0.0, 0.0, float(lengths.mean())])
    else:
        q = sign * _as_positions(guess, "guess").reshape(3).copy()
    offsets = params.upper_hooke_points - params.lower_hooke_points
    residual = math.inf
    for it in range(max_iter + 1):
        v = q + offsets
        current = np.linalg.norm(v, axis=1)
        residual = float(np.max(np.abs(current - lengths)))
        if residual <= tol:
            return FkSolution(sign * q, True, it, residual)
        if it == max_iter:
            break
        f = current**2 - lengths**2
        jac = 2.0 * v
        try:
            q = q - np.linalg.solve(jac, f)
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(q)):
            break
    return FkSolution(sign * q, False, it, residual)


def forward_kinematics(
    lengths, params: UpuParams, moving: str = "upper", guess=None, tol: float = 1e-10
) -> np.ndarray:
    """Position [m] for the limb `lengths` [m] by Newton's method; ValueError if it fails.

    Failure means the lengths admit no assembly near the guess (e.g. lengths differing by more
    than the platform offsets allow).
    """
    sol = solve_forward_kinematics(lengths, params, moving=moving, guess=guess, tol=tol)
    if not sol.converged:
        raise ValueError(
            f"forward kinematics did not converge for limb lengths {np.asarray(lengths)} m "
            f"(residual {sol.residual:.3g} m after {sol.iterations} iterations): no assembly "
            "of the mechanism has these lengths"
        )
    return sol.position


def forward_kinematics_closed_form(lengths, params: UpuParams, moving: str = "upper"):
    """Exact solution of eq. (6) (or (8)), used to cross-check the Newton solver [m].

    Subtracting the equations pairwise leaves two linear ones: 3 Delta x + sqrt(3) Delta y =
    l1^2 - l2^2 and 3 Delta x - sqrt(3) Delta y = l1^2 - l3^2; then z = +sqrt(l1^2 - (x +
    Delta)^2 - y^2) (upper platform above the lower one).
    """
    l1, l2, l3 = np.asarray(lengths, dtype=float)
    d = params.delta
    x = (2 * l1**2 - l2**2 - l3**2) / (6 * d)
    y = (l3**2 - l2**2) / (2 * math.sqrt(3.0) * d)
    z2 = l1**2 - (x + d) ** 2 - y**2
    if not z2 >= 0:
        raise ValueError(f"limb lengths {(l1, l2, l3)} m admit no assembly (z^2 = {z2:.3g})")
    q = np.array([x, y, math.sqrt(z2)])
    return q if check_platform(moving, "moving") == "upper" else -q


@dataclass(frozen=True)
class HookeAngles:
    """Hooke-joint angles of the three limbs [rad], arrays of shape (..., 3)."""

    theta1: np.ndarray
    """Tilt out of the limb's radial-vertical plane, eq. (10) (signed)."""
    theta2: np.ndarray
    """Tilt from the vertical within the radial-vertical plane, eq. (11) (signed, + outward)."""


def hooke_angles(p, params: UpuParams, moving: str = "upper") -> HookeAngles:
    """Hooke-joint angles (eqs. 10-11, generalised to every limb; see module doc) [rad]."""
    v = limb_vectors(p, params, moving)
    length = np.linalg.norm(v, axis=-1)
    along_t = np.sum(v * _TANGENT, axis=-1)
    along_u = np.sum(v * _RADIAL, axis=-1)
    theta1 = np.arcsin(np.clip(along_t / length, -1.0, 1.0))
    theta2 = np.arctan2(along_u, v[..., 2])
    return HookeAngles(theta1=theta1, theta2=theta2)


LIMIT_NAMES: tuple[str, ...] = ("limb_min", "limb_max", "hooke_theta1", "hooke_theta2")
"""Order of the constraint columns returned by `limit_margins`."""


def limit_margins(p, params: UpuParams, moving: str = "upper") -> np.ndarray:
    """(..., 3, 4) distance to each limit per limb, > 0 inside [m for lengths, rad for angles].

    Columns follow `LIMIT_NAMES`: l - l_min, l_max - l, limit - |theta1|, limit - |theta2|.
    Tolerance is not applied here.
    """
    lengths = inverse_kinematics(p, params, moving)
    ang = hooke_angles(p, params, moving)
    return np.stack(
        [
            lengths - params.limb_min,
            params.limb_max - lengths,
            params.hooke_limit - np.abs(ang.theta1),
            params.hooke_limit - np.abs(ang.theta2),
        ],
        axis=-1,
    )


def inside_limits(p, params: UpuParams, moving: str = "upper", tol: float | None = None):
    """Boolean array (...,): every limb length and Hooke angle within its limits (+ `tol`).

    `tol` [m] defaults to `params.limit_tolerance`; angles get tol / limb_min [rad].
    """
    tol = params.limit_tolerance if tol is None else float(tol)
    margins = limit_margins(p, params, moving)
    slack = np.array([tol, tol, tol / params.limb_min, tol / params.limb_min])
    return np.all(margins >= -slack, axis=(-2, -1))


@dataclass(frozen=True)
class LimitCheck:
    """Whether one pose respects the mechanism's limits, and why not."""

    ok: bool
    reasons: tuple[str, ...]
    """One human-readable line per violated limit (empty when ok)."""
    limb_lengths: np.ndarray
    """(3,) [m]."""
    theta1: np.ndarray
    """(3,) [rad]."""
    theta2: np.ndarray
    """(3,) [rad]."""

    def __bool__(self) -> bool:
        return self.ok


def check_limits(p, params: UpuParams, moving: str = "upper", tol: float | None = None):
    """Check a single pose `p` (3,) [m] against limb-length and Hooke-angle limits (eqs. 9-11).

    Returns a `LimitCheck`; its `reasons` name every violated limit with the value and bound.
    `tol` [m] defaults to `params.limit_tolerance` (see there); angles get tol / limb_min [rad].
    """
    arr = _as_positions(p)
    if arr.shape != (3,):
        raise ValueError(f"check_limits takes one position of shape (3,), got {arr.shape}")
    tol = params.limit_tolerance if tol is None else float(tol)
    lengths = inverse_kinematics(arr, params, moving)
    ang = hooke_angles(arr, params, moving)
    a_tol = tol / params.limb_min
    lim_deg = math.degrees(params.hooke_limit)
    reasons = []
    for i, name in enumerate(LIMB_NAMES):
        length = float(lengths[i])
        if length < params.limb_min - tol:
            reasons.append(f"{name} length {length:.4f} m < limb_min {params.limb_min} m")
        if length > params.limb_max + tol:
            reasons.append(f"{name} length {length:.4f} m > limb_max {params.limb_max} m")
        for label, value in (("theta1", ang.theta1[i]), ("theta2", ang.theta2[i])):
            if abs(value) > params.hooke_limit + a_tol:
                reasons.append(
                    f"{name} Hooke angle {label} = {math.degrees(value):.1f} deg outside "
                    f"±{lim_deg:.1f} deg"
                )
    return LimitCheck(
        ok=not reasons,
        reasons=tuple(reasons),
        limb_lengths=lengths,
        theta1=ang.theta1,
        theta2=ang.theta2,
    )


def is_reachable(p, params: UpuParams, moving: str = "upper", tol: float | None = None) -> bool:
    """True when the single pose `p` [m] respects every limit (see `check_limits`)."""
    return check_limits(p, params, moving, tol).ok


__all__ = [
    "FkSolution",
    "HookeAngles",
    "LIMIT_NAMES",
    "LimitCheck",
    "PLATFORMS",
    "check_limits",
    "forward_kinematics",
    "forward_kinematics_closed_form",
    "hooke_angles",
    "inside_limits",
    "inverse_kinematics",
    "inverse_kinematics_lower",
    "is_reachable",
    "limb_vectors",
    "limit_margins",
    "solve_forward_kinematics",
    "upper_position",
]
