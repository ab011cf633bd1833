"""The batched vector env (`hexapod_envs.vector`) returns exactly what N single envs return.

The reference is Gymnasium's `SyncVectorEnv` over ``gym.make(id)`` envs with the same seeds:
observations, rewards, terminations, truncations and the vector info dict are compared bit for
bit over episodes that end by tipping over and by the time limit, through the autoresets."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode
from helpers.same import assert_same

import hexapod_envs  # noqa: F401  (registers the ids)
from hexapod_envs.vector import BatchedVectorEnv

BATCHED_IDS = [
    "HexapodCliffWalk-v0",
    "HexapodCliffWalk-v1",
    "HexapodStewartTilt-v0",
    "HexapodStewartTilt-v1",
    "HexapodIrregularTerrain-v0",
    "HexapodIrregularTerrain-v1",
]


def _pair(env_id: str, num_envs: int, nthread: int = 2, **kwargs):
    batched = gym.make_vec(
        env_id, num_envs, vectorization_mode="vector_entry_point", nthread=nthread, **kwargs
    )
    autoreset = kwargs.pop("autoreset_mode", AutoresetMode.NEXT_STEP)
    sync = gym.make_vec(
        env_id,
        num_envs,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": autoreset},
        **kwargs,
    )
    return batched, sync


def _run_both(batched, sync, steps: int, seed: int) -> tuple[int, int]:
    """Step both with the same random actions; (terminations, truncations) seen."""
    assert_same(batched.reset(seed=seed), sync.reset(seed=seed), "reset")
    rng = np.random.default_rng(seed)
    shape = (batched.num_envs, *batched.single_action_space.shape)
    ended = np.zeros(2, dtype=int)
    for k in range(steps):
        actions = rng.uniform(-1.0, 1.0, shape).astype(np.float32)
        got, expected = batched.step(actions), sync.step(actions)
        assert_same(got, expected, f"step {k}")
        ended += [int(got[2].sum()), int(got[3].sum())]
    batched.close()
    sync.close()
    return tuple(ended)


@pytest.mark.parametrize("env_id", BATCHED_IDS)
def test_batched_equals_single_envs_through_resets(env_id):
    batched, sync = _pair(env_id, 3, task_distribution="train", max_episode_steps=40)
    assert isinstance(batched, BatchedVectorEnv)
    terminated, truncated = _run_both(batched, sync, 130, seed=7)
    assert truncated > 0  # the time limit's autoresets were exercised


@pytest.mark.parametrize("env_id", ["HexapodDitchCrossing-v0", "HexapodDitchCrossing-v1"])
def test_the_ditch_crossing_batches_too(env_id):
    """The UPU robot's env (registered with the same entry point) on its paper task."""
    batched, sync = _pair(env_id, 2, max_episode_steps=30)
    assert sum(_run_both(batched, sync, 70, seed=3)) > 0  # episodes ended and reset


@pytest.mark.parametrize("landing_action", [False, True])
def test_batched_equals_single_envs_on_tip_overs(landing_action):
    """On a platform that starts tilting at once, the held robot tips over: terminations and
    their autoresets (with the landing action too: a 19th action, state carried per world)."""
    batched, sync = _pair(
        "HexapodStewartTilt-v1",
        2,
        task_distribution="train",
        tilt_start_time=0.2,
        max_episode_steps=400,
        landing_action=landing_action,
    )
    assert batched.single_action_space.shape == (19 if landing_action else 18,)
    terminated, _ = _run_both(batched, sync, 300, seed=1)
    assert terminated > 0


@pytest.mark.parametrize("nthread", [0, 1, 3])
def test_thread_count_does_not_change_results(nthread):
    batched, sync = _pair("HexapodStewartTilt-v1", 4, nthread=nthread, max_episode_steps=25)
    _run_both(batched, sync, 60, seed=2)


def test_same_step_autoreset():
    batched, sync = _pair(
        "HexapodCliffWalk-v0", 2, autoreset_mode=AutoresetMode.SAME_STEP, max_episode_steps=20
    )
    assert batched.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    _run_both(batched, sync, 50, seed=4)


