"""Invariants every registered hexapod env must satisfy (docs/architecture.md)."""

import copy
import math
from functools import partial

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import hexapod_envs  # noqa: F401
from hexapod_envs.envs import physics

ENV_IDS = sorted(k for k in gym.registry if k.startswith("Hexapod"))
IRREGULAR = "HexapodIrregularTerrain-v0"


def test_env_ids_registered():
    assert "HexapodCliffWalk-v0" in ENV_IDS


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_and_sb3_checkers_pass(env_id):
    env = gym.make(env_id)
    gym_check_env(env.unwrapped, skip_render_check=True)
    sb3_check_env(env.unwrapped, warn=True)
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_trajectory(env_id):
    def rollout():
        env = gym.make(env_id)
        obs, _ = env.reset(seed=123)
        env.action_space.seed(7)
        trace = [obs]
        for _ in range(40):
            obs, reward, *_ = env.step(env.action_space.sample())
            trace.append(np.append(obs, reward))
        env.close()
        return np.concatenate(trace)

    np.testing.assert_array_equal(rollout(), rollout())


def _random_rollout(env_id, steps=60, **kwargs):
    """Observations, rewards and numeric infos of `steps` seeded random actions, flattened."""
    env = gym.make(env_id, **kwargs)
    obs, _ = env.reset(seed=5)
    env.action_space.seed(5)
    trace = [obs]
    for _ in range(steps):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        numbers = [v for v in info.values() if isinstance(v, (int, float, np.ndarray))]
        trace.append(np.concatenate([obs, [reward], *map(np.ravel, numbers)]))
        if terminated or truncated:
            break
    env.close()
    return np.concatenate(trace)


SPEED_ONLY_CASES = [(e, {}) for e in ENV_IDS] + [(IRREGULAR, {"terrain": "blocks"})]


@pytest.mark.parametrize(("env_id", "kwargs"), SPEED_ONLY_CASES)
def test_sensing_in_the_last_substep_only_leaves_every_step_unchanged(env_id, kwargs, monkeypatch):
    """The envs skip the sensors in all but the last physics step of a control period (ATHENA:
    of each contact check); observations, rewards and infos equal those of sensing every step."""
    skipping = _random_rollout(env_id, **kwargs)
    monkeypatch.setattr(physics, "SENSORS_OFF", 0)  # "disable nothing": sensors at every step
    np.testing.assert_array_equal(skipping, _random_rollout(env_id, **kwargs))


@pytest.mark.parametrize(("env_id", "kwargs"), SPEED_ONLY_CASES)
def test_the_collision_midphase_changes_no_step(env_id, kwargs):
    """``midphase`` is chosen per env by speed alone: both ways give the same episode."""
    on = _random_rollout(env_id, midphase=True, **kwargs)
    np.testing.assert_array_equal(on, _random_rollout(env_id, midphase=False, **kwargs))


@pytest.mark.parametrize(
    ("env_id", "kwargs", "default"),
    [
        ("HexapodCliffWalk-v0", {}, False),
        ("HexapodStewartTilt-v0", {}, False),
        (IRREGULAR, {}, False),
        (IRREGULAR, {"terrain": "blocks"}, True),
        ("HexapodDitchCrossing-v0", {}, True),
    ],
)
def test_the_midphase_setting_reaches_the_model(env_id, kwargs, default):
    for setting, expected in ((None, default), (True, True), (False, False)):
        with gym.make(env_id, midphase=setting, **kwargs) as env:
            env.reset(seed=0)
            flags = env.unwrapped.model.opt.disableflags
            assert bool(flags & mujoco.mjtDisableBit.mjDSBL_MIDPHASE) != expected, setting


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_observation_finite_in_space_and_reward_is_sum_of_terms(env_id):
    env = gym.make(env_id)
    obs, info = env.reset(seed=1)
    structure = env.unwrapped.observation_structure
    assert {"foot_force", "fasm_margin_deg", "joint_pos", "joint_vel"} <= set(structure)
    assert max(s.stop for s in structure.values()) == env.observation_space.shape[0]
    for _ in range(30):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs) and np.all(np.isfinite(obs))
        terms = {k: v for k, v in info.items() if k.startswith("reward_")}
        assert terms and reward == pytest.approx(sum(terms.values()))
        for key in ("fasm_margin_deg", "stance_legs", "is_tipping", "is_success"):
            assert key in info
        if terminated or truncated:
            break
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rgb_render_headless(env_id):
    env = gym.make(env_id, render_mode="rgb_array", width=96, height=64)
    env.reset(seed=0)
    frame = env.render()
    env.close()
    assert frame.shape == (64, 96, 3) and frame.std() > 0


