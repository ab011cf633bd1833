"""Closed-form tests of the Force-Angle Stability Measure (Zhang et al. 2024 eqs. 5-9)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from hexapod_envs.stability import FasmResult, fasm, support_polygon

W = 5000.0 * 9.81  # weight of the heavy-duty hexapod [N]
GRAVITY_FORCE = np.array([0.0, 0.0, -W])

# Zhang et al. 2024 stance: feet at x = ±2.4 m, y = ±1.9 m, 1.75 m below the CoG (the footholds of
# Zhang et al. 2024 §5.2).
HEXAPOD_FEET = {
    "LF": (2.4, 1.9, -1.75),
    "LM": (0.0, 1.9, -1.75),
    "LR": (-2.4, 1.9, -1.75),
    "RF": (2.4, -1.9, -1.75),
    "RM": (0.0, -1.9, -1.75),
    "RR": (-2.4, -1.9, -1.75),
}


def box_feet(half_length: float, half_width: float) -> np.ndarray:
    """Four feet on z = 0: front-left, rear-left, rear-right, front-right."""
    a, b = half_length, half_width
    return np.array([[a, b, 0.0], [-a, b, 0.0], [-a, -b, 0.0], [a, -b, 0.0]])


def angle_of_edge(result: FasmResult, i: int, j: int) -> float:
    """Angle [deg] of the edge between feet i and j (either direction)."""
    for (p, q), angle in zip(result.edges.tolist(), result.angles_deg, strict=True):
        if {p, q} == {i, j}:
            return float(angle)
    raise AssertionError(f"edge ({i}, {j}) is not in {result.edges.tolist()}")


def angles_by_edge(result: FasmResult) -> dict[tuple[int, int], float]:
    """{(i, j): angle [deg]} for the directed (counter-clockwise) edges of a result."""
    return {
        (int(i), int(j)): float(angle)
        for (i, j), angle in zip(result.edges, result.angles_deg, strict=True)
    }


def rotation(axis, angle: float) -> np.ndarray:
    """Rotation matrix about ``axis`` by ``angle`` [rad] (Rodrigues)."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * kx @ kx


def reference_fasm(feet, cog, force, moment, up) -> np.ndarray:
    """Literal transcription of Zhang et al. 2024 eqs. 5-8 (acos form with the sign rule), numpy."""
    feet = np.asarray(feet, dtype=float)
    hull = support_polygon(feet, up=up)
    angles = []
    for j in range(len(hull)):
        p, q = feet[hull[j]], feet[hull[(j + 1) % len(hull)]]
        a = (q - p) / np.linalg.norm(q - p)
        proj = np.eye(3) - np.outer(a, a)
        l_vec = proj @ (q - cog)
        l_hat = l_vec / np.linalg.norm(l_vec)
        f_i = proj @ force
        n_i = np.outer(a, a) @ moment
        f_ni = np.cross(l_hat, n_i) / np.linalg.norm(l_vec)
        f_star = f_i + f_ni
        f_hat = f_star / np.linalg.norm(f_star)
        theta = math.degrees(math.acos(np.clip(f_hat @ l_hat, -1.0, 1.0)))
        angles.append(theta if np.cross(l_hat, f_hat) @ a > 0 else -theta)
    return np.array(angles)


@pytest.mark.parametrize(
    ("half_length", "half_width", "height"), [(1.0, 0.5, 0.8), (0.3, 2.0, 1.5)]
)
def test_box_edge_angle_is_atan_half_width_over_height(half_length, half_width, height):
    feet = box_feet(half_length, half_width)
    result = fasm(feet, [0.0, 0.0, height], GRAVITY_FORCE)
    side = math.degrees(math.atan(half_width / height))  # edges along x, at y = ±half_width
    end = math.degrees(math.atan(half_length / height))  # edges along y, at x = ±half_length
    assert angle_of_edge(result, 0, 1) == pytest.approx(side, abs=1e-9)
    assert angle_of_edge(result, 2, 3) == pytest.approx(side, abs=1e-9)
    assert angle_of_edge(result, 1, 2) == pytest.approx(end, abs=1e-9)
    assert angle_of_edge(result, 3, 0) == pytest.approx(end, abs=1e-9)
    assert result.margin_deg == pytest.approx(min(side, end), abs=1e-9)
    assert result.angles_deg[result.edge_index] == result.margin_deg
    assert tuple(result.edges[result.edge_index]) == result.edge
    np.testing.assert_allclose(result.tipping_forces, W * np.ones(4))