def test_registered_ids_build_batched_worlds_with_their_settings():
    for env_id in [*BATCHED_IDS, "HexapodDitchCrossing-v0", "HexapodDitchCrossing-v1"]:
        spec = gym.spec(env_id)
        envs = gym.make_vec(env_id, 2, vectorization_mode="vector_entry_point", nthread=1)
        single = gym.make(env_id)
        assert envs.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
        assert vars(envs.worlds[0].settings) == vars(single.unwrapped.settings), env_id
        assert envs.envs[0]._max_episode_steps == spec.max_episode_steps
        assert envs.single_observation_space == single.observation_space
        envs.close()
        single.close()
    # None is the registered time limit, as gym.make reads it; a number replaces it.
    for limit, expected in ((None, 1500), (40, 40)):
        envs = gym.make_vec(
            "HexapodCliffWalk-v1",
            2,
            vectorization_mode="vector_entry_point",
            nthread=0,
            max_episode_steps=limit,
        )
        assert (
            envs.envs[0]._max_episode_steps
            == expected
            == gym.make("HexapodCliffWalk-v1", max_episode_steps=limit)._max_episode_steps
        )
        envs.close()


def test_bad_action_leaves_every_world_alone():
    batched, sync = _pair("HexapodCliffWalk-v1", 2, max_episode_steps=30)
    batched.reset(seed=0)
    sync.reset(seed=0)
    bad = np.zeros((2, 18), dtype=np.float32)
    bad[1, 3] = np.nan
    with pytest.raises(ValueError, match="NaN or inf"):
        batched.step(bad)
    assert not any("_simulate" in w.__dict__ for w in batched.worlds)
    good = np.full((2, 18), 0.1, dtype=np.float32)
    assert_same(batched.step(good), sync.step(good), "after the refused action")


def test_nthread_is_checked():
    with pytest.raises(ValueError, match="nthread must be an integer >= 0"):
        gym.make_vec("HexapodCliffWalk-v0", 2, vectorization_mode="vector_entry_point", nthread=-1)


def test_a_wrapper_that_changes_the_action_is_refused():
    def world():
        env = gym.make("HexapodCliffWalk-v1")
        return gym.wrappers.TransformAction(env, lambda a: 0.5 * a, env.action_space)

    envs = BatchedVectorEnv([world, world], nthread=1)
    envs.reset(seed=0)
    with pytest.raises(RuntimeError, match="a wrapper changed the action"):
        envs.step(np.ones((2, 18), dtype=np.float32))
    assert not any("_apply_action" in w.__dict__ for w in envs.worlds)
    envs.close()


def test_an_error_in_a_world_s_physics_reaches_the_caller():
    envs = gym.make_vec(
        "HexapodCliffWalk-v1", 3, vectorization_mode="vector_entry_point", nthread=2
    )
    envs.reset(seed=0)

    def broken():
        raise FloatingPointError("physics failed")

    envs.worlds[1]._simulate = broken
    with pytest.raises(FloatingPointError, match="physics failed"):
        envs.step(np.zeros((3, 18), dtype=np.float32))
    assert not any("_simulate" in w.__dict__ or "_apply_action" in w.__dict__ for w in envs.worlds)
    with pytest.raises(RuntimeError, match="call reset"):  # worlds 0 and 2 ran physics alone
        envs.step(np.zeros((3, 18), dtype=np.float32))
    sync = gym.make_vec("HexapodCliffWalk-v1", 3, vectorization_mode="sync")
    zeros = np.zeros((3, 18), dtype=np.float32)
    # the threads serve the next steps, and the vector info is merged again
    assert_same(envs.reset(seed=1), sync.reset(seed=1), "reset after the error")
    assert_same(envs.step(zeros), sync.step(zeros), "step after the error")
    envs.close()
    sync.close()


def test_an_error_applying_an_action_leaves_no_physics_running():
    """World 2's action fails after worlds 0 and 1 have their physics queued."""
    envs = gym.make_vec(
        "HexapodCliffWalk-v1", 3, vectorization_mode="vector_entry_point", nthread=2
    )
    envs.reset(seed=0)

    def broken(action):
        raise FloatingPointError("servo command failed")

    envs.worlds[2]._apply_action = broken
    with pytest.raises(FloatingPointError, match="servo command failed"):
        envs.step(np.zeros((3, 18), dtype=np.float32))
    assert not envs.physics._running
    assert all(w._needs_reset for w in envs.worlds)
    assert "_apply_action" not in envs.worlds[2].__dict__  # the step's replacements are gone
    envs.reset(seed=1)
    envs.step(np.zeros((3, 18), dtype=np.float32))
    envs.close()


