"""ZMP estimate and margin (Coelho et al. 2024 eqs. 32-33) and Hirose's NESM, against closed
forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hexapod_envs.stability import nesm, nesm_per_edge, zmp, zmp_margin
from hexapod_envs.stability._geometry import hull_2d, signed_distance_2d

SQUARE = np.array([[1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]])


# ----------------------------------------------------------------------------------------- ZMP


def test_equal_forces_put_the_zmp_at_the_centroid():
    rng = np.random.default_rng(0)
    feet = rng.normal(size=(6, 3))
    np.testing.assert_allclose(zmp(feet, np.full(6, 37.5)), feet[:, :2].mean(axis=0), atol=1e-12)


def test_zmp_is_the_force_weighted_mean_of_x_and_y():
    feet = np.array([[0.0, 0.0, 0.3], [4.0, 0.0, -0.2], [0.0, 2.0, 0.0]])
    # (1*0 + 3*4 + 0*0)/6 = 2, (0 + 0 + 2*2)/6 = 2/3; z is ignored.
    np.testing.assert_allclose(zmp(feet, [1.0, 3.0, 2.0]), [2.0, 2.0 / 3.0], atol=1e-12)
    np.testing.assert_allclose(zmp(feet[:, :2], [1.0, 3.0, 2.0]), [2.0, 2.0 / 3.0], atol=1e-12)


def test_zmp_margin_of_a_square():
    assert zmp_margin(SQUARE, [10.0, 10.0, 10.0, 10.0]) == pytest.approx(1.0)
    # Load shifted to the front feet (x = +1): ZMP x = (3 - 1)/(3 + 1) = 0.5 -> margin 0.5.
    assert zmp_margin(SQUARE, [30.0, 10.0, 10.0, 30.0]) == pytest.approx(0.5)


def test_unloaded_feet_are_not_part_of_the_support_polygon():
    feet = np.vstack([SQUARE, [[5.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]]])
    forces = [10.0, 10.0, 10.0, 10.0, 0.0, -0.3]  # a foot in the air, a noisy negative reading
    np.testing.assert_allclose(zmp(feet, forces), [0.0, 0.0], atol=1e-12)
    assert zmp_margin(feet, forces) == pytest.approx(1.0)
    # Once the far foot carries load the polygon includes it.
    forces[4] = 1e-3
    assert zmp_margin(feet, forces) > 0.0
    assert zmp(feet, forces)[0] == pytest.approx(5.0 * 1e-3 / 40.001)
    # A custom threshold.
    assert zmp_margin(feet, forces, min_force=0.01) == pytest.approx(1.0)


def test_zmp_margin_of_a_loaded_triangle():
    feet = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 3.0, 0.0]])
    # Equal forces: ZMP at the centroid (1, 1), 1 from both legs, 1/sqrt(2) from the hypotenuse.
    assert zmp_margin(feet, [5.0, 5.0, 5.0]) == pytest.approx(1.0 / math.sqrt(2.0))
    # Nearly all load on foot 0: ZMP at (0.03, 0.03), 0.03 from both legs.
    assert zmp_margin(feet, [98.0, 1.0, 1.0]) == pytest.approx(0.03)


@pytest.mark.parametrize(
    "forces",
    [
        [10.0, 0.0, 0.0, 0.0],  # one loaded foot
        [10.0, 0.0, 10.0, 0.0],  # two loaded feet (a diagonal)
    ],
)
def test_fewer_than_three_loaded_feet_give_zero_margin(forces):
    assert zmp_margin(SQUARE, forces) == 0.0


def test_collinear_loaded_feet_give_zero_margin():
    feet = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    assert zmp_margin(feet, [1.0, 1.0, 1.0, 0.0]) == 0.0


def test_zmp_errors():
    with pytest.raises(ValueError, match="no foot carries"):
        zmp(SQUARE, np.zeros(4))
    with pytest.raises(ValueError, match="no foot carries"):
        zmp_margin(SQUARE, [-1.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"shape \(4,\)"):
        zmp(SQUARE, [1.0, 2.0])
    with pytest.raises(ValueError, match="NaN"):
        zmp_margin(SQUARE, [1.0, np.nan, 1.0, 1.0])
    with pytest.raises(ValueError, match="shape"):
        zmp(np.zeros((4, 4)), np.ones(4))


def _python_zmp_margin(feet: np.ndarray, forces: np.ndarray) -> tuple[float, float, float]:
    """Eqs. (32)-(33) as plain Python (the implementation before the compiled kernel): the
    loaded feet's force-weighted mean with Python's sums, and its signed distance to their hull."""
    rows = zip(feet[:, :2].tolist(), forces.tolist(), strict=True)
    loaded = [(x, y, f) for (x, y), f in rows if f > 1e-6]
    total = sum(f for _, _, f in loaded)
    px = sum(x * f for x, _, f in loaded) / total
    py = sum(y * f for _, y, f in loaded) / total
    if len(loaded) < 3:
        return px, py, 0.0
    xs, ys = [x for x, _, _ in loaded], [y for _, y, _ in loaded]
    try:
        hull = hull_2d(xs, ys)
    except ValueError:
        return px, py, 0.0
    margin = signed_distance_2d(xs, ys, hull, px, py)
    span = max(max(xs) - min(xs), max(ys) - min(ys))
    return px, py, (0.0 if abs(margin) <= 1e-12 * span else margin)


def test_zmp_and_margin_are_the_plain_python_to_the_bit():
    """The compiled kernel behind `zmp` and `zmp_margin` sums in the feet's order, as Python's
    ``sum`` does: equal bits on random stances with unloaded, barely loaded and collinear feet."""
    rng = np.random.default_rng(7)
    outcomes = {"polygon": 0, "no polygon": 0, "collinear": 0}
    for k in range(3000):
        n = int(rng.integers(1, 7))
        feet = rng.normal(scale=0.2, size=(n, 3))
        if k % 10 == 0:  # feet on a line
            feet[:, 1] = 0.5 * feet[:, 0]
        forces = rng.uniform(0.0, 40.0, n) * (rng.uniform(size=n) > 0.3)
        forces[rng.uniform(size=n) < 0.1] = 1e-7  # at or below min_force: unloaded
        if not (forces > 1e-6).any():
            continue
        px, py, margin = _python_zmp_margin(feet, forces)
        assert zmp_margin(feet, forces) == margin
        assert zmp(feet[:, :2], forces).tolist() == [px, py]
        outcomes["polygon" if margin != 0.0 else "no polygon"] += 1
        if k % 10 == 0 and (forces > 1e-6).sum() >= 3:
            assert margin == 0.0  # loaded feet on a line: no polygon
            outcomes["collinear"] += 1
    assert min(outcomes.values()) > 20


# ---------------------------------------------------------------------------------------- NESM


def brute_force_rise(p, q, cog, up, steps: int = 200_001) -> float:
    """Max CoG height gain when rotating the CoG about the line p-q (dense sampling)."""
    a = (q - p) / np.linalg.norm(q - p)
    r = cog - p
    angles = np.linspace(-math.pi, math.pi, steps)
    # Rodrigues: r(t) = r cos t + (a × r) sin t + a (a·r)(1 - cos t)
    rotated = (
        np.outer(np.cos(angles), r)
        + np.outer(np.sin(angles), np.cross(a, r))
        + np.outer(1.0 - np.cos(angles), a * (a @ r))
    )
    return float((rotated @ up).max() - r @ up)


@pytest.mark.parametrize(("a", "b", "h"), [(1.0, 0.5, 0.8), (0.4, 2.0, 1.0), (1.0, 1.0, 0.2)])
def test_nesm_of_a_symmetric_box(a, b, h):
    feet = np.array([[a, b, 0.0], [-a, b, 0.0], [-a, -b, 0.0], [a, -b, 0.0]])
    w = min(a, b)
    assert nesm(feet, [0.0, 0.0, h]) == pytest.approx(math.hypot(w, h) - h, abs=1e-12)
    heights, edges = nesm_per_edge(feet, [0.0, 0.0, h])
    for (i, j), rise in zip(edges.tolist(), heights, strict=True):
        half = b if feet[i, 1] == feet[j, 1] else a  # edge along x: at y = ±b
        assert rise == pytest.approx(math.hypot(half, h) - h, abs=1e-12)


@pytest.mark.parametrize("phi_deg", [5.0, 20.0, 40.0])
def test_nesm_with_tilted_gravity(phi_deg):
    """Gravity tilted by phi toward -y: the downhill edge (y = -b) needs r(1 - cos(alpha - phi)),
    r = sqrt(b² + h²), alpha = atan(b/h); beyond the tip-over angle the margin is negative."""
    b, h = 0.6, 0.9
    feet = np.array([[2.0, b, 0.0], [-2.0, b, 0.0], [-2.0, -b, 0.0], [2.0, -b, 0.0]])
    phi = math.radians(phi_deg)
    gravity = (0.0, -math.sin(phi), -math.cos(phi))
    r, alpha = math.hypot(b, h), math.atan2(b, h)
    expected = r * (1.0 - math.cos(alpha - phi))
    if phi > alpha:
        expected = -expected
    assert nesm(feet, [0.0, 0.0, h], gravity=gravity) == pytest.approx(expected, abs=1e-12)


def test_nesm_over_an_inclined_edge_is_distance_times_cos_psi():
    """Edge axis inclined by psi through the origin, CoG horizontally d away from it at the
    axis' height: the top of the CoG's circle is d cos(psi) above it (Hirose's cos psi)."""
    psi, d, length = math.radians(30.0), 0.4, 3.0
    axis = np.array([math.cos(psi), 0.0, math.sin(psi)])
    feet = np.array([-length * axis, length * axis, [0.0, 5.0, 0.0]])
    heights, edges = nesm_per_edge(feet, [0.0, d, 0.0])
    edge = [k for k, (i, j) in enumerate(edges.tolist()) if {i, j} == {0, 1}]
    assert heights[edge[0]] == pytest.approx(d * math.cos(psi), abs=1e-12)


def test_nesm_matches_brute_force_rotation_on_random_stances():
    rng = np.random.default_rng(4)
    for _ in range(20):
        k = int(rng.integers(3, 7))
        angles = np.sort(rng.uniform(0.0, 2.0 * math.pi, size=k))
        feet = np.column_stack(
            [2.0 * np.cos(angles), 1.5 * np.sin(angles), rng.normal(scale=0.3, size=k)]
        )
        cog = np.array([*rng.normal(scale=0.2, size=2), rng.uniform(0.5, 1.5)])
        g = np.array([*rng.normal(scale=0.2, size=2), -1.0])
        up = -g / np.linalg.norm(g)
        heights, edges = nesm_per_edge(feet, cog, gravity=g)
        for (i, j), rise in zip(edges.tolist(), heights, strict=True):
            assert abs(rise) == pytest.approx(brute_force_rise(feet[i], feet[j], cog, up), abs=1e-8)


def test_nesm_is_negative_outside_and_zero_on_the_boundary():
    assert nesm(SQUARE, [0.0, -1.3, 0.4]) == pytest.approx(-(0.5 - 0.4), abs=1e-12)
    assert nesm(SQUARE, [0.0, -1.0, 0.4]) == pytest.approx(0.0, abs=1e-12)


def test_nesm_errors():
    with pytest.raises(ValueError, match="collinear"):
        nesm([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [0, 1, 1])
    with pytest.raises(ValueError, match="gravity must be a non-zero"):
        nesm(SQUARE, [0, 0, 1], gravity=[0, 0, 0])