@pytest.mark.parametrize("phi_deg", [5.0, 20.0, 45.0])
def test_tilting_gravity_lowers_downhill_edge_and_raises_uphill_edge(phi_deg):
    a, b, h = 1.2, 0.6, 0.9
    feet = box_feet(a, b)
    phi = math.radians(phi_deg)
    # Gravity tilted by phi about x toward -y: the edge at y = -b (feet 2, 3) is downhill.
    force = W * np.array([0.0, -math.sin(phi), -math.cos(phi)])
    result = fasm(feet, [0.0, 0.0, h], force, up=(0.0, 0.0, 1.0))
    side = math.degrees(math.atan(b / h))
    assert angle_of_edge(result, 2, 3) == pytest.approx(side - phi_deg, abs=1e-9)
    assert angle_of_edge(result, 0, 1) == pytest.approx(side + phi_deg, abs=1e-9)
    # The front and rear edges are perpendicular to the tilt axis' plane: unchanged.
    assert angle_of_edge(result, 1, 2) == pytest.approx(math.degrees(math.atan(a / h)), abs=1e-9)
    assert angle_of_edge(result, 3, 0) == pytest.approx(math.degrees(math.atan(a / h)), abs=1e-9)
    assert result.margin_deg == pytest.approx(side - phi_deg, abs=1e-9)  # 33.7 deg - phi
    assert (result.margin_deg < 0.0) == (phi_deg > side)
    if phi_deg > side:
        assert set(result.edge) == {2, 3}


@pytest.mark.parametrize("moment_ratio", [-0.4, 0.1, 0.3, 0.9])
def test_pure_moment_about_an_edge_axis(moment_ratio):
    """A moment M about the edge's own (ccw) axis a adds the equivalent couple force M/|l|.

    Box with half-width b, CoG height h, weight W. For the edge at y = -b (a = +x, l from the CoG
    to the edge = (0, -b, -h), |l| = r = sqrt(b² + h²)), t̂ = a × l̂ = (0, h, -b)/r, and
    f*·l̂ = W h / r, f*·t̂ = W b / r - M / r, so theta = atan((b - M/W) / h): the moment acts like
    moving the CoG by M/W toward the edge. The opposite edge (a = -x) gets atan((b + M/W) / h);
    the end edges (a = ±y) are unaffected. Dropping the 1/|l| in f_ni would give
    atan((b - M r/W) / h) instead.
    """
    a, b, h = 1.0, 0.5, 0.8
    moment_x = moment_ratio * W * b  # [N m]
    result = fasm(box_feet(a, b), [0.0, 0.0, h], GRAVITY_FORCE, moment=[moment_x, 0.0, 0.0])
    shift = moment_x / W
    assert angle_of_edge(result, 2, 3) == pytest.approx(
        math.degrees(math.atan((b - shift) / h)), abs=1e-9
    )
    assert angle_of_edge(result, 0, 1) == pytest.approx(
        math.degrees(math.atan((b + shift) / h)), abs=1e-9
    )
    assert angle_of_edge(result, 1, 2) == pytest.approx(math.degrees(math.atan(a / h)), abs=1e-9)
    # Same as moving the CoG by M/W toward -y under gravity alone.
    shifted = fasm(box_feet(a, b), [0.0, -shift, h], GRAVITY_FORCE)
    np.testing.assert_allclose(result.angles_deg, shifted.angles_deg, atol=1e-9)


def test_moment_normal_to_the_support_plane_changes_nothing_on_level_ground():
    feet, cog = box_feet(1.0, 0.5), [0.1, -0.05, 0.7]
    plain = fasm(feet, cog, GRAVITY_FORCE)
    yawed = fasm(feet, cog, GRAVITY_FORCE, moment=[0.0, 0.0, 1e5])
    np.testing.assert_allclose(yawed.angles_deg, plain.angles_deg, atol=1e-12)


def test_cog_outside_polygon_gives_negative_margin_over_that_edge():
    feet = box_feet(1.0, 0.5)
    result = fasm(feet, [0.0, -0.7, 0.8], GRAVITY_FORCE)
    assert result.margin_deg == pytest.approx(-math.degrees(math.atan(0.2 / 0.8)), abs=1e-9)
    assert set(result.edge) == {2, 3}


def test_hexapod_six_legs_and_tripod_match_seed_geometry():
    names = list(HEXAPOD_FEET)
    feet = np.array([HEXAPOD_FEET[n] for n in names])
    six = fasm(feet, np.zeros(3), GRAVITY_FORCE)
    assert six.margin_deg == pytest.approx(math.degrees(math.atan(1.9 / 1.75)), abs=1e-9)
    assert six.margin_deg == pytest.approx(47.35, abs=0.01)  # paper: "approximately 48"
    assert len(six.edges) == 4  # LM and RM lie on the long edges and are dropped
    assert {names.index("LM"), names.index("RM")}.isdisjoint(six.edges.ravel().tolist())

    tripod = ["LF", "LR", "RM"]
    result = fasm(np.array([HEXAPOD_FEET[n] for n in tripod]), np.zeros(3), GRAVITY_FORCE)
    # Distance from the CoG's projection to the line LR-RM: |(-2.4, 1.9) x (2.4, -3.8)| / |...|
    dist = abs(-2.4 * -3.8 - 1.9 * 2.4) / math.hypot(2.4, 3.8)
    assert result.margin_deg == pytest.approx(math.degrees(math.atan(dist / 1.75)), abs=1e-9)
    assert result.margin_deg == pytest.approx(30.10, abs=0.01)  # paper: 31.41
    assert tripod.index("RM") in result.edge
    assert angle_of_edge(result, 0, 1) == pytest.approx(six.margin_deg, abs=1e-9)


