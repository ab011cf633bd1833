"""The observation layout: named pieces in one flat vector (`ObservationLayout`), written by
readers or by groups (`PieceGroup`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

import numpy as np

__all__ = ["ObservationLayout", "PieceGroup", "Reader"]

Reader = Callable[[], Any]
"""Returns one observation piece's current value (an array, a float or a tuple of floats)."""


class PieceGroup(NamedTuple):
    """Consecutive observation pieces written by one call (e.g. a compiled one): `sizes` is
    name -> size in order, `write(out)` fills `out`, the group's slice of the observation."""

    sizes: Mapping[str, int]
    write: Callable[[np.ndarray], Any]


class ObservationLayout:
    """Named pieces laid out in one flat vector, in order: name -> (size, reader), or a
    `PieceGroup` under a label (its pieces take the group's place).

    The layout is the single table of the observation: it gives the slices
    (`observation_structure`, the docs, the policies' readers) and writes the vector, each
    piece by its reader (or each group by its writer), straight into a preallocated buffer
    (`write`).
    """

    def __init__(self, pieces: Mapping[str, tuple[int, Reader] | PieceGroup]):
        self.slices: dict[str, slice] = {}
        self._writers: list[tuple[slice, Callable, bool]] = []
        start = 0
        for name, piece in pieces.items():
            if isinstance(piece, PieceGroup):
                group_start = start
                for member, size in piece.sizes.items():
                    start = self._add_slice(member, start, size)
                self._writers.append((slice(group_start, start), piece.write, True))
            else:
                size, read = piece
                self._writers.append((slice(start, start + size), read, False))
                start = self._add_slice(name, start, size)
        self.size = start

    def _add_slice(self, name: str, start: int, size: int) -> int:
        if name in self.slices:
            raise ValueError(f"observation piece {name!r} appears twice")
        self.slices[name] = slice(start, start + size)
        return start + size

    def write(self, out: np.ndarray) -> np.ndarray:
        """Write every piece's current value into `out` (size `size`) and return it."""
        for sl, write, is_group in self._writers:
            if is_group:
                write(out[sl])
            else:
                out[sl] = write()
        return out

    def unpack(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        return {name: observation[..., sl] for name, sl in self.slices.items()}
