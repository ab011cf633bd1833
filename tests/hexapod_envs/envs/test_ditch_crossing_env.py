"""HexapodDitchCrossing-v0: keyword arguments, observation layout, measurements, randomisation."""

import warnings

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.envs.ditch_crossing import DitchCrossingEnv
from hexapod_envs.robots.upu.gait_schedule import standing_command
from hexapod_envs.robots.upu.params import LEG_NAMES, UpuParams
from hexapod_envs.stability import static_stability_margin

P = UpuParams()
ZERO = np.zeros(9)


def test_bad_keyword_arguments_are_named():
    with pytest.raises(ValueError, match="terrain"):
        DitchCrossingEnv(terrain="lava")
    with pytest.raises(ValueError, match="action_mode"):
        DitchCrossingEnv(action_mode="torque")
    with pytest.raises(ValueError, match="under or right in front"):
        DitchCrossingEnv(ditch_start_x=0.15)
    with pytest.raises(ValueError, match="x >= 0.240"):
        DitchCrossingEnv(ditch_start_x=0.23)
    DitchCrossingEnv(ditch_start_x=0.241).reset(seed=0)  # about the closest that can be planned
    with pytest.raises(ValueError, match="ditch_width_range"):
        DitchCrossingEnv(ditch_width_range=(0.4, 0.3))
    with pytest.raises(ValueError, match="ditch_depth_range"):
        DitchCrossingEnv(ditch_depth_range=0.1)
    with pytest.raises(ValueError, match="under or right in front"):
        DitchCrossingEnv(ditch_start_x_range=(0.1, 0.6))
    with pytest.raises(ValueError, match="width"):
        DitchCrossingEnv(ditch_width=0.0)
    with pytest.raises(TypeError, match="valid"):
        DitchCrossingEnv(ditch_wdth=0.3)
    with pytest.raises(ValueError, match="residual_leg_m"):
        DitchCrossingEnv(residual_leg_m=-0.001)
    with pytest.raises(ValueError, match="not a whole multiple"):
        DitchCrossingEnv(control_dt=0.1, physics_dt=0.003)


def test_observation_layout_and_reset_state():
    env = DitchCrossingEnv()
    obs, info = env.reset(seed=0)
    sizes = {k: s.stop - s.start for k, s in env.observation_structure.items()}
    assert sizes == {
        "joint_pos": 9,
        "joint_vel": 9,
        "foot_force": 18,
        "foot_contact": 6,
        "fasm_margin_deg": 1,
        "static_margin_m": 1,
        "imu_gyro": 3,
        "imu_accel": 3,
        "imu_quat": 4,
        "reference_action": 9,
        "residual_state": 9,
    }
    o = {k: obs[s] for k, s in env.observation_structure.items()}
    # Standing on six feet: all in contact, they carry the weight, margin = hexagon inradius-ish.
    assert o["foot_contact"].tolist() == [1.0] * 6
    forces = o["foot_force"].reshape(6, 3)
    assert forces[:, 2].sum() == pytest.approx(P.total_mass * 9.81, rel=0.02)
    assert np.abs(forces[:, :2].sum(axis=0)).max() < 0.5  # at rest: no net horizontal force
    assert info["static_margin_m"] == o["static_margin_m"][0] > 0.15
    assert info["fasm_margin_deg"] > 0
    assert info["stance_legs"] == LEG_NAMES
    np.testing.assert_allclose(o["joint_pos"][3:], 0.0, atol=2e-3)  # legs at nominal length
    q = o["imu_quat"]  # level; turned by the seeded start yaw only
    np.testing.assert_allclose(q[1:3], 0.0, atol=1e-4)
    assert abs(q[3]) <= np.sin(0.5 * env.reset_noise_scale / P.leg_circle_radius) + 1e-4
    # The reference's first row: the upper legs begin to unload from the standing pose.
    center = (env.command_low + env.command_high) / 2
    half = (env.command_high - env.command_low) / 2
    first = env.reference_command()
    np.testing.assert_allclose(o["reference_action"], (first - center) / half)
    stand = standing_command(P)
    np.testing.assert_allclose(first[:3], stand[:3])
    assert np.all(first[3:6] < stand[3:6]) and np.all(stand[3:6] - first[3:6] < 0.005)
    np.testing.assert_allclose(first[6:], stand[6:])
    assert info["planner_status"] == "ok" and info["gait_phase"] == "unload"
    assert info["ditch"] == {"start_x": 0.6, "width": 0.35, "depth": 0.14}
    assert info["finish_x"] == pytest.approx(0.95)


