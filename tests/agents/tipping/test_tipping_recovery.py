"""Tipping-recovery controller of Zhang et al. 2024 (agents/tipping/controller.py): its sensor
model, the
margin-rate estimate, leg selection and the state machine driven by synthetic sensor readings.
The full Stewart-platform and cliff runs are in test_tipping_recovery_e2e.py."""

import math

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from agents.tipping.body_model import (
    HeavyDutyBodyModel,
    forces_to_body,
    gravity_in_body,
    quat_to_matrix,
)
from agents.tipping.controller import (
    RecoveryConfig,
    SensorReading,
    TippingRecoveryController,
    TippingRecoveryPolicy,
)
from agents.tipping.gait_with_recovery import GaitWithRecoveryPolicy
from agents.tipping.margin_rate import MarginHistory
from hexapod_envs.robots.heavy_duty import LEG_NAMES, HeavyDutyParams, foot_in_body
from hexapod_envs.robots.heavy_duty.kinematics import joints_for_foot

PARAMS = HeavyDutyParams()
BODY = HeavyDutyBodyModel(PARAMS)


def _quat_about(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


# --- body model ----------------------------------------------------------------------------
def test_quaternion_rotation_closed_forms():
    np.testing.assert_allclose(quat_to_matrix([1, 0, 0, 0]), np.eye(3), atol=1e-15)
    rz = quat_to_matrix(_quat_about([0, 0, 1], math.pi / 2))
    np.testing.assert_allclose(rz @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    # Nose up by 10° (rotation about -y): gravity in the body frame points backward and down.
    phi = math.radians(10)
    r = quat_to_matrix(_quat_about([0, -1, 0], phi))
    g = gravity_in_body(r)
    np.testing.assert_allclose(g, 9.81 * np.array([-math.sin(phi), 0, -math.cos(phi)]))
    np.testing.assert_allclose(
        forces_to_body([[0, 0, 1.0]], r), [[math.sin(phi), 0, math.cos(phi)]], atol=1e-5
    )
    with pytest.raises(ValueError, match="zero norm"):
        quat_to_matrix([0, 0, 0, 0])


def test_feet_match_the_robot_kinematics():
    rng = np.random.default_rng(0)
    ranges = PARAMS.joint_ranges
    joints = rng.uniform(ranges[:, 0], ranges[:, 1], size=(6, 3))
    expected = [foot_in_body(leg, joints[i], PARAMS) for i, leg in enumerate(LEG_NAMES)]
    np.testing.assert_allclose(BODY.feet(joints), expected, atol=1e-12)


def test_cog_of_a_symmetric_pose_lies_on_the_centre_line():
    feet = {leg: PARAMS.hip_offsets[leg] + [0, PARAMS.signed_l1(leg), -1.75] for leg in LEG_NAMES}
    joints = np.array([joints_for_foot(leg, feet[leg], PARAMS) for leg in LEG_NAMES])
    cog = BODY.cog(joints)
    assert abs(cog[0]) < 1e-12 and abs(cog[1]) < 1e-12
    # Legs (600 kg) hang below the body origin: the CoG is lower, by less than leg_mass/total·d.
    assert -6 * 100 * 1.75 / 5000 < cog[2] < 0
    # Pushing every foot 0.5 m forward moves the moving leg masses (60 % of each leg) forward.
    forward = joints.copy()
    forward[:, 0] += 0.5 / PARAMS.k_x
    assert BODY.cog(forward)[0] == pytest.approx(6 * 60 * 0.5 / 5000)


def test_cog_and_feet_match_the_simulator():
    env = gym.make("HexapodStewartTilt-v0", scenario="side", stance="LM-RF-RR")
    base = env.unwrapped
    obs, _ = env.reset(seed=0)
    joints = obs[base.observation_structure["joint_pos"]].reshape(6, 3)
    rot = quat_to_matrix(obs[base.observation_structure["imu_quat"]])
    origin = base.sensors.torso_position()
    np.testing.assert_allclose(BODY.cog(joints), rot.T @ (base.sensors.cog() - origin), atol=1e-9)
    feet_sim = (base.sensors.foot_positions() - origin) @ rot
    np.testing.assert_allclose(BODY.feet(joints), feet_sim, atol=1e-9)


def test_target_change_for_force_closed_form():
    kx, kd, kt = PARAMS.foot_stiffness
    joints = np.zeros((6, 3))
    joints[:, 1] = 0.2  # d = 1.8 m, swing 0
    change = BODY.target_change_for_force(joints, np.tile([0.0, 0.0, 1000.0], (6, 1)))
    # More upward ground reaction: a longer leg (ΔJ_z > 0) and, for a left leg (L1 > 0), a
    # negative swing (the foot presses down); the horizontal joint is untouched.
    np.testing.assert_allclose(change[:, 0], 0.0, atol=1e-15)
    np.testing.assert_allclose(change[:, 1], 1000.0 / kd / PARAMS.k_z)
    l1 = np.array([PARAMS.signed_l1(leg) for leg in LEG_NAMES])
    np.testing.assert_allclose(change[:, 2], -l1 * 1000.0 / kt)
    forward = BODY.target_change_for_force(joints, [[500.0, 0, 0]], legs=[0])
    np.testing.assert_allclose(forward, [[-500.0 / kx / PARAMS.k_x, 0, 0]])


# --- margin rate ---------------------------------------------------------------------------
def test_margin_history_recovers_rate_and_acceleration():
    history = MarginHistory(window=0.5)
    for k in range(40):
        t = 0.02 * k
        history.add(t, 25.0 - 2.0 * t - 0.75 * t * t)
    t_end = 0.02 * 39
    rate, accel = history.rate_and_acceleration()
    assert rate == pytest.approx(-2.0 - 1.5 * t_end, abs=1e-9)
    assert accel == pytest.approx(-1.5, abs=1e-9)
    assert len(history) == 26  # 0.5 s window at 0.02 s


def test_margin_history_few_samples_and_bad_input():
    history = MarginHistory()
    assert history.rate_and_acceleration() == (0.0, 0.0)
    history.add(0.0, 20.0)
    history.add(0.1, 19.0)
    rate, accel = history.rate_and_acceleration()
    assert rate == pytest.approx(-10.0) and accel == 0.0
    with pytest.raises(ValueError, match="increase"):
        history.add(0.1, 18.0)
    with pytest.raises(ValueError, match="window"):
        MarginHistory(window=0.0)


# --- configuration and leg choice ------------------------------------------------------------
def test_config_errors_name_the_choices():
    with pytest.raises(ValueError, match="kinematic"):
        RecoveryConfig(reach_model="exact")
    with pytest.raises(ValueError, match="force_gain"):
        RecoveryConfig(force_gain=0.0)
    for bad in ((0.004, 0.004), 0.004, (0.004, -0.001, 0.004)):
        with pytest.raises(ValueError, match="max_offset must be 3 finite limits"):
            RecoveryConfig(max_offset=bad)
    # settings first used at a tipping judgment are checked when the config is made
    for kwargs, match in (
        ({"kappa": 1.5}, "kappa must lie in"),
        ({"rho": 1.5}, "rho must be a finite number"),
        ({"t_min": 5.0}, "need 0 < t_min <= t_max"),
        ({"threshold_deg": float("nan")}, "threshold_deg must be a finite number"),
        ({"cone_ratios": (0.65, 1.2)}, "cone_ratios must be values in"),
        ({"swing_clearance": -0.1}, "swing_clearance"),
        ({"arm_after": -1.0}, "arm_after"),
        ({"angle_threshold_deg": 200.0}, "angle_threshold_deg"),
    ):
        with pytest.raises(ValueError, match=match):
            RecoveryConfig(**kwargs)
    assert RecoveryConfig(cone_ratios=()).cone_ratios == ()  # the paper's λ alone (row 7d)
    env = gym.make("HexapodStewartTilt-v0", scenario="climb")
    with pytest.raises(ValueError, match="valid:.*reach_model"):
        TippingRecoveryPolicy(env, reach_mode="paper")
    policy = TippingRecoveryPolicy(env, reach_model="paper", solver="quadprog")
    assert policy.config.qp.solver == "quadprog" and policy.config.reach_model == "paper"
    with pytest.raises(ValueError, match="gait_phase"):
        GaitWithRecoveryPolicy(env)


def test_non_tripod_stance_uses_table_ii_or_the_leg_outside_the_edge():
    controller = TippingRecoveryController(PARAMS)
    feet = BODY.feet(np.tile([0.0, 0.2, 0.0], (6, 1)))
    # The cliff case: five-leg stance without RF, tipping about RM-LF: Table II's RF is free.
    assert controller._pick_leg(("RM", "LF"), ("LF", "LM", "LR", "RM", "RR"), feet) == "RF"
    # Stance LF, LR, RF tipping about LR-RF (not in Table II): of the free legs LM, RM, RR the
    # farthest outside the edge is RR (LM lies inside).
    assert controller._pick_leg(("LR", "RF"), ("LF", "LR", "RF"), feet) == "RR"
    # Rectangle LF, LR, RR, RF tipping backward about LR-RR: the free middle legs lie inside.
    assert controller._pick_leg(("LR", "RR"), ("LF", "LR", "RF", "RR"), feet) is None


# --- the state machine on synthetic sensor readings -----------------------------------------
STANCE = ("LF", "LR", "RM")


def _hold_joints():
    joints = []
    for leg in LEG_NAMES:
        foot = PARAMS.hip_offsets[leg] + np.array([0.0, 0.0, -1.95])
        foot[1] = 1.7 if leg[0] == "L" else -1.7
        if leg not in STANCE:
            foot[2] += 0.45
        joints.append(joints_for_foot(leg, foot, PARAMS))
    return np.array(joints)


def _support_forces(joints, direction, legs, weight):
    """Forces along ``direction`` on ``legs`` that carry ``weight`` with no moment about the
    CoG (the CoG projected along ``direction`` in barycentric coordinates of three feet)."""
    feet, cog = BODY.feet(joints), BODY.cog(joints)
    idx = [LEG_NAMES.index(leg) for leg in legs]
    p = feet[idx]
    u = direction / np.linalg.norm(direction)
    # Solve cog + s u = Σ w_i p_i, Σ w_i = 1 for (w, s).
    mat = np.zeros((4, 4))
    mat[:3, :3] = p.T
    mat[:3, 3] = -u
    mat[3, :3] = 1.0
    w = np.linalg.solve(mat, np.concatenate([cog, [1.0]]))[:3]
    forces = np.zeros((6, 3))
    forces[idx] = np.outer(w, u) * weight
    return forces


def _reading(joints, forces):
    return SensorReading(
        joints,
        np.zeros((6, 3)),
        forces,
        np.array([1.0, 0, 0, 0]),
        np.zeros(3),
        np.array([0.0, 0.0, 9.81]),
    )


def test_state_machine_judges_plans_lands_and_distributes_forces():
    controller = TippingRecoveryController(PARAMS, RecoveryConfig(), control_dt=0.02)
    weight = BODY.total_mass * 9.81
    joints = _hold_joints()
    nominal = joints.copy()
    judged_at = None
    for k in range(600):
        t = 0.02 * k
        tilt = math.radians(2.0 * t)  # support force leaning forward: the body tips backward
        direction = np.array([math.sin(tilt), 0.0, math.cos(tilt)])
        forces = _support_forces(joints, direction, STANCE, weight)
        leg = controller.diagnostics["adjustment_leg"]
        touching = controller.phase == "touchdown"
        if touching:
            forces[LEG_NAMES.index(leg)] = [0.0, 0.0, 0.05 * weight]
        targets = controller.step(_reading(joints, forces), nominal, t)
        if judged_at is None and controller.active:
            judged_at = t
            d = controller.diagnostics
            assert d["margin_at_judgment_deg"] < 20.0 <= controller.history.margins[-2]
            assert set(d["tipping_edge"]) == {"LR", "RM"} and d["adjustment_leg"] == "RR"
            assert 0.5 <= d["t_s"] <= 3.0 and d["margin_rate_deg_s"] < 0.0
            assert d["foothold_status"] == "ok" and d["foothold"][1] < -1.7
            assert d["foothold"][2] == pytest.approx(-1.95, abs=1e-6)  # on the stance plane
        # A perfect servo: the encoders read last period's targets.
        joints = targets.copy()
        if controller.phase == "supported":
            break
    d = controller.diagnostics
    assert judged_at is not None and controller.phase == "supported"
    assert d["supported_legs"] == ("LF", "LR", "RM", "RR")
    assert d["recovery_time"] >= d["t_s"] - 0.02
    np.testing.assert_allclose(BODY.feet(joints)[LEG_NAMES.index("RR")], d["foothold"], atol=0.1)
    # One more period in support: the QP runs again (the landing period's report cleared) and
    # reports planned beside measured forces.
    d["qp_status"] = d["planned_forces"] = d["measured_forces"] = None
    forces = _support_forces(joints, np.array([0.2, 0.0, 1.0]), ("LF", "LR", "RM"), weight)
    forces[LEG_NAMES.index("RR")] = [0.0, 0.0, 0.05 * weight]
    controller.step(_reading(joints, forces), nominal, 0.02 * (k + 1))
    assert d["qp_status"] == "optimal"
    assert d["planned_forces"].shape == d["measured_forces"].shape == (4, 3)
    assert d["planned_forces"][:, 2].min() >= 0.04 * weight * 0.999  # every foot stays loaded


def test_no_ground_is_a_held_posture_with_a_reason():
    config = RecoveryConfig(max_search_depth=0.1)
    controller = TippingRecoveryController(PARAMS, config, control_dt=0.02)
    weight = BODY.total_mass * 9.81
    joints = _hold_joints()
    for k in range(600):
        tilt = math.radians(2.0 * 0.02 * k)
        forces = _support_forces(
            joints, np.array([math.sin(tilt), 0.0, math.cos(tilt)]), STANCE, weight
        )
        joints = controller.step(_reading(joints, forces), _hold_joints(), 0.02 * k)
        if controller.phase == "holding":
            break
    d = controller.diagnostics
    assert controller.phase == "holding" and "no ground under RR" in d["failure"]
    np.testing.assert_allclose(joints[LEG_NAMES.index("RR")], _hold_joints()[5])  # pulled back


def _array_feet_cog_and_target_change(body, joints, delta_force, legs):
    """The body model's feet, CoG and target change as numpy array expressions (their form
    before the float rewrite of issue 14), as the reference for the equivalence test."""
    p = body.params
    x, d, theta = p.k_x * joints[:, 0], p.k_z * joints[:, 1] + p.l2, joints[:, 2].copy()
    c, s = np.cos(theta), np.sin(theta)
    feet = body.hips.copy()
    feet[:, 0] += x
    feet[:, 1] += body.l1 * c + d * s
    feet[:, 2] += body.l1 * s - d * c
    m_moving = body._m_carriage + body._m_shank + body._m_foot
    y = (0.5 * body._m_hip + m_moving) * body.l1
    z = (
        body._m_carriage * body._carriage_z
        + body._m_shank * (body._shank_up - d)
        + body._m_foot * (body._foot_up - d)
    )
    hips = body._hip_sums
    moment = (
        p.leg_mass * hips[0] + m_moving * float(x.sum()),
        p.leg_mass * hips[1] + float((y * c - z * s).sum()),
        p.leg_mass * hips[2] + float((y * s + z * c).sum()),
    )
    jac = np.zeros((6, 3, 3))
    jac[:, 0, 0] = 1.0
    jac[:, 1, 1], jac[:, 2, 1] = s, -c
    jac[:, 1, 2] = -body.l1 * s + d * c
    jac[:, 2, 2] = body.l1 * c + d * s
    change = -np.einsum("lji,lj->li", jac[legs], delta_force) / body.stiffness
    return feet, np.array(moment) / body.total_mass, change / body._joint_scale


def test_body_model_float_code_is_bit_identical_to_array_expressions():
    body = HeavyDutyBodyModel(PARAMS)
    rng = np.random.default_rng(14)
    for _ in range(500):
        joints = np.column_stack(
            [rng.uniform(-0.3, 0.3, 6), rng.uniform(-0.2, 0.5, 6), rng.uniform(-0.6, 0.6, 6)]
        )
        legs = np.sort(rng.permutation(6)[: rng.integers(3, 7)])
        delta_force = rng.normal(scale=1000.0, size=(len(legs), 3))
        feet, cog, change = _array_feet_cog_and_target_change(body, joints, delta_force, legs)
        new_feet, new_cog = body.feet_and_cog(joints)
        assert new_feet.tobytes() == feet.tobytes() == body.feet(joints).tobytes()
        assert new_cog.tobytes() == cog.tobytes() == body.cog(joints).tobytes()
        new_change = body.target_change_for_force(joints, delta_force, legs=legs)
        assert new_change.tobytes() == change.tobytes()


def test_null_space_solve_is_numpys_to_the_bit_and_refuses_a_singular_matrix():
    # The supported phase projects the force error with the gesv gufunc behind np.linalg.solve
    # (its wrapper cost ~10 µs per step); the numbers must be np.linalg.solve's exactly.
    from agents.tipping.controller import _solve

    rng = np.random.default_rng(3)
    for _ in range(200):
        a_mat = rng.normal(size=(6, 3 * int(rng.integers(3, 7))))
        m, v = a_mat @ a_mat.T, a_mat @ rng.normal(size=a_mat.shape[1])
        assert np.array_equal(_solve(m, v), np.linalg.solve(m, v))
    with pytest.warns(RuntimeWarning), pytest.raises(np.linalg.LinAlgError, match="Singular"):
        _solve(np.zeros((6, 6)), np.ones(6))
