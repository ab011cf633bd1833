"""The episode's safety figures and the benchmark's rules on them (`SafetyFigures`)."""

from __future__ import annotations

import math

__all__ = ["SafetyFigures"]


class SafetyFigures:
    """The safety figures of an episode and the benchmark's rules on them, a part of
    `HexapodEnv` (which supplies ``settings``, ``sensors``, ``_fasm_deg``, ``_step_count``,
    ``_margin_steps_to_tip`` and `_is_tipping`): the body tilt and its maximum, the steps on
    which the stability criterion failed, the run of steps at FASM <= 0; the tip-over by a lost
    margin (`_margin_lost`) and the success rule's safety part (`_stayed_stable`)."""

    def _start_safety(self) -> None:
        """The figures at the start of an episode (after its first measurement)."""
        self._read_posture()
        self._max_tilt_deg = self._tilt_deg
        self._tipping_steps = 0
        self._steps_at_zero_margin = 0

    def _track_safety(self) -> None:
        """Update the episode's safety figures after a step's measurement: the tilt and its
        maximum, the steps on which the stability criterion failed, the run of steps at FASM
        <= 0."""
        self._read_posture()
        self._max_tilt_deg = max(self._max_tilt_deg, self._tilt_deg)
        self._tipping_steps += self._tipping
        self._steps_at_zero_margin = self._steps_at_zero_margin + 1 if self._fasm_deg <= 0 else 0

    def _read_posture(self) -> None:
        """The step's tilt (``_tilt_cos_now``, ``_tilt_deg``) and stability criterion
        (``_tipping``), read once: the tip-over test and the info use them."""
        self._tilt_cos_now = self._tilt_cos()
        self._tilt_deg = math.degrees(math.acos(min(1.0, max(-1.0, self._tilt_cos_now))))
        self._tipping = bool(self._is_tipping())

    @property
    def _tipping_share(self) -> float:
        """Share of the episode's steps so far on which the stability criterion failed."""
        return self._tipping_steps / max(self._step_count, 1)

    def _margin_lost(self) -> bool:
        """The FASM has stayed at or below 0 for ``tip_over_margin_time`` (if set)."""
        n = self._margin_steps_to_tip
        return n is not None and self._steps_at_zero_margin >= n

    def _stayed_stable(self) -> bool:
        """The success rule's safety part: the episode's max tilt and share of time tipping
        within ``success_max_tilt_deg`` and ``success_max_tipping_share`` (each if set)."""
        s = self.settings
        if s.success_max_tilt_deg is not None and self._max_tilt_deg > s.success_max_tilt_deg:
            return False
        limit = s.success_max_tipping_share
        return limit is None or self._tipping_share <= limit

    def _tilt_cos(self) -> float:
        """cos of the angle between the body's up axis and the vertical (an env whose robot
        stands on a moving support measures it from the support's up axis)."""
        return self.sensors.tilt_cos()