def test_plain_control_periods_run_compiled():
    """The heavy-duty and UPU worlds' periods are plain MuJoCo steps (the compiled mode where
    the machine has it); ATHENA's contact checks keep the pool of `_simulate` calls."""
    from hexapod_envs.vector.compiled_steps import compiled_steps_available

    for env_id, plain in (
        ("HexapodCliffWalk-v1", True),
        ("HexapodStewartTilt-v1", True),
        ("HexapodDitchCrossing-v1", True),
        ("HexapodIrregularTerrain-v1", False),
    ):
        envs = gym.make_vec(env_id, 2, vectorization_mode="vector_entry_point", nthread=2)
        assert envs.physics.compiled == (plain and compiled_steps_available()), env_id
        envs.close()
    envs = gym.make_vec(
        "HexapodCliffWalk-v1", 2, vectorization_mode="vector_entry_point", nthread=0
    )
    assert not envs.physics.compiled  # no threads: the plain SyncVectorEnv step
    envs.close()


@pytest.mark.parametrize("share", [0.0, 0.5, 1.0])
def test_the_split_between_the_threads_does_not_change_results(share):
    """The calling thread's share of the worlds in the compiled mode, held at each extreme."""
    batched, sync = _pair("HexapodCliffWalk-v1", 5, nthread=3, max_episode_steps=20)
    assert_same(batched.reset(seed=5), sync.reset(seed=5), "reset")
    rng = np.random.default_rng(5)
    for k in range(45):
        batched.physics._own_share = share
        actions = rng.uniform(-1.0, 1.0, (5, 18)).astype(np.float32)
        assert_same(batched.step(actions), sync.step(actions), f"step {k}")
    batched.close()
    sync.close()


def _balance(stores_in_order, monkeypatch, done, share=0.5):
    """A `_Balance` over 4 worlds whose last 2 are one helper's share (already finished: its
    future is done), with the done flags `done`."""
    from concurrent.futures import Future
    from types import SimpleNamespace

    import hexapod_envs.vector.batched as batched_module

    monkeypatch.setattr(batched_module, "_STORES_IN_ORDER", stores_in_order)
    physics = SimpleNamespace(worlds=[None] * 4, _done=np.array(done, np.int8), _own_share=share)
    future = Future()
    future.set_result(None)
    return physics, batched_module._Balance(physics, {range(2, 4): future}, 2, 4)


@pytest.mark.parametrize("stores_in_order", [True, False])
def test_the_split_moves_toward_the_thread_that_waited(stores_in_order, monkeypatch):
    """The calling thread's share moves by one world a step: down when the helper had
    finished before the calling thread reached its first world, up when the calling thread
    had to wait for it (for the last world where the flags are trusted, for the share where
    they are not). Each world's wait returns its stability check."""
    physics, balance = _balance(stores_in_order, monkeypatch, [1, 1, 1, 1])
    assert balance.wait(2, lambda: True) and balance.wait(3, lambda: False) is False
    assert physics._own_share == 0.25  # the helper waited idle
    physics, balance = _balance(stores_in_order, monkeypatch, [1, 1, 0, 0])
    balance.wait(2, lambda: True)
    balance.wait(3, lambda: True)
    assert physics._own_share == 0.75  # the calling thread waited
    physics, balance = _balance(stores_in_order, monkeypatch, [1, 1, 1, 0])
    balance.wait(2, lambda: True)
    balance.wait(3, lambda: True)  # the last world only
    assert physics._own_share == 0.75
    physics, balance = _balance(stores_in_order, monkeypatch, [1, 1, 0, 0], share=1.0)
    balance.wait(2, lambda: True)
    balance.wait(3, lambda: True)
    assert physics._own_share == 1.0  # within [0, 1] (the step keeps the helpers a world)


def test_the_helpers_keep_a_world_at_any_split():
    envs = gym.make_vec(
        "HexapodStewartTilt-v1", 4, vectorization_mode="vector_entry_point", nthread=2
    )
    if not envs.physics.compiled:
        pytest.skip("compiled control periods not available here")
    envs.reset(seed=0)
    envs.physics._own_share = 1.0
    submitted = []
    pool = envs.physics._pool
    original = pool.submit
    pool.submit = lambda *args: submitted.append(args[-2:]) or original(*args)
    envs.step(np.zeros((4, 18), dtype=np.float32))
    assert submitted == [(3, 4)]  # the calling thread steps worlds 0-2, the helper world 3
    envs.close()


def test_a_step_on_which_every_world_autoresets():
    """Worlds that all reach the time limit together all autoreset on the next step: a step
    in which no world's physics runs."""
    batched, sync = _pair("HexapodStewartTilt-v1", 2, nthread=2, max_episode_steps=3)
    assert_same(batched.reset(seed=0), sync.reset(seed=0), "reset")
    zeros = np.zeros((2, 18), dtype=np.float32)
    for k in range(8):
        got = batched.step(zeros)
        assert_same(got, sync.step(zeros), f"step {k}")
        if k == 2:
            assert got[3].all()  # both truncated: the next step resets both
    batched.close()
    sync.close()
