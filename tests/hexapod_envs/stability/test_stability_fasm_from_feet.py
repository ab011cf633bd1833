"""fasm_from_feet: the FASM a robot computes from its measured foot forces."""

import numpy as np
import pytest

from hexapod_envs.stability import fasm, fasm_from_feet

FEET = np.array([[x, y, -1.75] for y in (1.9, -1.9) for x in (2.4, 0.0, -2.4)])
WEIGHT = 5000 * 9.81


def static_forces(feet, cog):
    """Vertical foot forces in static balance (least-norm solution of the two moment equations)."""
    a = np.vstack([np.ones(len(feet)), feet[:, 0] - cog[0], feet[:, 1] - cog[1]])
    fz = np.linalg.lstsq(a, [WEIGHT, 0.0, 0.0], rcond=None)[0]
    return np.column_stack([np.zeros(len(feet)), np.zeros(len(feet)), fz])


def test_static_balance_matches_fasm_with_gravity():
    cog = np.array([0.3, -0.2, 0.0])
    forces = static_forces(FEET, cog)
    margin, edge = fasm_from_feet(FEET, forces, cog, np.ones(6, bool))
    expected = fasm(FEET, cog, (0.0, 0.0, -WEIGHT))
    assert margin == pytest.approx(expected.margin_deg, abs=1e-9)
    assert edge == expected.edge


def test_unloaded_feet_are_left_out_and_edge_indexes_the_full_array():
    loaded = np.array([True, False, True, False, True, False])  # LF LR RM of this ordering
    feet = FEET.copy()
    forces = static_forces(feet[loaded], np.zeros(3))
    full = np.zeros((6, 3))
    full[loaded] = forces
    margin, edge = fasm_from_feet(feet, full, np.zeros(3), loaded)
    assert margin == pytest.approx(np.degrees(np.arctan2(1.0147, 1.75)), abs=0.05)
    assert set(edge) <= set(np.flatnonzero(loaded).tolist())


def test_fewer_than_three_loaded_feet_is_zero_margin():
    loaded = np.array([True, True, False, False, False, False])
    assert fasm_from_feet(FEET, np.zeros((6, 3)), np.zeros(3), loaded) == (0.0, None)


def test_non_finite_forces_are_a_clear_error():
    forces = static_forces(FEET, np.zeros(3))
    forces[2, 2] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        fasm_from_feet(FEET, forces, np.zeros(3), np.ones(6, bool))


def test_a_net_moment_about_the_cog_enters_as_n_r():
    """Foot forces out of balance about the CoG (horizontal pushes on two feet): f_r and n_r are
    minus the measured wrench about the CoG, and here the moment moves the margin."""
    cog = np.array([0.3, -0.2, 0.0])
    forces = static_forces(FEET, cog)
    forces[0, 1] += 4000.0
    forces[3, 0] -= 3000.0
    f_r = -forces.sum(axis=0)
    n_r = -np.cross(FEET - cog, forces).sum(axis=0)
    margin, edge = fasm_from_feet(FEET, forces, cog, np.ones(6, bool))
    expected = fasm(FEET, cog, f_r, n_r)
    assert margin == pytest.approx(expected.margin_deg, abs=1e-9)
    assert edge == expected.edge
    assert abs(margin - fasm(FEET, cog, f_r).margin_deg) > 0.5
