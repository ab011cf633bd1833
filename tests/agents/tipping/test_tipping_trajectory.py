"""Adjustment time budget (Zhang et al. 2024 eq. 15) and quintic foot trajectory."""

import math

import numpy as np
import pytest

from agents.tipping.trajectory import (
    KAPPA,
    T_MAX,
    T_MIN,
    QuinticTrajectory,
    time_budget,
    zero_crossing_time,
)


def first_positive_root(margin, rate, accel):
    """Smallest positive real root of margin + rate t + ½ accel t² = 0 (numpy reference)."""
    roots = np.roots([0.5 * accel, rate, margin])
    real = [r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0.0]
    return min(real) if real else math.inf


def test_linear_forecast_closed_form():
    # S = 20°, falling at 10°/s, no acceleration: zero in 2 s; ϰ = 0.7 -> 1.4 s.
    assert zero_crossing_time(20.0, -10.0, 0.0) == pytest.approx(2.0)
    assert time_budget(20.0, -10.0, 0.0, kappa=0.7) == pytest.approx(1.4)
    assert zero_crossing_time(20.0, -10.0, 1e-12) == pytest.approx(2.0)


def test_accelerating_decline_closed_form():
    # 20 - 10 t - 5 t² = 0 -> t = -1 + sqrt(5). Eq. (15)'s printed "+" branch with a_s = -5
    # (its t² coefficient) gives (10 + sqrt(500)) / -10 < 0, the other root.
    t = zero_crossing_time(20.0, -10.0, -10.0)
    assert t == pytest.approx(math.sqrt(5.0) - 1.0)
    printed = (10.0 + math.sqrt(100.0 - 4.0 * -5.0 * 20.0)) / (2.0 * -5.0)
    assert printed < 0.0
    minus_branch = (10.0 - math.sqrt(100.0 - 4.0 * -5.0 * 20.0)) / (2.0 * -5.0)
    assert t == pytest.approx(minus_branch)


def test_slowing_decline_takes_the_first_crossing():
    # 20 - 20 t + 4 t² = 0: roots (5 ± sqrt 5) / 2; the margin reaches 0 first at the smaller.
    t = zero_crossing_time(20.0, -20.0, 8.0)
    assert t == pytest.approx((5.0 - math.sqrt(5.0)) / 2.0)


@pytest.mark.parametrize(
    ("margin", "rate", "accel"),
    [(19.5, -3.0, -2.0), (15.0, -8.0, 1.0), (10.0, -1.0, -30.0), (19.9, -0.5, 0.01)],
)
def test_crossing_matches_numpy_roots(margin, rate, accel):
    assert zero_crossing_time(margin, rate, accel) == pytest.approx(
        first_positive_root(margin, rate, accel), rel=1e-12
    )


def test_fallbacks():
    # No real root: the decline turns round before 0 -> no urgency, t_max.
    assert zero_crossing_time(20.0, -2.0, 10.0) == math.inf
    assert time_budget(20.0, -2.0, 10.0) == T_MAX
    # Margin not falling.
    assert time_budget(20.0, 0.0, 0.0) == T_MAX
    assert time_budget(20.0, 1.0, 0.5) == T_MAX
    # Rising but decelerating: crosses eventually.
    assert zero_crossing_time(10.0, 2.0, -4.0) == pytest.approx(first_positive_root(10, 2, -4))
    # Already at or past the tipping point -> act as fast as allowed.
    assert zero_crossing_time(-1.0, -5.0, 0.0) == 0.0
    assert time_budget(-1.0, -5.0, 0.0) == T_MIN
    # Clamping.
    assert time_budget(19.0, -1000.0, 0.0) == T_MIN
    assert time_budget(19.0, -1.0, 0.0) == T_MAX
    assert T_MIN < KAPPA * 1.9 < T_MAX
    assert time_budget(19.0, -10.0, 0.0) == pytest.approx(KAPPA * 1.9)


