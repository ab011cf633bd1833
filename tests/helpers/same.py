"""Bit-identical comparison of what envs and vector envs return."""

from __future__ import annotations

import numpy as np


def assert_same(a, b, where: str) -> None:
    """Bit-identical values: arrays (NaN equal to NaN; dtype and shape too), dicts (the keys in
    order), sequences, scalars (type too)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), where  # the keys in order
        for key in a:
            assert_same(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        if a.dtype == object:
            for k, (x, y) in enumerate(zip(a, b, strict=True)):
                assert_same(x, y, f"{where}[{k}]")
        else:
            assert np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), where
    elif isinstance(a, list | tuple):
        assert type(a) is type(b) and len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{where}[{k}]")
    elif isinstance(a, float) and np.isnan(a):
        assert isinstance(b, float) and np.isnan(b), where
    else:
        assert a == b and type(a) is type(b), where
