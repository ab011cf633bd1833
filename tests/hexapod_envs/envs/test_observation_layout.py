"""ObservationLayout: pieces and piece groups laid out in one vector."""

import numpy as np
import pytest

from hexapod_envs.envs.observation import ObservationLayout, PieceGroup


def _group_writer(out):
    out[:] = np.arange(10.0, 10.0 + len(out))


def test_a_group_takes_its_place_among_the_pieces():
    layout = ObservationLayout(
        {
            "clock": (1, lambda: 7.0),
            "sensors": PieceGroup({"a": 2, "b": 3}, _group_writer),
            "phase": (2, lambda: (0.5, -0.5)),
        }
    )
    assert layout.size == 8
    assert layout.slices == {
        "clock": slice(0, 1),
        "a": slice(1, 3),
        "b": slice(3, 6),
        "phase": slice(6, 8),
    }
    out = layout.write(np.zeros(8))
    np.testing.assert_array_equal(out, [7.0, 10.0, 11.0, 12.0, 13.0, 14.0, 0.5, -0.5])
    assert list(layout.unpack(out)) == ["clock", "a", "b", "phase"]


def test_a_piece_named_twice_is_refused():
    with pytest.raises(ValueError, match="'a' appears twice"):
        ObservationLayout({"a": (1, lambda: 0.0), "g": PieceGroup({"a": 1}, _group_writer)})
