"""`merge_infos` builds the vector info dict that Gymnasium's world-by-world merge
(`VectorEnv._add_info`) builds, on the shapes of info the envs give and on the irregular ones."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.vector.vector_env import VectorEnv
from helpers.same import assert_same

from hexapod_envs.vector.infos import merge_infos

N = 4


class _Gymnasium:
    """Gymnasium's merge on its own: `_add_info` reads only `num_envs` and itself."""

    num_envs = N
    _add_info = VectorEnv._add_info


def _both(entries):
    ref = _Gymnasium()
    expected = {}
    for info, world in entries:
        expected = ref._add_info(expected, info, world)
    return merge_infos(entries, N, ref._add_info), expected


CASES = {
    "alike scalars and arrays, nested dict": [
        (
            {"a": 1.5, "n": 3, "b": True, "v": np.arange(3.0), "t": {"x": 0.1, "s": "left"}},
            world,
        )
        for world in range(N)
    ],
    "a key some worlds lack, in another order": [
        ({"a": 1.0, "only_0": (1, 2)}, 0),
        ({"a": 2.0}, 1),
        ({"late": np.float32(2.5), "a": 3.0}, 3),
    ],
    "None beside tuples (object array)": [
        ({"edge": None}, 0),
        ({"edge": (0, 1)}, 1),
        ({"edge": (2, 3)}, 2),
    ],
    "a float, then None (cast one by one: NaN)": [({"t": 1.0}, 0), ({"t": None}, 2)],
    "an int, then a float (truncated as Gymnasium casts it)": [({"k": 1}, 0), ({"k": 2.7}, 1)],
    "float32 first, python and numpy floats after": [
        ({"f": np.float32(0.1)}, 0),
        ({"f": 0.1}, 1),
        ({"f": np.float64(1 / 3)}, 2),
    ],
    "arrays of another dtype or shape": [
        ({"v": np.zeros(3, np.float32)}, 0),
        ({"v": np.ones(3, np.float64)}, 1),
        ({"v": np.ones(3, np.float32)}, 2),
    ],
    "same-step autoreset: final_obs and final_info, then the reset's info": [
        ({"final_obs": np.ones(2), "final_info": {"r": 1.0, "task": {"d": 0.3}}}, 1),
        ({"r": 0.0, "task": {"d": 0.7}}, 1),
        ({"r": 0.5, "task": {"d": 0.1}}, 2),
    ],
    "same-step autoreset of world 1 while world 0 goes on": [
        ({"r": 0.5, "task": {"d": 0.1}}, 0),
        ({"final_obs": np.ones(2), "final_info": {"r": 1.0, "task": {"d": 0.3}}}, 1),
        ({"r": 0.0, "task": {"d": 0.7}}, 1),
    ],
    "keys that are not strings": [({0: 1.0, "a": {1: "x"}}, 0), ({0: 2.0, "a": {1: "y"}}, 1)],
    "a world given twice under one key": [({"a": 1.0}, 0), ({"a": 2.0}, 0)],
    "a key beginning with an underscore": [({"a": 1.0, "_b": 2.0}, 0), ({"b": 3.0}, 1)],
}


def _masks(info: dict) -> list[np.ndarray]:
    """Every ``_key`` mask of a vector info, nested ones included."""
    out = []
    for key, value in info.items():
        if isinstance(value, dict):
            out += _masks(value)
        elif isinstance(key, str) and key.startswith("_"):
            out.append(value)
    return out


LEFT_TO_GYMNASIUM = {
    "keys that are not strings",
    "a world given twice under one key",
    "a key beginning with an underscore",
}
"""The cases the one-pass merge hands to Gymnasium's pair-by-pair fold; every other case must
be merged without it."""


def _no_fold(*_):
    raise AssertionError("the one-pass merge fell back to Gymnasium's fold")


@pytest.mark.parametrize("name", CASES)
def test_merge_equals_gymnasium_s(name):
    got, expected = _both(CASES[name])
    assert_same(got, expected, name)
    masks = _masks(got)
    assert len({id(mask) for mask in masks}) == len(masks)  # each key its own mask, as there
    if name not in LEFT_TO_GYMNASIUM:
        assert_same(merge_infos(CASES[name], N, _no_fold), expected, name)
    else:
        with pytest.raises(AssertionError, match="fell back"):
            merge_infos(CASES[name], N, _no_fold)


def test_a_value_gymnasium_cannot_cast_fails_as_there():
    """NaN into an int batch array: Gymnasium's element-wise cast raises; one cast of the lot
    would write an arbitrary integer instead."""
    entries = [({"k": 1}, 0), ({"k": float("nan")}, 1)]
    with pytest.raises(ValueError):
        _both(entries)  # Gymnasium's
    with pytest.raises(ValueError):
        merge_infos(entries, N, _Gymnasium()._add_info)


def test_no_worlds_give_an_empty_info():
    assert merge_infos([], N, _Gymnasium()._add_info) == {}


def test_a_dict_beside_a_scalar_under_one_key_is_left_to_gymnasium():
    calls = []

    def add(vector_infos, info, world):
        calls.append(world)
        return vector_infos

    merge_infos([({"a": 1.0}, 0), ({"a": {"x": 1.0}}, 1)], N, add)
    assert calls == [0, 1]
