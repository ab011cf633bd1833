"""HexapodIrregularTerrain-v0: env contract for every terrain and action mode, the gains mode's
cycle-start rule, per-cycle statistics, torso contact, start poses and bad input."""

import math

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import hexapod_envs  # noqa: F401  (registers the env ids)
from agents.athena_policy import AthenaPosturePolicy, analytical_policy
from agents.registry import analytical_factory
from hexapod_envs.robots.athena.kinematics import standing_foot_positions
from hexapod_envs.robots.athena.params import ATHENA
from hexapod_envs.stability import zmp_margin

ENV_ID = "HexapodIrregularTerrain-v0"
TERRAINS = ("ramp", "blocks", "flat")


@pytest.mark.parametrize("terrain", TERRAINS)
def test_gymnasium_and_sb3_checkers_pass(terrain):
    env = gym.make(ENV_ID, terrain=terrain)
    gym_check_env(env.unwrapped, skip_render_check=True)
    sb3_check_env(env.unwrapped, warn=True)
    env.close()


@pytest.mark.parametrize("mode", ["joint", "gains"])
def test_checkers_pass_in_the_other_action_modes(mode):
    env = gym.make(ENV_ID, terrain="blocks", action_mode=mode)
    gym_check_env(env.unwrapped, skip_render_check=True)
    sb3_check_env(env.unwrapped, warn=True)
    env.close()


def _rollout(terrain, seed, steps=60, mode="residual"):
    env = gym.make(ENV_ID, terrain=terrain, action_mode=mode)
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(5)
    trace = [obs]
    for _ in range(steps):
        obs, reward, *_ = env.step(env.action_space.sample())
        trace.append(np.append(obs, reward))
    heights = env.unwrapped.terrain_info.heights.copy() if terrain == "blocks" else None
    env.close()
    return np.concatenate(trace), heights


@pytest.mark.parametrize("terrain", TERRAINS)
def test_same_seed_same_trajectory(terrain):
    a, heights_a = _rollout(terrain, seed=11)
    b, heights_b = _rollout(terrain, seed=11)
    np.testing.assert_array_equal(a, b)
    if terrain == "blocks":
        np.testing.assert_array_equal(heights_a, heights_b)


def test_each_seed_draws_its_own_block_bed_unless_the_layout_is_fixed():
    env = gym.make(ENV_ID, terrain="blocks")
    env.reset(seed=1)
    first = env.unwrapped.terrain_info.heights.copy()
    env.reset(seed=2)
    second = env.unwrapped.terrain_info.heights
    assert not np.array_equal(first, second)
    assert first.min() >= 0.04 and first.max() <= 0.13
    fixed = gym.make(ENV_ID, terrain="blocks", block_layout_seed=7)
    fixed.reset(seed=1)
    bed = fixed.unwrapped.terrain_info.heights.copy()
    fixed.reset(seed=2)
    np.testing.assert_array_equal(bed, fixed.unwrapped.terrain_info.heights)