def test_static_margin_is_the_support_polygon_margin_of_the_loaded_feet():
    env = DitchCrossingEnv()
    _, info = env.reset(seed=3)
    smallest = info["static_margin_m"]
    assert info["min_static_margin_m"] == smallest
    seen = set()
    for _ in range(60):  # through the first lift-off: six, then three loaded feet
        _, _, _, _, info = env.step(ZERO)
        smallest = min(smallest, info["static_margin_m"])
        assert info["min_static_margin_m"] == smallest  # the episode's smallest so far
        loaded = env._loaded
        seen.add(int(loaded.sum()))
        if loaded.sum() >= 3:
            soles = env.data.xpos[env._foot_body][loaded]
            cog = env.data.subtree_com[env._torso]
            expected = static_stability_margin(soles, cog)
            assert info["static_margin_m"] == pytest.approx(expected, abs=1e-12)
        assert info["is_tipping"] == (info["static_margin_m"] <= 0)
        assert info["stance_legs"] == tuple(
            leg for leg, on in zip(LEG_NAMES, loaded, strict=True) if on
        )
    assert {3, 6} <= seen
    assert smallest < env.reset(seed=3)[1]["min_static_margin_m"]  # a new episode starts afresh
    # Random actions soon leave two feet loaded (no polygon: margin 0), where the robot tips.
    env.reset(seed=0)
    env.action_space.seed(0)
    tipping = set()
    for _ in range(60):
        info = env.step(env.action_space.sample())[4]
        assert info["is_tipping"] == (info["static_margin_m"] <= 0)
        tipping.add(info["is_tipping"])
    assert tipping == {True, False}


def test_nan_action_is_rejected():
    env = DitchCrossingEnv()
    env.reset(seed=0)
    bad = ZERO.copy()
    bad[4] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        env.step(bad)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(6))


def test_joint_mode_standing_action_stands_still():
    env = DitchCrossingEnv(action_mode="joint")
    obs, _ = env.reset(seed=0)
    center = (env.command_low + env.command_high) / 2
    half = (env.command_high - env.command_low) / 2
    action = (standing_command(P) - center) / half
    for _ in range(20):
        obs, reward, terminated, truncated, info = env.step(action)
    assert not (terminated or truncated)
    assert abs(info["distance"]) < 1e-3 and info["tilt_deg"] < 0.2
    assert len(info["stance_legs"]) == 6


def test_ditch_randomisation_is_seeded_and_rebuilds_the_terrain():
    kwargs = {
        "ditch_width_range": (0.25, 0.45),
        "ditch_depth_range": (0.08, 0.15),
        "ditch_start_x_range": (0.5, 0.7),
    }
    env = DitchCrossingEnv(**kwargs)
    seen = []
    for seed in (1, 2, 1):
        _, info = env.reset(seed=seed)
        d = info["ditch"]
        assert 0.25 <= d["width"] <= 0.45 and 0.08 <= d["depth"] <= 0.15
        assert 0.5 <= d["start_x"] <= 0.7
        assert info["planner_status"] == "ok"
        floor = env.model.geom("ditch_floor")
        assert floor.size[0] == pytest.approx(d["width"] / 2)
        assert floor.pos[0] == pytest.approx(d["start_x"] + d["width"] / 2)
        assert floor.pos[2] + floor.size[2] == pytest.approx(-d["depth"])
        assert env.plan.ditch.width == d["width"]
        seen.append(d)
    assert seen[0] == seen[2] and seen[0] != seen[1]
    fixed = DitchCrossingEnv()
    _, info = fixed.reset(seed=5)
    assert info["ditch"] == {"start_x": 0.6, "width": 0.35, "depth": 0.14}


def test_flat_terrain_keeps_the_finish_line():
    env = gym.make("HexapodDitchCrossing-v0", terrain="flat")
    _, info = env.reset(seed=0)
    base = env.unwrapped
    assert info["ditch"] is None and info["finish_x"] == pytest.approx(0.95)
    assert "ditch_floor" not in [base.model.geom(i).name for i in range(base.model.ngeom)]
    assert info["planner_status"] == "ok" and "flat ground" in info["planner_reason"]
    env.close()