def test_a_rendered_env_deep_copies_and_the_copy_renders_on_its_own():
    """The renderer's OpenGL context cannot be copied: a copy of a rendered env (look-ahead
    rollouts copy the env every cycle) makes its own, and both render the same frame."""
    env = gym.make(ENV_IDS[0], render_mode="rgb_array", width=96, height=64).unwrapped
    env.reset(seed=0)
    env.render()
    twin = copy.deepcopy(env)
    np.testing.assert_array_equal(twin.render(), env.render())
    twin.close()
    assert env.render().std() > 0  # closing the copy leaves the original's renderer alone
    env.close()


def test_envs_rendering_in_turn_each_draw_their_own_scene():
    """Each env's frame is drawn in its own OpenGL context, also after another env rendered
    (Gymnasium's renderer leaves the last-made context current) and after it closed."""
    make = partial(gym.make, render_mode="rgb_array", width=96, height=64)
    first, second = make(ENV_IDS[0]), make("HexapodIrregularTerrain-v1")
    first.reset(seed=0)
    alone = first.render().copy()
    second.reset(seed=0)
    second.render()
    np.testing.assert_array_equal(first.render(), alone)
    second.close()
    np.testing.assert_array_equal(first.render(), alone)
    first.close()


def test_rendering_without_an_opengl_context_says_to_set_mujoco_gl():
    """Without MUJOCO_GL and a display MuJoCo finds no OpenGL context: render() says what to
    set instead of MuJoCo's bare FatalError."""
    import os
    import subprocess
    import sys

    from helpers.paths import REPO

    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY")}
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), env.get("PYTHONPATH", "")])
    code = (
        "import gymnasium as gym, hexapod_envs\n"
        "env = gym.make('HexapodCliffWalk-v1', render_mode='rgb_array', width=32, height=24)\n"
        "env.reset(seed=0)\n"
        "env.render()\n"
        "print('rendered')\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", code], env=env, cwd=REPO, capture_output=True, text=True, timeout=300
    )
    if "rendered" in run.stdout:
        pytest.skip("this machine renders without MUJOCO_GL and a display")
    assert "RuntimeError: rendering needs an OpenGL context" in run.stderr, run.stderr[-2000:]
    assert "MUJOCO_GL=egl" in run.stderr


def test_a_missing_opengl_context_becomes_an_error_that_names_mujoco_gl(monkeypatch):
    """The same on any machine: a renderer whose render() meets MuJoCo's no-context error."""
    from hexapod_envs.envs import base

    class FailingRenderer:  # as Gymnasium's: the error comes when a viewer is made
        message = "an OpenGL platform library has not been loaded"
        _viewers = {}

        def _get_viewer(self, mode):
            raise mujoco.FatalError(self.message)

        def render(self, mode):
            return self._get_viewer(mode)

        def close(self):
            pass

    renderer = FailingRenderer()
    monkeypatch.setattr(base, "make_renderer", lambda *args: renderer)
    env = gym.make("HexapodCliffWalk-v1", render_mode="rgb_array")
    env.reset(seed=0)
    with pytest.raises(RuntimeError, match="set MUJOCO_GL=egl"):
        env.render()
    renderer.message = "another fatal error"  # passed on as it is
    with pytest.raises(mujoco.FatalError, match="another fatal error"):
        env.render()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_docstring_tables_name_every_observation_piece_and_reward_term(env_id):
    """The user-facing docstring (module + class) must describe what the env really returns."""
    import inspect

    env = gym.make(env_id)
    base = env.unwrapped
    doc = (inspect.getmodule(type(base)).__doc__ or "") + (type(base).__doc__ or "")
    _, info = env.reset(seed=0)
    _, _, _, _, info = env.step(env.action_space.sample())
    missing = [name for name in base.observation_structure if name not in doc]
    missing += [k for k in info if k.startswith("reward_") and k[len("reward_") :] not in doc]
    env.close()
    assert not missing, f"{env_id} docstring does not mention {missing}"


