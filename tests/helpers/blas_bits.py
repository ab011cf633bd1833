"""Whether numba's ``np.dot`` (scipy's BLAS) gives numpy's ``@`` bits on this machine.

The compiled kernels (agents.tipping._compiled, hexapod_envs.envs._compiled) form their small
matrix products with ``np.dot`` so that they reproduce numpy's results exactly; that holds
where the two BLAS builds agree, as they do on the machines the committed results come from.
Tests that compare kernels with numpy bit for bit skip themselves where they do not.
"""

import functools

import numpy as np
from numba import njit


@njit(cache=True)
def _dot(a, b):
    return np.dot(a, b)


@functools.cache
def numba_blas_matches_numpy() -> bool:
    """True when 200 random products of the kernels' shapes (6 x 12 by 12 x 6 and by 12, 12 x 6
    by 6, 6 x 3 by 3 x 3 and by its transpose, 3 x 3 by 3) are the same to the bit. The
    transposes are passed as the kernels pass them, as transposed views: a contiguous copy
    would take BLAS's other gemv kernel, whose sums differ."""
    rng = np.random.default_rng(0)
    for _ in range(200):
        a, b = rng.normal(size=(6, 12)), rng.normal(size=(3, 3))
        e, y, f = rng.normal(size=12), rng.normal(size=6), rng.normal(size=(6, 3))
        pairs = [(a, a.T), (a, e), (a.T, y), (f, b), (f, b.T), (b, f[0])]
        for left, right in pairs:
            if _dot(left, right).tobytes() != (left @ right).tobytes():
                return False
    return True


REASON = "numba's BLAS (scipy's) and numpy's differ in the last bit on this machine"
