"""Compiled helpers shared by the kernels of several packages (private; numba).

The envs' per-step measurements (`hexapod_envs.envs._compiled`) and the UPU robot's
(`hexapod_envs.robots.upu._compiled`) both sum the actuator power in numpy's order, so that the
compiled step gives the same bits as the numpy code it replaced; the one copy of that sum lives
here, below both.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def numpy_sum(a):
    """Sum of the 1-D float array ``a`` in the order of numpy's ``a.sum()`` (its pairwise sum:
    eight interleaved partial sums for 8-128 values, a plain loop below 8)."""
    n = a.shape[0]
    if n < 8:
        total = 0.0
        for i in range(n):
            total += a[i]
        return total
    if n > 128:  # numpy splits longer arrays recursively; not needed here
        raise ValueError("numpy_sum takes at most 128 values")
    r = a[:8].copy()
    i = 8
    while i < n - n % 8:
        for j in range(8):
            r[j] += a[i + j]
        i += 8
    total = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < n:
        total += a[i]
        i += 1
    return 0.0 + total


@njit(cache=True)
def actuator_power(force, velocity):
    """Σ |F v| [W] over the actuators, as numpy's ``np.abs(force * velocity).sum()``."""
    return numpy_sum(np.abs(force * velocity))