# --- the episode skeleton --------------------------------------------------------------------
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_reset_and_step_come_from_the_base(env_id):
    from hexapod_envs.envs.base import HexapodEnv

    cls = type(gym.make(env_id).unwrapped)
    for klass in cls.__mro__[: cls.__mro__.index(HexapodEnv)]:
        assert "step" not in vars(klass) and "reset" not in vars(klass), klass.__name__


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_common_info_keys_and_task_at_reset_and_every_step(env_id):
    from hexapod_envs.info_keys import COMMON_INFO_KEYS, TASK

    env = gym.make(env_id)
    _, info = env.reset(seed=3)
    infos = [info] + [env.step(env.action_space.sample())[4] for _ in range(3)]
    for info in infos:
        assert set(COMMON_INFO_KEYS) <= set(info), set(COMMON_INFO_KEYS) - set(info)
        task = info[TASK]
        assert task and all(type(v) in (float, int, str) for v in task.values()), task
        assert np.isfinite(info["fasm_margin_deg"])
    assert infos[1][TASK] is not infos[2][TASK]  # a fresh dict: callers may keep infos
    base = env.unwrapped
    assert isinstance(base.tipping_threshold_deg, float) and base.stability_criterion
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_step_before_reset_says_call_reset_first(env_id):
    env = gym.make(env_id).unwrapped
    with pytest.raises(RuntimeError, match=r"call reset\(\) first"):
        env.step(env.action_space.sample())


