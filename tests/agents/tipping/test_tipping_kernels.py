"""The recovery controller's compiled kernels (agents.tipping._compiled) against the numpy
expressions they replaced, bit for bit (random inputs of the controller's sizes)."""

import mujoco
import numpy as np
import pytest
from helpers.blas_bits import REASON, numba_blas_matches_numpy

from agents.tipping import _compiled
from agents.tipping.body_model import forces_to_body, quat_to_matrix

RNG_SEEDS = range(20)
needs_same_blas = pytest.mark.skipif(not numba_blas_matches_numpy(), reason=REASON)


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@needs_same_blas
@pytest.mark.parametrize("seed", RNG_SEEDS)
def test_body_sensing_is_rotation_forces_and_contact_test(seed):
    rng = np.random.default_rng(seed)
    quat = rng.normal(size=4)
    forces_world = rng.normal(scale=2e4, size=(6, 3))
    contact_sq = float(rng.uniform(1e6, 4e8))
    rot, forces, loaded = _compiled.body_sensing(quat, forces_world, contact_sq)
    expected_rot = quat_to_matrix(quat)
    expected_forces = forces_to_body(forces_world, expected_rot)
    assert _same(rot, expected_rot) and _same(forces, expected_forces)
    # quat_to_matrix runs the same kernel: the rotation itself is checked against MuJoCo's
    independent = np.zeros(9)
    mujoco.mju_quat2Mat(independent, quat / np.linalg.norm(quat))
    np.testing.assert_allclose(rot, independent.reshape(3, 3), atol=1e-12)
    assert _same(loaded, np.add.reduce(expected_forces * expected_forces, axis=1) > contact_sq)


def _cross(a, b):
    """The former desired_wrench's cross product (plain floats)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))


@needs_same_blas
@pytest.mark.parametrize("seed", RNG_SEEDS)
def test_newton_euler_wrench_is_the_former_expression(seed):
    rng = np.random.default_rng(seed)
    mass = float(rng.uniform(100.0, 6000.0))
    inertia = rng.normal(scale=1e3, size=(3, 3))
    g, a, w, wd = (rng.normal(size=3) for _ in range(4))
    expected = np.concatenate([mass * (a - g), inertia @ wd + _cross(w, inertia @ w)])
    assert _same(_compiled.newton_euler_wrench(mass, inertia, g, a, w, wd), expected)


@needs_same_blas
@pytest.mark.parametrize("seed", RNG_SEEDS)
def test_force_error_system_and_internal_part(seed):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(3, 7))
    a_mat = rng.normal(size=(6, 3 * k))
    planned, measured = rng.normal(scale=1e4, size=(2, k, 3))
    error, a_at, a_error = _compiled.force_error_system(planned, measured, a_mat)
    expected_error = (planned - measured).reshape(-1)
    assert _same(error, expected_error)
    assert _same(a_at, a_mat @ a_mat.T) and _same(a_error, a_mat @ expected_error)
    y = rng.normal(size=6)
    assert _same(_compiled.internal_part(error, a_mat, y), expected_error - a_mat.T @ y)


@needs_same_blas
@pytest.mark.parametrize("seed", RNG_SEEDS)
def test_qp_outcome_is_the_former_bookkeeping(seed):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(3, 7))
    g_mat, h_vec = rng.normal(size=(9 * k, 3 * k)), rng.normal(size=9 * k)
    a_mat, wrench = rng.normal(size=(6, 3 * k)), rng.normal(size=6)
    x_scaled, scale = rng.normal(size=3 * k), float(rng.uniform(1.0, 1e5))
    slack, violation, x, achieved, residual = _compiled.qp_outcome(
        g_mat, h_vec, x_scaled, scale, a_mat, wrench
    )
    expected_slack = (h_vec - g_mat @ x_scaled) * scale
    assert _same(slack, expected_slack)
    assert violation == max(0.0, -float(np.minimum.reduce(expected_slack)))
    assert _same(x, x_scaled * scale) and _same(achieved, a_mat @ (x_scaled * scale))
    assert _same(residual, a_mat @ (x_scaled * scale) - wrench)


@needs_same_blas
@pytest.mark.parametrize("seed", RNG_SEEDS)
def test_tipping_products_are_the_former_numpy(seed):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(3, 7))
    m = int(rng.integers(3, k + 1))
    ima, couple = rng.normal(size=(2, m, 3, 3))
    moment_rows = rng.normal(size=(3, 3 * k))
    expected = couple @ moment_rows
    blocks = expected.reshape(m, 3, k, 3)
    np.add(blocks, ima.reshape(m, 3, 1, 3), out=blocks)
    assert _same(_compiled.tipping_products(ima, couple, moment_rows), expected)


@pytest.mark.parametrize("seed", RNG_SEEDS)
def test_offset_kernels_are_the_fancy_index_expressions(seed):
    rng = np.random.default_rng(seed)
    legs = np.sort(rng.choice(6, size=int(rng.integers(3, 7)), replace=False)).astype(np.intp)
    offsets = rng.normal(scale=0.003, size=(6, 3))
    change = rng.normal(scale=0.004, size=(len(legs), 3))
    gain, limit = float(rng.uniform(0.1, 1.0)), np.array([0.004, 0.003, 0.005])
    expected = offsets.copy()
    expected[legs] = np.minimum(np.maximum(expected[legs] + gain * change, -limit), limit)
    _compiled.add_offsets(offsets, legs, change, gain, limit)
    assert _same(offsets, expected)
    nominal, targets = rng.normal(size=(2, 6, 3))
    expected_targets = targets.copy()
    expected_targets[legs] = nominal[legs] + offsets[legs]
    _compiled.offset_targets(targets, nominal, offsets, legs)
    assert _same(targets, expected_targets)