@pytest.mark.parametrize("terrain", TERRAINS)
def test_observation_info_and_reward_terms(terrain):
    env = gym.make(ENV_ID, terrain=terrain, action_mode="gains")
    base = env.unwrapped
    obs, info = env.reset(seed=0)
    structure = base.observation_structure
    expected = {"joint_pos", "joint_vel", "foot_force", "foot_contact", "fasm_margin_deg"}
    expected |= {"imu_gyro", "imu_accel", "imu_quat", "torso_height", "gait_phase"}
    assert expected | {"posture_gains"} == set(structure)
    policy = AthenaPosturePolicy(env, kz=0.6, ka=0.4, kb=0.4)
    policy.reset()
    assert info["episode_metrics"]["cycle_height_rms"] == []
    cycles, metrics = [], None
    for _ in range(200):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        assert env.observation_space.contains(obs) and np.all(np.isfinite(obs))
        terms = {k: v for k, v in info.items() if k.startswith("reward_")}
        assert set(terms) == {f"reward_{n}" for n in [*base.weights, "alive"]}
        assert reward == pytest.approx(sum(terms.values()))
        assert info["zmp_margin"] >= 0.0 and info["pitch_rate"] == obs[structure["imu_gyro"]][1]
        if "cycle_stats" in info:
            cycles.append(info["cycle_stats"])
        metrics = info.get("episode_metrics", metrics)  # sent when a cycle finishes
        assert not terminated and not truncated
    # Cycles of 2 t_g = 40 steps (more when a landing leg has to be extended to the ground).
    assert len(cycles) >= 2 and [c["index"] for c in cycles] == list(range(len(cycles)))
    assert all(c["steps"] >= base.ticks_per_cycle for c in cycles)
    first = cycles[0]
    assert first["gains"] == pytest.approx((0.6, 0.4, 0.4))
    assert 0.03 < first["height_rms"] < 0.25 and first["pitch_rate_rms"] >= 0.0
    assert info["distance"] > 0.05  # it walks forward
    assert metrics["cycle_height_rms"] == [c["height_rms"] for c in cycles]
    assert metrics["cycle_zmp_margin"] == [c["zmp_margin_mean"] for c in cycles]
    assert set(base.evaluation_metrics) >= set(metrics) | {"torso_collisions", "zmp_margin"}
    assert info["actuator_power_w"] > 0.0
    assert obs[structure["posture_gains"]] == pytest.approx([0.6, 0.4, 0.4])


def test_pitch_rate_factor_weighs_pitch_against_roll_in_the_rate_term():
    env = gym.make(ENV_ID, action_mode="gains", rate_weight=2.0, pitch_rate_factor=10.0)
    env.reset(seed=0)
    for _ in range(30):
        *_, info = env.step(np.array([0.8, 0.6, 0.0], dtype=np.float32))
        pitch, roll = info["pitch_rate"], info["roll_rate"]
        expected = -2.0 * min(10.0 * pitch**2 + roll**2, 4.0)
        assert info["reward_steadiness_rate"] == pytest.approx(expected, rel=1e-12, abs=1e-15)
    assert abs(pitch) > 1e-4  # the term is not trivially 0


def test_gains_are_applied_only_at_gait_cycle_starts():
    """The gains are read once per cycle, at its first step (the observation's start flag is up
    then; it stays up while the gait waits there for the ground, and those actions are ignored)."""
    env = gym.make(ENV_ID, terrain="ramp", action_mode="gains", gait_ground_search="always")
    base = env.unwrapped
    phase = base.observation_structure["gait_phase"]
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    applied, waits = [], 0
    for _ in range(4 * base.ticks_per_cycle):
        due = base.gains_due
        waits += obs[phase][2] == 1.0 and not due
        assert not due or obs[phase][2] == 1.0
        action = rng.uniform(0, 1, 3).astype(np.float32)
        obs, *_, info = env.step(action)
        if due:
            applied.append(action.astype(float))
            assert info["posture_gains"] == pytest.approx(tuple(action))
        else:
            assert info["posture_gains"] == pytest.approx(tuple(applied[-1]))
    assert len(applied) == info["gait_cycle"] + 1
    assert waits > 0  # the ramp start waits for a landing leg: those steps set nothing