def test_bad_time_budget_arguments():
    with pytest.raises(ValueError, match="kappa"):
        time_budget(20.0, -10.0, 0.0, kappa=1.0)
    with pytest.raises(ValueError, match="t_min"):
        time_budget(20.0, -10.0, 0.0, t_min=2.0, t_max=1.0)
    with pytest.raises(ValueError, match="finite"):
        zero_crossing_time(float("nan"), -1.0, 0.0)


@pytest.mark.parametrize("clearance", [0.0, 0.35])
def test_quintic_boundary_conditions_exact(clearance):
    rng = np.random.default_rng(7)
    p0, v0, a0, p1, v1, a1 = rng.normal(size=(6, 3))
    duration = 1.37
    traj = QuinticTrajectory.plan(p0, p1, duration, v0, a0, v1, a1, clearance=clearance)
    for t, p, v, a in ((0.0, p0, v0, a0), (duration, p1, v1, a1)):
        pos, vel, acc = traj.evaluate(t)
        np.testing.assert_allclose(pos, p, atol=1e-12)
        np.testing.assert_allclose(vel, v, atol=1e-12)
        np.testing.assert_allclose(acc, a, atol=1e-11)


def test_quintic_derivatives_are_consistent_and_vectorised():
    rng = np.random.default_rng(3)
    p0, v0, a0, p1, v1, a1 = rng.normal(size=(6, 3))
    traj = QuinticTrajectory.plan(p0, p1, 2.0, v0, a0, v1, a1, clearance=0.2)
    t = np.linspace(0.05, 1.95, 7)
    h = 1e-6
    pos, vel, acc = traj.evaluate(t)
    assert pos.shape == vel.shape == acc.shape == (7, 3)
    np.testing.assert_allclose(
        (traj.position(t + h) - traj.position(t - h)) / (2 * h), vel, atol=1e-7
    )
    np.testing.assert_allclose(
        (traj.velocity(t + h) - traj.velocity(t - h)) / (2 * h), acc, atol=1e-6
    )
    grid = traj.position(np.zeros((2, 4)))
    assert grid.shape == (2, 4, 3)


def test_quintic_rest_to_rest_is_symmetric_and_clamped():
    p0, p1 = np.array([-2.4, -1.25, -1.2]), np.array([-2.4, -2.5, -1.75])
    traj = QuinticTrajectory.plan(p0, p1, 1.0)
    np.testing.assert_allclose(traj.position(0.5), 0.5 * (p0 + p1), atol=1e-12)
    # Classic minimum-jerk profile: peak speed 15/8 of the mean speed at mid-time.
    speed = np.linalg.norm(traj.velocity(0.5))
    assert speed == pytest.approx(15.0 / 8.0 * np.linalg.norm(p1 - p0))
    np.testing.assert_allclose(traj.position(-1.0), p0)
    np.testing.assert_allclose(traj.position(5.0), p1)


def test_clearance_bump_peaks_at_mid_swing():
    p = np.array([1.0, 2.0, -1.75])
    traj = QuinticTrajectory.plan(p, p, 0.8, clearance=0.3)
    np.testing.assert_allclose(traj.position(0.4), p + [0.0, 0.0, 0.3], atol=1e-12)
    t = np.linspace(0.0, 0.8, 81)
    assert traj.position(t)[:, 2].max() == pytest.approx(p[2] + 0.3)


def test_quintic_bad_arguments():
    with pytest.raises(ValueError, match="duration"):
        QuinticTrajectory.plan(np.zeros(3), np.ones(3), 0.0)
    with pytest.raises(ValueError, match="shape"):
        QuinticTrajectory.plan(np.zeros(3), np.ones(2), 1.0)
    with pytest.raises(ValueError, match="clearance"):
        QuinticTrajectory.plan(np.zeros(3), np.ones(3), 1.0, clearance=-0.1)
