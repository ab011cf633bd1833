"""Tipping judgment and adjustment-leg selection of Zhang et al. 2024 (§3 end, §4.1, Table II).

The robot is judged to be tipping when its FASM margin falls below the threshold ξ_f = 20°
(§5.1). It then rolls about the line through the feet of the two *effective support legs*, the
stance legs with the largest vertical foot force (§2.2, verified in §5.2). The swing leg that is
put down to stop the roll (the *adjustment leg*) is read from Table II.

Table II's check marks are lost in the text extraction. The mapping used here follows from the
six cases of §5.2 and from geometry: the adjustment leg is the swing leg lying between the two
edge legs when going round the body, i.e. on the far side of the tipping edge:

    (LF, LR) -> LM    (LR, RM) -> RR    (RM, LF) -> RF
    (LM, RF) -> LF    (RF, RR) -> RM    (RR, LM) -> LR

Leg names follow docs/architecture.md (paper legs 1-6 = LF LM LR RF RM RR; tripods {LF, LR, RM} and
{LM, RF, RR}).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from hexapod_envs.robots.heavy_duty.params import LEG_NAMES, TRIPODS

XI_F_DEG: float = 20.0
"""Instability threshold ξ_f [deg] on the FASM margin (Zhang et al. 2024 §5.1)."""

CCW_LEG_ORDER: tuple[str, ...] = ("LF", "LM", "LR", "RR", "RM", "RF")
"""Legs in counter-clockwise order round the body seen from above (x forward, y left, z up)."""

ADJUSTMENT_LEG: dict[frozenset[str], str] = {
    frozenset(("LF", "LR")): "LM",
    frozenset(("LR", "RM")): "RR",
    frozenset(("RM", "LF")): "RF",
    frozenset(("LM", "RF")): "LF",
    frozenset(("RF", "RR")): "RM",
    frozenset(("RR", "LM")): "LR",
}
"""Table II of Zhang et al. 2024: tipping edge (either order) -> adjustment leg."""


@dataclass(frozen=True)
class TippingJudgment:
    """Outcome of :func:`judge` for one control step.

    Attributes:
        tipping: margin below the threshold.
        margin_deg: the FASM margin that was judged [deg].
        threshold_deg: ξ_f used [deg].
        support_legs: the two effective support legs, larger vertical force first.
        edge: the same two legs ordered counter-clockwise seen from above (the tipping axis).
        adjustment_leg: Table II's leg for ``edge``; None when the stance is not a tripod
            (the table only covers tripod stance).
    """

    tipping: bool
    margin_deg: float
    threshold_deg: float
    support_legs: tuple[str, str]
    edge: tuple[str, str]
    adjustment_leg: str | None


def is_tipping(margin_deg: float, threshold_deg: float = XI_F_DEG) -> bool:
    """True when the FASM margin [deg] is below the instability threshold ξ_f [deg]."""
    return bool(margin_deg < threshold_deg)


def _check_legs(legs: Iterable[str], what: str) -> tuple[str, ...]:
    legs = tuple(legs)
    unknown = [leg for leg in legs if leg not in LEG_NAMES]
    if unknown:
        raise ValueError(f"unknown leg name(s) {unknown} in {what}; valid legs: {LEG_NAMES}")
    if len(set(legs)) != len(legs):
        raise ValueError(f"{what} lists a leg twice: {legs}")
    return legs


def effective_support_legs(
    vertical_forces: Mapping[str, float], stance_legs: Iterable[str]
) -> tuple[str, str]:
    """The two stance legs carrying the largest vertical foot force, larger first.

    Args:
        vertical_forces: vertical ground reaction force on each foot [N], keyed by leg name;
            must contain every stance leg (other legs are ignored). The recovery controller
            passes the component along the body's z axis, the frame in which it also measures
            the feet and the FASM; on a tilted body this can rank the legs otherwise than the
            world's z would.
        stance_legs: legs in stance (at least 2).
    """
    stance = _check_legs(stance_legs, "stance_legs")
    if len(stance) < 2:
        raise ValueError(f"need at least 2 stance legs to define a tipping edge, got {stance}")
    missing = [leg for leg in stance if leg not in vertical_forces]
    if missing:
        raise ValueError(
            f"vertical_forces has no entry for stance leg(s) {missing}; "
            f"it has {sorted(vertical_forces)}"
        )
    # Stable sort: ties keep the counter-clockwise order, so the result is deterministic.
    ranked = sorted(
        sorted(stance, key=CCW_LEG_ORDER.index),
        key=lambda leg: -float(vertical_forces[leg]),
    )
    return ranked[0], ranked[1]


def ccw_edge(
    leg_a: str,
    leg_b: str,
    stance_legs: Iterable[str],
    feet: Mapping[str, np.ndarray] | None = None,
) -> tuple[str, str]:
    """Order the edge (leg_a, leg_b) counter-clockwise seen from above.

    A counter-clockwise edge has the rest of the support polygon on its left. With ``feet``
    (body-frame foot positions [m] of the stance legs) this is decided geometrically, seen from
    body +z; without, from the legs' order round the body (:data:`CCW_LEG_ORDER`), which is the
    same for the standard stance layout.
    """
    stance = _check_legs(stance_legs, "stance_legs")
    _check_legs((leg_a, leg_b), "edge")
    if leg_a == leg_b or leg_a not in stance or leg_b not in stance:
        raise ValueError(
            f"edge ({leg_a}, {leg_b}) must be two different stance legs; stance legs: {stance}"
        )
    others = [leg for leg in stance if leg not in (leg_a, leg_b)]
    if feet is not None and others:
        p, q = np.asarray(feet[leg_a], float), np.asarray(feet[leg_b], float)
        rest = np.mean([np.asarray(feet[leg], float) for leg in others], axis=0)
        edge, to_rest = q - p, rest - p
        side = edge[0] * to_rest[1] - edge[1] * to_rest[0]
        scale = float(np.hypot(*edge[:2]) * np.hypot(*to_rest[:2]))
        if abs(side) > 1e-9 * scale:
            return (leg_a, leg_b) if side > 0.0 else (leg_b, leg_a)
    # Round-the-body order: b follows a among the stance legs going counter-clockwise.
    ring = [leg for leg in CCW_LEG_ORDER if leg in stance]
    i = ring.index(leg_a)
    return (leg_a, leg_b) if ring[(i + 1) % len(ring)] == leg_b else (leg_b, leg_a)


def tipping_edge(
    vertical_forces: Mapping[str, float],
    stance_legs: Iterable[str],
    feet: Mapping[str, np.ndarray] | None = None,
) -> tuple[str, str]:
    """The tipping axis: the effective support legs ordered counter-clockwise seen from above."""
    stance = tuple(stance_legs)
    a, b = effective_support_legs(vertical_forces, stance)
    return ccw_edge(a, b, stance, feet)


def select_adjustment_leg(stance_legs: Iterable[str], tipping_edge: tuple[str, str]) -> str:
    """Table II: the swing leg to put down when the robot tips about ``tipping_edge``.

    Args:
        stance_legs: the stance tripod, {LF, LR, RM} or {LM, RF, RR} (any order).
        tipping_edge: two legs of that tripod, in either order.

    Raises:
        ValueError: unknown leg names, a stance set that is not a tripod, or an edge whose legs
            are not both in the stance tripod (the message lists the valid choices).
    """
    stance = _check_legs(stance_legs, "stance_legs")
    edge = _check_legs(tipping_edge, "tipping_edge")
    tripod = next((t for t in TRIPODS if set(t) == set(stance)), None)
    if tripod is None:
        raise ValueError(
            f"Table II covers tripod stance only; stance_legs {stance} is not one of {TRIPODS}"
        )
    if len(edge) != 2 or not set(edge) <= set(tripod):
        valid = [
            tuple(sorted(k, key=CCW_LEG_ORDER.index)) for k in ADJUSTMENT_LEG if k <= set(tripod)
        ]
        raise ValueError(
            f"tipping_edge {edge} is not an edge of the stance tripod {tripod}; "
            f"valid edges: {valid}"
        )
    return ADJUSTMENT_LEG[frozenset(edge)]


def judge(
    margin_deg: float,
    vertical_forces: Mapping[str, float],
    stance_legs: Iterable[str],
    feet: Mapping[str, np.ndarray] | None = None,
    threshold_deg: float = XI_F_DEG,
) -> TippingJudgment:
    """Tipping judgment for one control step (Zhang et al. 2024 §3, §4.1).

    Args:
        margin_deg: current FASM margin [deg].
        vertical_forces: vertical foot force per leg [N] (see :func:`effective_support_legs`).
        stance_legs: legs in stance.
        feet: optional body-frame foot positions [m] to order the edge geometrically.
        threshold_deg: ξ_f [deg].
    """
    stance = tuple(stance_legs)
    support = effective_support_legs(vertical_forces, stance)
    edge = ccw_edge(*support, stance, feet)
    is_tripod = any(set(t) == set(stance) for t in TRIPODS)
    return TippingJudgment(
        tipping=is_tipping(margin_deg, threshold_deg),
        margin_deg=float(margin_deg),
        threshold_deg=float(threshold_deg),
        support_legs=support,
        edge=edge,
        adjustment_leg=select_adjustment_leg(stance, edge) if is_tripod else None,
    )