def test_height_knob_at_zero_walks_the_gains_modes_episode_and_otherwise_moves_the_reference():
    """gains_height_offset_m adds a fourth gains-mode action: at 0 the episode is the one of
    the three gains alone, bit for bit; otherwise the height control's reference moves by the
    action x the range, read at cycle starts only, and the torso walks higher."""
    kwargs = {"terrain": "blocks", "action_mode": "gains", "task_distribution": "train"}
    plain = gym.make("HexapodIrregularTerrain-v1", **kwargs)
    knob = gym.make("HexapodIrregularTerrain-v1", gains_height_offset_m=0.04, **kwargs)
    assert knob.action_space.shape == (4,) and knob.action_space.low[3] == -1.0
    assert AthenaPosturePolicy(knob, kz=0.6, ka=0.4, kb=0.4)(None).tolist() == pytest.approx(
        [0.6, 0.4, 0.4, 0.0]
    )
    offset = knob.unwrapped.observation_structure["height_offset"]
    obs_p, _ = plain.reset(seed=5)
    obs_k, _ = knob.reset(seed=5)
    gains = np.array([0.6, 0.4, 0.4], np.float32)
    for _ in range(120):
        obs_p, r_p, *_ = plain.step(gains)
        obs_k, r_k, *_ = knob.step(np.append(gains, np.float32(0.0)))
        assert r_k == r_p and np.array_equal(np.delete(obs_k, offset), obs_p)
    assert obs_k[offset] == 0.0

    base = knob.unwrapped
    heights = {}
    for action in (0.0, 0.75):
        knob.reset(seed=5)
        readings = []
        for _ in range(6 * base.ticks_per_cycle):
            due = base.gains_due
            held = action if due else -1.0  # actions between cycle starts are ignored
            obs, *_, info = knob.step(np.append(gains, np.float32(held)))
            assert obs[offset][0] == pytest.approx(action * 0.04)
            readings.append(info["torso_height"])
        heights[action] = np.mean(readings[-2 * base.ticks_per_cycle :])
    assert heights[0.75] > heights[0.0] + 0.005  # a 3 cm higher reference, closed over cycles

    with pytest.raises(ValueError, match="gains_height_offset_m.*'gains'"):
        gym.make("HexapodIrregularTerrain-v1", gains_height_offset_m=0.04)


def test_policy_gives_the_same_walk_in_every_action_mode():
    """The env's internal controller (gains, residual) and the policy's own (joint) agree."""

    def walk(mode):
        env = gym.make(ENV_ID, terrain="ramp", action_mode=mode)
        policy = AthenaPosturePolicy(env, kz=0.8, ka=0.6, kb=0.0)
        obs, _ = env.reset(seed=3)
        policy.reset()
        cog = []
        for _ in range(100):
            obs, *_, info = env.step(policy(obs))
            cog.append(info["cog"])
        return np.array(cog)

    gains = walk("gains")
    assert gains[-1, 0] - gains[0, 0] > 0.2
    np.testing.assert_allclose(walk("joint"), gains, atol=1e-6)  # float32 joint actions
    np.testing.assert_allclose(walk("residual"), gains, atol=1e-6)


def test_zero_residual_walks_the_reference_gait_with_the_reference_gains():
    def walk(**kwargs):
        env = gym.make(ENV_ID, terrain="flat", **kwargs)
        obs, _ = env.reset(seed=0)
        for _ in range(60):
            obs, *_, info = env.step(np.zeros(env.action_space.shape, np.float32))
        return info["cog"]

    simple = walk(action_mode="residual")
    np.testing.assert_array_equal(simple, walk(action_mode="gains"))  # gains (0, 0, 0)
    assert not np.array_equal(simple, walk(action_mode="residual", reference_gains=(1, 0, 0)))


def test_analytical_policy_is_registered_with_the_papers_gains():
    env = gym.make(ENV_ID, terrain="blocks", action_mode="gains")
    assert analytical_factory(ENV_ID) is analytical_policy
    policy = analytical_factory(ENV_ID)(env)
    obs, _ = env.reset(seed=0)
    assert policy(obs) == pytest.approx([0.6, 0.4, 0.4])