def test_flat_terrain_plans_for_each_sampled_finish_line():
    """A randomised finish line on flat ground gets its own reference plan, not the first
    episode's: the plan reaches past each episode's finish line."""
    from hexapod_envs.robots.upu.gait_plan import plan_flat_past

    env = gym.make("HexapodDitchCrossing-v0", terrain="flat", ditch_start_x_range=(0.6, 1.1))
    plans = set()
    for seed in range(4):
        _, info = env.reset(seed=seed)
        base = env.unwrapped
        expected = plan_flat_past(base.params, info["finish_x"], base.start_x, base.gait_settings)
        assert len(base.plan.steps) == len(expected.steps), seed
        plans.add(len(base.plan.steps))
    assert len(plans) > 1
    env.close()


def test_impassable_ditch_reference_stands_still():
    env = DitchCrossingEnv(ditch_depth=0.2)
    _, info = env.reset(seed=0)
    assert info["planner_status"] == "too_deep"
    assert "0.160" in info["planner_reason"]
    for _ in range(30):
        _, _, terminated, _, info = env.step(ZERO)  # residual mode: the reference itself
    assert not terminated and abs(info["distance"]) < 1e-3
    assert len(info["stance_legs"]) == 6 and info["gait_phase"] == "stand"


def test_reward_is_the_sum_of_named_terms_and_progress_follows_the_cog():
    env = DitchCrossingEnv()
    env.reset(seed=0)
    x0 = env.data.subtree_com[env._torso][0]
    total_progress = 0.0
    for _ in range(120):  # the first upper step carries the CoG forward
        _, reward, _, _, info = env.step(ZERO)
        terms = {k[len("reward_") :]: v for k, v in info.items() if k.startswith("reward_")}
        names = {"forward", "stability", "alive", "success", "tip_over", "effort"}
        names |= {"foothold", "landing"}  # the stride learners' shaping terms, 0 by default
        assert set(terms) == names
        assert reward == pytest.approx(sum(terms.values()))
        assert terms["tip_over"] == 0.0 and terms["effort"] <= 0.0
        total_progress += terms["forward"]
    moved = env.data.subtree_com[env._torso][0] - x0
    assert moved > 0.05
    assert total_progress == pytest.approx(env.weights["forward"] * moved / env.control_dt)


def test_residual_is_filtered_and_observed():
    env = DitchCrossingEnv(residual_filter_tau=0.3)
    obs, _ = env.reset(seed=0)
    state = env.observation_structure["residual_state"]
    np.testing.assert_array_equal(obs[state], 0.0)
    alpha = env.control_dt / (0.3 + env.control_dt)
    assert env.residual_filter_alpha == pytest.approx(alpha)
    action = np.array([1.0, -1.0, 0.5, 0, 0, 0, 0, 0, -0.5])
    expected = np.zeros(9)
    for _ in range(3):
        obs, *_ = env.step(action)
        expected += alpha * (action - expected)
        np.testing.assert_allclose(obs[state], expected)
    # The servo targets follow reference + residual [m] (limb gain 2 mm, leg gain 5 mm).
    np.testing.assert_allclose(env.residual_gain, [0.002] * 3 + [0.005] * 6)
    # (clamped to the actuator ranges, as MuJoCo clamps the activation)
    target = env.reference_command(env._step_count - 1) + expected * env.residual_gain
    target = np.clip(target, env.command_low, env.command_high)
    np.testing.assert_allclose(env.data.act[env._act_state], target, atol=1e-12)
    joint = DitchCrossingEnv(action_mode="joint")
    joint.reset(seed=0)
    obs, *_ = joint.step(np.zeros(9))
    np.testing.assert_array_equal(obs[state], 0.0)


def test_a_crossing_ends_the_episode_once_and_pays_its_bonus_once():
    """Stepping on after the crossing terminated keeps `terminated` True and the success, and
    never pays the success bonus again (it paid ~2000 per extra step)."""
    env = gym.make("HexapodDitchCrossing-v0").unwrapped
    env.reset(seed=0)
    for _ in range(env.horizon_steps):
        _, _, terminated, _, info = env.step(ZERO)
        if terminated:
            break
    assert terminated and info["is_success"] and info["reward_success"] > 0
    for _ in range(5):
        _, _, terminated, _, info = env.step(ZERO)
        assert terminated and info["is_success"] and info["reward_success"] == 0.0


def test_an_episode_past_the_bonus_horizon_warns_once():
    """A time limit raised above horizon_steps would let a late crossing earn no bonus: the
    env says so on the first step past it, once."""
    env = DitchCrossingEnv(horizon_steps=3)
    env.reset(seed=0)
    for _ in range(3):
        env.step(ZERO)
    with pytest.warns(UserWarning, match="ran past horizon_steps=3"):
        env.step(ZERO)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env.step(ZERO)