def test_reset_options_are_refused_not_ignored():
    env = gym.make("HexapodCliffWalk-v1")
    env.reset(seed=0, options={})  # None and an empty dict are no options
    with pytest.raises(ValueError, match=r"takes no options, got \['task'\].*'paper', 'train'"):
        env.reset(seed=0, options={"task": {"cliff_x": 1.0}})


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("kind", ["complex", "bool", "object", "str"])
def test_non_real_actions_are_refused(env_id, kind):
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    n = env.action_space.shape[0]
    action = {
        "complex": np.zeros(n, dtype=complex),
        "bool": np.zeros(n, dtype=bool),
        "object": np.array([0.0] * n, dtype=object),
        "str": np.array(["0"] * n),
    }[kind]
    with pytest.raises(ValueError, match="dtype"):
        env.step(action)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_every_real_dtype_and_layout_of_an_action_steps_as_float64(env_id):
    """Half, single, double and extended floats, integers and strided views give the step of
    the same values as float64 (clipped into the action space)."""
    n = gym.make(env_id).action_space.shape[0]

    def first_step(action):
        env = gym.make(env_id).unwrapped
        env.reset(seed=0)
        obs, reward, *_ = env.step(action)
        return obs, reward, env.data.ctrl.copy()

    def same(a, b):
        return all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))

    values = np.resize([-3.0, -0.5, 0.0, 0.25, 2.0], n)  # exact in every float dtype
    double = first_step(values)
    for dtype in (np.float16, np.float32, np.longdouble):
        assert same(first_step(values.astype(dtype)), double), dtype
    assert same(first_step(np.repeat(values, 2)[::2]), double)  # a strided view
    counts = np.resize([0, 1, 2], n)
    for dtype in (np.int8, np.uint8, np.int64):
        assert same(first_step(counts.astype(dtype)), first_step(counts.astype(float))), dtype


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_tip_over_penalty_is_paid_once_and_termination_sticks(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    upright = env.tip_over_cos
    env.tip_over_cos = 2.0  # every pose counts as tipped over
    action = np.zeros(env.action_space.shape)
    _, _, terminated, _, info = env.step(action)
    assert terminated and info["is_tipped_over"] and info["reward_tip_over"] < 0
    env.tip_over_cos = upright  # the robot stands again: the episode stays ended
    for _ in range(2):
        _, _, terminated, _, info = env.step(action)
        assert terminated and info["is_tipped_over"] and info["reward_tip_over"] == 0.0


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_mujoco_warning_counts_as_instability(env_id):
    env = gym.make(env_id).unwrapped
    obs0, _ = env.reset(seed=0)
    env.data.qvel[:] = 1e12  # MuJoCo flags a bad qvel and resets the state
    obs, reward, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
    assert info["sim_unstable"] and truncated and not terminated and reward == 0.0
    assert np.all(np.isfinite(obs))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_a_warning_alone_marks_the_step_unstable(env_id):
    """A warning counted on a step whose clock advanced truncates the episode too: the check
    does not rest on the clock alone (the count is set by hand here; MuJoCo itself also resets
    the state, clock included, when it meets bad values)."""
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    env.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number = 1
    time_before = env.data.time
    *_, truncated, info = env.step(np.zeros(env.action_space.shape))
    assert env.data.time == pytest.approx(time_before + env.control_dt)
    assert truncated and info["sim_unstable"]


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_an_unstable_step_returns_the_last_observation_as_it_was_returned(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    obs = env.step(np.zeros(env.action_space.shape))[0]
    kept = obs.copy()
    obs[:] = 0.0  # a caller editing its observation in place
    env.data.qvel[:] = 1e12
    again, *_, info = env.step(np.zeros(env.action_space.shape))
    assert info["sim_unstable"]
    np.testing.assert_array_equal(again, kept)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_instability_while_settling_is_flagged_at_reset(env_id, monkeypatch):
    env = gym.make(env_id).unwrapped
    monkeypatch.setattr(env, "_simulate", lambda: False)  # every settle period unstable
    assert env.reset(seed=0)[1]["sim_unstable"]


def _cloudpickled(env):
    import cloudpickle  # a Gymnasium dependency; plain pickle cannot take the readers' lambdas

    return cloudpickle.loads(cloudpickle.dumps(env))


@pytest.mark.parametrize("copier", [copy.deepcopy, _cloudpickled], ids=["deepcopy", "cloudpickle"])
@pytest.mark.parametrize(
    ("env_id", "kwargs"), [*SPEED_ONLY_CASES, (ENV_IDS[0], {"sensor_noise": 0.05})]
)
def test_a_deep_copy_steps_and_observes_on_its_own(env_id, kwargs, copier):
    """`copy.deepcopy` of a reset env (look-ahead and common-random-number rollouts step such
    twins), or a pickled and unpickled one: the twin's observations equal a fresh env's stepped
    alike; the original is intact (with sensor noise: the twin draws from its own copy of the
    random generator)."""
    space = gym.make(env_id, **kwargs).action_space
    space.seed(9)
    actions = [space.sample() for _ in range(5)]

    def fresh():
        env = gym.make(env_id, **kwargs).unwrapped
        env.reset(seed=3)
        return env

    original = fresh()
    twin, alike = copier(original), fresh()
    for a in actions:
        np.testing.assert_array_equal(twin.step(a)[0], alike.step(a)[0])
    np.testing.assert_array_equal(original.step(actions[0])[0], fresh().step(actions[0])[0])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_task_description_is_declared_and_frozen(env_id):
    import dataclasses

    env = gym.make(env_id, task_distribution="train").unwrapped
    _, info = env.reset(seed=2)
    desc = env.task_description
    assert dict(desc.course) == info["task"] and desc.reference
    assert len(desc.joint_low) == len(desc.joint_high) and desc.control_dt == env.control_dt
    assert desc.tipping_threshold_deg == env.tipping_threshold_deg
    with pytest.raises(dataclasses.FrozenInstanceError):
        desc.control_dt = 1.0
    with pytest.raises(TypeError):
        desc.course["x"] = 1.0
    import pickle

    for copied in (copy.deepcopy(desc), pickle.loads(pickle.dumps(desc))):
        assert copied.course == desc.course and type(copied.robot) is type(desc.robot)
        assert copied.observation_structure == desc.observation_structure
        assert copied.reference.keys() == desc.reference.keys()  # values: arrays, plans
        with pytest.raises(TypeError):  # read-only again
            copied.reference["x"] = 1.0


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_numeric_info_values_are_finite_or_nan_by_contract(env_id):
    from hexapod_envs.info_keys import UNDEFINED_AS_NAN

    env = gym.make(env_id, task_distribution="train")
    _, info = env.reset(seed=5)
    infos = [info] + [env.step(env.action_space.sample())[4] for _ in range(30)]
    for info in infos:
        for key, value in info.items():
            if key in UNDEFINED_AS_NAN:
                continue
            for path, number in _numbers(value, key):  # inside tuples and dicts too
                assert math.isfinite(number), (path, number)
    env.close()


def _numbers(value, path):
    """(path, float) of every number in `value`, through dicts, tuples, lists and arrays."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _numbers(item, f"{path}.{key}")
    elif isinstance(value, (tuple, list)):
        for i, item in enumerate(value):
            yield from _numbers(item, f"{path}[{i}]")
    elif isinstance(value, (bool, np.bool_)) or value is None or isinstance(value, str):
        return
    else:
        for number in np.asarray(value, dtype=float).ravel():
            yield path, float(number)