def test_flat_start_standing_height_clearance_and_zmp():
    env = gym.make(ENV_ID, terrain="flat")
    _, info = env.reset(seed=0)
    base = env.unwrapped
    assert info["torso_height"] == pytest.approx(ATHENA.standing_torso_height, abs=0.006)
    assert info["torso_clearance"] == pytest.approx(0.104 - 0.028, abs=0.006)
    assert len(info["stance_legs"]) == 6 and not info["torso_contact"]
    # Six feet equally loaded around the torso: the ZMP sits near the centre and its margin is
    # that of the standing hexagon (eq. 33), within the settling asymmetry.
    feet = standing_foot_positions()
    assert np.linalg.norm(info["zmp"]) < 0.01
    assert info["zmp_margin"] == pytest.approx(zmp_margin(feet, np.ones(6)), abs=0.01)
    assert info["fasm_margin_deg"] > 30.0
    assert (
        base.observation_structure["torso_height"].stop
        - base.observation_structure["torso_height"].start
        == 1
    )


def test_ramp_start_on_the_slope_and_on_the_approach():
    env = gym.make(ENV_ID, terrain="ramp")
    _, info = env.reset(seed=0)
    rot = env.unwrapped.data.xmat[env.unwrapped.sensors.torso_id].reshape(3, 3)
    nose_up = math.degrees(math.asin(rot[2, 0]))
    assert nose_up == pytest.approx(10.0, abs=1.0)  # parallel to the slope
    assert len(info["stance_legs"]) == 6
    assert info["torso_height"] == pytest.approx(ATHENA.standing_torso_height, abs=0.006)
    env = gym.make(ENV_ID, terrain="ramp", ramp_start_x=0.5)
    env.reset(seed=0)
    rot = env.unwrapped.data.xmat[env.unwrapped.sensors.torso_id].reshape(3, 3)
    assert abs(math.degrees(math.asin(rot[2, 0]))) < 1.0


def test_blocks_start_resting_on_the_bed():
    env = gym.make(ENV_ID, terrain="blocks")
    _, info = env.reset(seed=4)
    assert len(info["stance_legs"]) >= 3 and not info["torso_contact"]
    assert info["cog"][2] > 0.04 + 0.08  # above the lowest blocks, not on the floor


@pytest.mark.parametrize("terrain", TERRAINS)
def test_terrain_scan_is_the_torso_height_above_the_terrain_around_it(terrain):
    from hexapod_envs.envs.irregular_terrain import SCAN_X, SCAN_Y

    plain = gym.make(ENV_ID, terrain=terrain)
    env = gym.make(ENV_ID, terrain=terrain, terrain_scan=True)
    assert env.observation_space.shape[0] == plain.observation_space.shape[0] + 15
    obs, _ = env.reset(seed=2)
    for _ in range(5):
        obs, *_ = env.step(np.zeros(env.action_space.shape))
    base = env.unwrapped
    scan = obs[base.observation_structure["terrain_scan"]].reshape(len(SCAN_X), len(SCAN_Y))
    x, y, z = base.sensors.torso_position().tolist()
    rot = base.sensors.torso_rotation()
    heading = math.atan2(rot[1, 0], rot[0, 0])
    for i, ahead in enumerate(SCAN_X):
        for j, left in enumerate(SCAN_Y):
            px = x + math.cos(heading) * ahead - math.sin(heading) * left
            py = y + math.sin(heading) * ahead + math.cos(heading) * left
            info = base.terrain_info
            ground = 0.0 if info is None else info.height_at(px, py)
            assert scan[i, j] == pytest.approx(z - ground, abs=1e-6)  # float32 observation
    if terrain == "ramp":  # on the slope: the ground rises by 0.1 m x tan 10° per row ahead
        rows = scan.mean(axis=1)
        np.testing.assert_allclose(np.diff(rows), -0.1 * math.tan(math.radians(10)), atol=2e-3)
    if terrain == "flat":
        np.testing.assert_allclose(scan, z, atol=1e-6)
    with pytest.raises(ValueError, match="terrain_scan must be one of"):
        gym.make(ENV_ID, terrain_scan="yes")