def test_stride_action_needs_the_residual_mode_and_the_flat_reference():
    with pytest.raises(ValueError, match="reference_plan='flat'"):
        gym.make("HexapodDitchCrossing-v0", stride_action=True)  # -v0 plans for the course
    with pytest.raises(ValueError, match="action_mode='residual'"):
        gym.make("HexapodDitchCrossing-v1", stride_action=True, action_mode="joint")
    with pytest.raises(ValueError, match="stride_action"):
        gym.make("HexapodDitchCrossing-v1", stride_action="yes")


def test_without_the_stride_action_every_action_value_is_read_on_every_step():
    assert gym.make("HexapodDitchCrossing-v1").unwrapped.action_read_flags == {}
    assert gym.make("HexapodDitchCrossing-v1").unwrapped.inert_actions == ()


def test_residuals_with_a_range_of_0_are_inert():
    env = gym.make("HexapodDitchCrossing-v1", residual_leg_m=0.0)
    assert env.unwrapped.inert_actions == tuple(range(3, 9))  # the six legs
    # Whatever an inert value is, the trajectory is the same.
    trajectories = []
    for value in (-1.0, 1.0):
        action = np.zeros(9, dtype=np.float32)
        action[3:] = value
        env.reset(seed=0)
        trajectories.append([env.step(action)[0] for _ in range(20)])
    np.testing.assert_array_equal(trajectories[0], trajectories[1])
    joint = gym.make("HexapodDitchCrossing-v1", action_mode="joint", residual_leg_m=0.0)
    assert joint.unwrapped.inert_actions == ()  # joint mode has no residuals


def test_full_strides_walk_the_flat_reference_bit_for_bit_on_flat_ground():
    plain = gym.make("HexapodDitchCrossing-v1", terrain="flat")
    strided = gym.make("HexapodDitchCrossing-v1", terrain="flat", stride_action=True)
    assert strided.action_space.shape == (10,)
    size = plain.observation_space.shape[0]
    a, _ = plain.reset(seed=3)
    b, _ = strided.reset(seed=3)
    np.testing.assert_array_equal(a, b[:size])  # the extra pieces come last
    for _ in range(160):  # three platform steps, decided at 0, 51 and 102
        a, ra, *_, ia = plain.step(ZERO)
        b, rb, *_, ib = strided.step(np.zeros(10))
        np.testing.assert_array_equal(a, b[:size])
        assert ra == rb and (ia["gait_step"], ia["gait_phase"]) == (
            ib["gait_step"],
            ib["gait_phase"],
        )


def test_the_stride_value_counts_only_on_a_steps_first_control_step():
    env = gym.make("HexapodDitchCrossing-v1", stride_action=True)  # the paper's ditch
    base = env.unwrapped
    obs, _ = env.reset(seed=0)
    ahead = obs[base.observation_structure["ditch_ahead"]]
    decision = base.observation_structure["stride_decision"]
    np.testing.assert_allclose(ahead, [0.6, 0.95, 0.6, 0.95, 0.14])  # both centres at x = 0
    assert obs[decision].tolist() == [1.0, 1.0]  # the upper platform, decided by this action
    assert base.action_read_flags == {9: decision.start + 1}  # the stride, read on that flag
    action = np.zeros(10)
    action[9] = -0.5
    obs, *_ = env.step(action)  # step 0: half a stride
    action[9] = -1.0  # ignored until the next step begins
    decided_at = []
    for t in range(1, 60):
        if obs[decision][1]:
            decided_at.append(t)
            action[9] = 0.0
        obs, *_ = env.step(action)
    assert decided_at == [51]  # 5.1 s per platform step at 10 Hz
    gait = base.online_gait
    assert [s.stride for s in gait.steps] == pytest.approx([0.08, 0.08])  # the lower's room
    np.testing.assert_allclose(obs[base.observation_structure["ditch_ahead"]][[0, 2]], 0.52)


def test_the_online_gaits_planner_info_does_not_depend_on_the_last_episode():
    env = gym.make("HexapodDitchCrossing-v1", stride_action=True)
    _, first = env.reset(seed=0)
    for _ in range(60):
        env.step(np.zeros(10))
    _, again = env.reset(seed=0)
    assert first["planner_reason"] == again["planner_reason"] == env.unwrapped.plan.reason
    assert "online" in first["planner_reason"] and len(env.unwrapped.online_gait.steps) == 0