def test_shuffled_feet_give_same_margin_and_edge_indices_into_shuffled_array():
    rng = np.random.default_rng(3)
    feet = np.array(list(HEXAPOD_FEET.values())) + rng.normal(scale=0.05, size=(6, 3))
    cog = np.array([0.3, -0.2, 0.05])
    force = np.array([2000.0, -4000.0, -W])
    moment = np.array([3000.0, 1000.0, -500.0])
    base = fasm(feet, cog, force, moment)
    for _ in range(5):
        perm = rng.permutation(6)
        shuffled = feet[perm]
        result = fasm(shuffled, cog, force, moment)
        assert result.margin_deg == pytest.approx(base.margin_deg, abs=1e-9)
        np.testing.assert_allclose(np.sort(result.angles_deg), np.sort(base.angles_deg), atol=1e-9)
        i, j = result.edge
        np.testing.assert_array_equal(shuffled[[i, j]], feet[list(base.edge)])


@pytest.mark.parametrize("perm", list(itertools.permutations(range(3))))
def test_tripod_in_any_order(perm):
    tripod = np.array([HEXAPOD_FEET[n] for n in ("LF", "LR", "RM")])
    feet = tripod[list(perm)]
    rm = list(perm).index(2)  # where RM went
    cog = np.array([0.4, 0.0, 0.0])  # forward: the front diagonal RM-LF is the critical edge
    result = fasm(feet, cog, GRAVITY_FORCE)
    expected = fasm(tripod, cog, GRAVITY_FORCE)
    assert result.margin_deg == pytest.approx(expected.margin_deg, abs=1e-12)
    assert result.margin_deg < fasm(tripod, np.zeros(3), GRAVITY_FORCE).margin_deg
    assert set(result.edge) == {rm, list(perm).index(0)}
    i, j = result.edge
    np.testing.assert_array_equal(feet[[i, j]], tripod[list(expected.edge)])


def test_matches_literal_transcription_of_the_paper_on_random_cases():
    rng = np.random.default_rng(11)
    for _ in range(200):
        k = int(rng.integers(3, 7))
        angles = np.sort(rng.uniform(0.0, 2.0 * math.pi, size=k))
        radii = rng.uniform(0.5, 2.0, size=k)
        feet = np.column_stack(
            [radii * np.cos(angles), radii * np.sin(angles), rng.normal(scale=0.1, size=k)]
        )
        cog = np.array([*rng.normal(scale=0.3, size=2), rng.uniform(0.3, 1.5)])
        force = np.array([*rng.normal(scale=0.4, size=2), -1.0]) * rng.uniform(10.0, 1e4)
        moment = rng.normal(size=3) * rng.uniform(0.0, 1e3)
        up = (0.0, 0.0, 1.0)
        result = fasm(feet, cog, force, moment, up=up)
        np.testing.assert_allclose(
            result.angles_deg, reference_fasm(feet, cog, force, moment, up), atol=1e-5
        )
        assert result.margin_deg == pytest.approx(result.angles_deg.min())


def test_invariant_to_rigid_motion_of_the_whole_scene():
    rng = np.random.default_rng(5)
    feet = np.array(list(HEXAPOD_FEET.values()))[[0, 2, 3, 4, 5]]
    cog = np.array([0.2, 0.1, 0.0])
    force = np.array([1000.0, -3000.0, -W])
    moment = np.array([2e4, -1e4, 3e3])
    base = fasm(feet, cog, force, moment)
    for _ in range(5):
        rot = rotation(rng.normal(size=3), rng.uniform(0.0, math.pi))
        shift = rng.normal(scale=10.0, size=3)
        moved = fasm(feet @ rot.T + shift, rot @ cog + shift, rot @ force, rot @ moment)
        assert angles_by_edge(moved) == pytest.approx(angles_by_edge(base), abs=1e-8)