@pytest.mark.parametrize("terrain", TERRAINS)
def test_foot_scan_is_each_foots_height_above_the_terrain_around_it(terrain):
    from hexapod_envs.envs.irregular_terrain import FOOT_SCAN_X, FOOT_SCAN_Y

    plain = gym.make(ENV_ID, terrain=terrain)
    env = gym.make(ENV_ID, terrain=terrain, foot_scan=True, terrain_scan=True)
    assert env.observation_space.shape[0] == plain.observation_space.shape[0] + 15 + 108
    obs, _ = env.reset(seed=3)
    for _ in range(7):
        obs, *_ = env.step(np.zeros(env.action_space.shape))
    base = env.unwrapped
    scan = obs[base.observation_structure["foot_scan"]].reshape(6, len(FOOT_SCAN_X), 3)
    rot = base.sensors.torso_rotation()
    heading = math.atan2(rot[1, 0], rot[0, 0])
    info = base.terrain_info
    for leg, (fx, fy, fz) in enumerate(base.sensors.foot_positions().tolist()):
        for i, ahead in enumerate(FOOT_SCAN_X):
            for j, left in enumerate(FOOT_SCAN_Y):
                px = fx + math.cos(heading) * ahead - math.sin(heading) * left
                py = fy + math.sin(heading) * ahead + math.cos(heading) * left
                ground = 0.0 if info is None else info.height_at(px, py)
                assert scan[leg, i, j] == pytest.approx(fz - ground, abs=1e-6)
    if terrain == "blocks":  # turned to face +y: ahead is +y and left is -x
        root = base.model.jnt_qposadr[0]
        base.data.qpos[root + 3 : root + 7] = [math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)]
        mujoco.mj_forward(base.model, base.data)
        turned = base.foot_scan().reshape(6, len(FOOT_SCAN_X), 3)
        for leg, (fx, fy, fz) in enumerate(base.sensors.foot_positions().tolist()):
            for i, ahead in enumerate(FOOT_SCAN_X):
                for j, left in enumerate(FOOT_SCAN_Y):
                    expected = fz - info.height_at(fx - left, fy + ahead)
                    assert turned[leg, i, j] == pytest.approx(expected, abs=1e-9)
        assert np.ptp(turned) > 0.02  # the block edges show
    own_spot = scan[:, FOOT_SCAN_X.index(0.0), FOOT_SCAN_Y.index(0.0)]
    loaded = obs[base.observation_structure["foot_contact"]] > 0
    assert loaded.sum() >= 3
    np.testing.assert_array_less(np.abs(own_spot[loaded]), 0.03)  # a loaded foot is on the ground
    if terrain == "flat":
        feet_z = base.sensors.foot_positions()[:, 2]
        np.testing.assert_allclose(scan, np.broadcast_to(feet_z[:, None, None], scan.shape))
    with pytest.raises(ValueError, match="foot_scan must be one of"):
        gym.make(ENV_ID, foot_scan="yes")


@pytest.mark.parametrize("terrain", TERRAINS)
def test_footprint_clearance_is_the_lowest_point_of_the_torso_bottom_above_the_terrain(terrain):
    env = gym.make(ENV_ID, terrain=terrain)
    env.reset(seed=5)
    base = env.unwrapped
    half = np.asarray(base.robot.body.size) / 2
    gaps = []
    for _ in range(60):
        env.step(np.zeros(env.action_space.shape))
        footprint = base.torso_footprint_clearance()
        # the grid holds the centre of the bottom face: never above the centre clearance
        gaps.append(base.torso_clearance() - footprint)
        assert gaps[-1] >= -1e-12
        if terrain == "flat":  # the lowest corner of a (slightly tilted) box over z = 0
            pos = base.data.xpos[base.sensors.torso_id]
            rot = base.data.xmat[base.sensors.torso_id].reshape(3, 3)
            corners = [rot @ (half * (sx, sy, -1.0)) for sx in (-1, 1) for sy in (-1, 1)]
            assert footprint == pytest.approx(pos[2] + min(c[2] for c in corners), abs=1e-12)
    if terrain == "blocks":  # blocks under an edge: well below the centre clearance at times
        assert max(gaps) > 0.005


