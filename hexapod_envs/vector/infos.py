"""The vector info dict of one vector step, built once from every world's info.

Gymnasium's vector envs merge each world's info into the vector info as the world steps
(`gymnasium.vector.VectorEnv._add_info`): for every key of every world it looks the key up,
allocates the batch array and its ``_key`` mask on first sight and assigns one element. With the
21-32 keys of a hexapod env's info that is a tenth or more of a heavy-duty world's step
(benchmarks/README.md). `merge_infos` builds the same dict (the same keys in the same order, the
same dtypes and values, the same masks) from the list of ``(info, world)`` pairs the step
collected, one batch assignment per key where the worlds' values are alike (a key whose type changes
between worlds is assigned world by world, as Gymnasium does). Where the infos leave what that
reproduces (a dict beside other values under one key, a world listed twice for one key, a key
beginning with ``_``), it merges them pair by pair with Gymnasium's own code.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

__all__ = ["merge_infos"]

Info = dict[str, Any]
AddInfo = Callable[[Info, Info, int], Info]
"""Gymnasium's merge of one world's info: ``add(vector_infos, env_info, world) -> vector_infos``."""

_SCALARS = (int, float, bool)


class _Irregular(Exception):
    """The infos leave the shortcut's assumptions: merge them pair by pair."""


def merge_infos(entries: Sequence[tuple[Info, int]], num_envs: int, add: AddInfo) -> Info:
    """The vector info of `entries` (each world's info with its index, in the order the step
    produced them), equal to folding them with Gymnasium's `add` (its ``_add_info``)."""
    try:
        return _merge(entries, num_envs)
    except _Irregular:
        merged: Info = {}
        for info, world in entries:
            merged = add(merged, info, world)
        return merged


def _merge(entries: Sequence[tuple[Info, int]], num_envs: int) -> Info:
    if not entries:
        return {}
    infos = [info for info, _ in entries]
    worlds = [world for _, world in entries]
    keys = tuple(infos[0])
    if len(set(worlds)) == len(worlds) and all(tuple(info) == keys for info in infos):
        # The usual step: every world gives the same keys in the same order.
        columns = zip(*(info.values() for info in infos), strict=True)
        return _merge_columns(keys, columns, worlds, num_envs)
    merged: Info = {}
    for key in dict.fromkeys(key for info in infos for key in info):
        pairs = [(info[key], world) for info, world in entries if key in info]
        column, key_worlds = zip(*pairs, strict=True)
        if len(set(key_worlds)) != len(key_worlds):
            raise _Irregular  # a world given twice: Gymnasium keeps its later value
        merged.update(_merge_columns((key,), [column], list(key_worlds), num_envs))
    return merged


def _merge_columns(keys, columns, worlds: list[int], num_envs: int) -> Info:
    """The batch array and mask of each key from its column of values (one per world)."""
    merged: Info = {}
    where = slice(None) if worlds == list(range(num_envs)) else np.array(worlds)
    mask = np.zeros(num_envs, dtype=np.bool_)
    mask[where] = True
    for key, column in zip(keys, columns, strict=True):
        if not isinstance(key, str) or key.startswith("_"):
            raise _Irregular  # "_<key>" could collide with another key's mask
        if key == "final_obs":
            array = _objects(column, where, num_envs)
        elif isinstance(column[0], dict):
            if not all(isinstance(value, dict) for value in column):
                raise _Irregular
            array = _merge(list(zip(column, worlds, strict=True)), num_envs)
        else:
            array = _batch(column, where, num_envs)
        merged[key], merged[f"_{key}"] = array, mask.copy()
    return merged


def _batch(column: Sequence, where: slice | np.ndarray, num_envs: int) -> np.ndarray:
    """The batch array of one key: its dtype from the first value, as Gymnasium chooses it, and
    each world's value cast to it as Gymnasium's element-wise assignment casts it."""
    first = column[0]
    kind = type(first)
    kinds = set(map(type, column))
    if any(issubclass(other, dict) for other in kinds):
        raise _Irregular  # Gymnasium would merge it into this key's batch array
    if kind in _SCALARS or issubclass(kind, np.number):
        array = np.zeros(num_envs, dtype=kind)
        # One cast of the lot equals casting each value when they share the first's type, or
        # are all floats (NumPy promotes them to the widest, which holds every one, then rounds
        # once to the dtype); other mixes go one by one rather than through NumPy's promotion.
        alike = len(kinds) == 1 or all(issubclass(other, float | np.floating) for other in kinds)
    elif isinstance(first, np.ndarray):
        array = np.zeros((num_envs, *first.shape), dtype=first.dtype)
        alike = all(issubclass(other, np.ndarray) for other in kinds) and all(
            value.shape == first.shape and value.dtype == first.dtype for value in column
        )
    else:  # an object array holds whatever each world gives
        return _objects(column, where, num_envs)
    if alike:
        array[where] = column
    else:
        for world, value in zip(np.arange(num_envs)[where], column, strict=True):
            array[world] = value
    return array


def _objects(column: Sequence, where: slice | np.ndarray, num_envs: int) -> np.ndarray:
    """An object array with each world's value as it is (None for the worlds without one)."""
    array = np.full(num_envs, None, dtype=object)
    array[where] = np.fromiter(column, dtype=object, count=len(column))
    return array