def test_default_up_points_to_the_cog_side():
    """The default "above" follows the CoG, so an upside-down scene gives the same angles."""
    feet, cog = box_feet(1.0, 0.5), np.array([0.1, 0.0, 0.8])
    flip = np.diag([1.0, -1.0, -1.0])  # rotation by pi about x
    upright = fasm(feet, cog, GRAVITY_FORCE)
    flipped = fasm(feet @ flip, flip @ cog, flip @ GRAVITY_FORCE)
    assert angles_by_edge(flipped) == pytest.approx(angles_by_edge(upright), abs=1e-9)
    # Three-feet fast path, both ways up, against the explicit "above" direction.
    for rot in (np.eye(3), flip):
        args = (feet[:3] @ rot.T, rot @ cog, rot @ GRAVITY_FORCE)
        explicit = fasm(*args, up=rot @ np.array([0.0, 0.0, 1.0]))
        assert angles_by_edge(fasm(*args)) == pytest.approx(angles_by_edge(explicit), abs=1e-12)
        # Triangle (1, .5), (-1, .5), (-1, -.5); the CoG (0.1, 0) is 0.1/sqrt(5) m outside the
        # diagonal, 0.5 m inside the side edge and 1.1 m inside the rear edge, 0.8 m up.
        expected = np.degrees(np.arctan(np.array([-0.1 / math.sqrt(5.0), 0.5, 1.1]) / 0.8))
        np.testing.assert_allclose(np.sort(explicit.angles_deg), expected, atol=1e-9)


def test_tripod_on_a_slope_with_default_up_matches_level_case():
    """Feet and CoG on a 25 deg slope with gravity along the slope normal = level ground."""
    feet = np.array([HEXAPOD_FEET[n] for n in ("LF", "LR", "RM")])
    rot = rotation([1.0, 0.3, 0.0], math.radians(25.0))
    level = fasm(feet, np.zeros(3), GRAVITY_FORCE)
    sloped = fasm(feet @ rot.T, np.zeros(3), rot @ GRAVITY_FORCE)
    assert sloped.margin_deg == pytest.approx(level.margin_deg, abs=1e-9)


def test_force_along_an_edge_gives_zero_angle_for_that_edge():
    result = fasm(box_feet(1.0, 0.5), [0.0, 0.0, 0.8], [100.0, 0.0, 0.0])
    assert angle_of_edge(result, 0, 1) == 0.0
    assert angle_of_edge(result, 2, 3) == 0.0
    # Pushing forward (+x) tips the body over the front edge (feet 3, 0): the force is rotated
    # atan(0.8 / 1.0) beyond the line from the CoG to that edge; the rear edge is very stable.
    assert angle_of_edge(result, 3, 0) == pytest.approx(-math.degrees(math.atan(0.8)), abs=1e-9)
    assert angle_of_edge(result, 1, 2) == pytest.approx(
        180.0 - math.degrees(math.atan(0.8)), abs=1e-9
    )


@pytest.mark.parametrize(
    ("feet", "message"),
    [
        ([[0, 0, 0], [1, 0, 0]], "at least 3"),
        ([[0, 0, 0], [1, 1, 0], [2, 2, 0]], "collinear"),
        ([[0, 0, 0], [1, 1, 0], [2, 2, 0], [3, 3, 0]], "collinear"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.5, 0.0], [0, 0, 0]], None),
        ([[0, 0], [1, 0], [0, 1]], "shape"),
        ([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]], "NaN"),
    ],
)
def test_bad_feet(feet, message):
    if message is None:  # duplicates and an interior point are fine
        assert fasm(feet, [0.5, 0.5, 1.0], GRAVITY_FORCE).edges.shape == (4, 2)
        return
    with pytest.raises(ValueError, match=message):
        fasm(feet, [0.0, 0.0, 1.0], GRAVITY_FORCE)


def test_zero_force_cog_on_edge_and_bad_vectors_are_errors():
    feet = box_feet(1.0, 0.5)
    with pytest.raises(ValueError, match="force is zero"):
        fasm(feet, [0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="CoG lies on the line"):
        fasm(feet, [0.0, 0.5, 0.0], GRAVITY_FORCE, up=(0, 0, 1))
    with pytest.raises(ValueError, match="cog must be a 3-vector"):
        fasm(feet, [0.0, 1.0], GRAVITY_FORCE)
    with pytest.raises(ValueError, match="moment must be a 3-vector"):
        fasm(feet, [0.0, 0.0, 1.0], GRAVITY_FORCE, moment=[1.0])
    with pytest.raises(ValueError, match="up must be a non-zero"):
        fasm(feet, [0.0, 0.0, 1.0], GRAVITY_FORCE, up=[0.0, 0.0, 0.0])


def test_result_is_frozen_and_reports_radians():
    result = fasm(box_feet(1.0, 0.5), [0.0, 0.0, 0.5], GRAVITY_FORCE)
    assert result.margin_rad == pytest.approx(math.atan(1.0))
    with pytest.raises(AttributeError):
        result.margin_deg = 0.0  # type: ignore[misc]