def test_torso_contact_is_detected_and_penalised():
    """Legs folded up in joint mode: the torso drops onto the ground."""
    env = gym.make(ENV_ID, terrain="flat", action_mode="joint", collision_penalty=2.0)
    env.reset(seed=0)
    base = env.unwrapped
    up = base.action_map.to_action(np.tile([0.0, 1.4, -1.5 * math.pi / 2], 6))
    infos = [env.step(up.astype(np.float32))[-1] for _ in range(30)]
    touched = [i for i in infos if i["torso_contact"]]
    assert touched and touched[-1]["reward_torso_collision"] == -2.0
    assert infos[-1]["torso_collisions"] == len(touched)
    assert not infos[-1]["is_success"]
    assert infos[-1]["torso_clearance"] < 0.005


@pytest.mark.parametrize("integrator", ["implicitfast", "rk4"])
def test_torso_contact_between_sensor_evaluations_matches_the_sensor(integrator):
    """The env evaluates its sensors once per control period but looks for torso contact
    every 10 ms: each check must agree with the `torso_contact` sensor evaluated at that moment
    (replayed here on a copy stepping with every sensor on), also when the torso touches only
    between the period's sensor evaluations; under RK4 too, whose stages overwrite the
    contacts after a step."""
    env = gym.make(ENV_ID, terrain="blocks", action_mode="joint", integrator=integrator)
    env.reset(seed=0)
    base = env.unwrapped
    up = base.action_map.to_action(np.tile([0.0, 1.4, -1.5 * math.pi / 2], 6)).astype(np.float32)
    rng = np.random.default_rng(0)
    sensor = base.model.sensor(base.handles.torso_contact_sensor).adr[0]
    chunk = base.n_substeps // 5
    only_between = 0
    for k in range(25):  # torso dropped onto the bed, then lifted off by random joint targets
        replay = mujoco.MjData(base.model)
        mujoco.mj_copyData(replay, base.model, base.data)
        info = env.step(up if k < 15 else rng.uniform(-1, 1, 18).astype(np.float32))[-1]
        replay.ctrl[:] = base.data.ctrl
        checks = []
        for _ in range(5):
            mujoco.mj_step(base.model, replay, nstep=chunk)
            checks.append(replay.sensordata[sensor] > 0)
        np.testing.assert_array_equal(replay.qpos, base.data.qpos)
        assert info["torso_contact"] == any(checks), k
        only_between += any(checks) and not checks[-1]
    assert only_between >= 1


def test_unstable_simulation_truncates_with_a_flag():
    env = gym.make(ENV_ID, terrain="flat")
    env.reset(seed=0)
    env.unwrapped.data.qvel[:] = 1e12
    _, reward, terminated, truncated, info = env.step(np.zeros(18, np.float32))
    assert truncated and not terminated and info["sim_unstable"] and reward == 0.0
    assert not info["is_success"]


def test_an_episode_that_tipped_over_stays_terminated_when_the_simulation_then_fails():
    env = gym.make(ENV_ID, terrain="flat").unwrapped
    env.reset(seed=0)
    env._tipped = True  # as after a tip-over step (termination is sticky)
    env.data.qvel[:] = 1e12
    _, reward, terminated, truncated, info = env.step(np.zeros(18, np.float32))
    assert terminated and truncated and info["sim_unstable"] and reward == 0.0


def test_nan_action_is_a_clear_error():
    env = gym.make(ENV_ID, action_mode="gains")
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"NaN.*\[1\]"):
        env.step(np.array([0.5, np.nan, 0.0]))


def test_unknown_keyword_is_named_with_valid_choices():
    with pytest.raises(TypeError, match=r"swing_hieght.*valid.*swing_height"):
        gym.make(ENV_ID, swing_hieght=0.1)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"terrain": "ice"}, "blocks"),
        ({"action_mode": "torque"}, "gains"),
        ({"ramp_start_x": 0.0}, "under the robot"),
        ({"reference_gains": (0.5, 1.5, 0.0)}, r"reference_gains entries must be >= 0 and <= 1"),
        ({"reference_gains": (0.5,)}, "reference_gains must have 3 entries"),
        ({"physics_dt": 0.003}, "whole multiple"),
        ({"physics_dt": 0.05 / 12}, "multiple of 5"),
        ({"servo_kp": 0.0}, "servo_kp"),
        ({"gait_start_from": "guess"}, "measured_height"),
        ({"gait_ground_search": "sometimes"}, "always"),
        ({"phase_time": 0.33}, "whole number"),
    ],
)
def test_bad_choices_list_the_valid_ones(kwargs, match):
    with pytest.raises(ValueError, match=match):
        gym.make(ENV_ID, **kwargs)


def test_policy_rejects_gains_outside_the_unit_interval():
    env = gym.make(ENV_ID, action_mode="gains")
    with pytest.raises(ValueError, match="kz"):
        AthenaPosturePolicy(env, kz=1.2)


def test_standing_still_is_not_a_success():
    """Success needs progress (half the gait's nominal distance), not only no tip-over and no
    torso contact: a robot holding its start posture fails, the reference gait succeeds."""
    env = gym.make("HexapodIrregularTerrain-v0", terrain="flat", action_mode="joint")
    obs, _ = env.reset(seed=0)
    base = env.unwrapped
    hold = base.action_map.to_action(obs[base.observation_structure["joint_pos"]])
    for _ in range(100):
        obs, _, terminated, truncated, info = env.step(hold)
    assert not terminated and not info["is_tipped_over"] and info["torso_collisions"] == 0
    assert abs(info["distance"]) < 0.05 and not info["is_success"]
    walker = gym.make("HexapodIrregularTerrain-v0", terrain="flat")
    walker.reset(seed=0)
    for _ in range(100):
        *_, info = walker.step(np.zeros(18, dtype=np.float32))
    assert info["is_success"]


def test_gymnasium_vector_envs_batch_the_infos_of_cycles_out_of_step():
    """Two block-bed envs in the gains mode reach their gait cycles' starts at other steps; the
    per-cycle statistics are in the info only when a cycle finished, so the vector env batches
    them (a key that was None in one env and a dict in the other raised there)."""
    envs = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="sync", action_mode="gains",
                        terrain="blocks")  # fmt: skip
    envs.reset(seed=[0, 5])
    rng = np.random.default_rng(0)
    finished = 0
    for _ in range(120):
        _, _, _, _, infos = envs.step(rng.uniform(0.0, 1.0, (2, 3)).astype(np.float32))
        finished += int(np.sum(infos.get("_cycle_stats", [False, False])))
    envs.close()
    assert finished >= 2


def test_a_servo_delay_needs_a_physics_step_its_history_covers():
    with pytest.raises(ValueError, match=r"servo_delay > 0 needs physics_dt >= 0\.0005"):
        gym.make("HexapodIrregularTerrain-v0", servo_delay=0.02, physics_dt=0.0001)


def test_a_drawn_highest_block_below_the_lowest_is_what_the_bed_has():
    """The bed's lowest block (block_height_range[0], 0.04 m) bounds its highest: a task drawn
    lower records, and is rated by, the height the bed really has."""
    env = gym.make(
        "HexapodIrregularTerrain-v1",
        task_distribution="train",
        train_ranges={"block_height_max": (0.02, 0.03)},
    )
    _, info = env.reset(seed=0)
    heights = env.unwrapped.terrain_info.heights
    assert info["task"]["block_height_max"] == 0.04 == heights.min() == heights.max()
