"""Rate and acceleration of the FASM margin from its recent history (inputs of eq. 15).

Zhang et al. 2024 §4.2 needs the margin's rate v_s [deg/s] and acceleration a_s [deg/s²] at the
moment the
robot is judged to be tipping. The margin is measured once per control period and carries sensor
noise, so both are taken from a least-squares quadratic S(τ) ≈ c0 + c1 τ + c2 τ² fitted to the
samples of the last `window` seconds (τ = sample time - newest time): v_s = c1, a_s = 2 c2.
With fewer than five samples a straight line is fitted (a_s = 0); with fewer than two both are 0.
"""

from __future__ import annotations

from collections import deque

import numpy as np


class MarginHistory:
    """Sliding window of (time [s], margin [deg]) samples with a quadratic-fit derivative."""

    def __init__(self, window: float = 0.4, max_samples: int = 400):
        if not window > 0.0:
            raise ValueError(f"window must be > 0 s, got {window}")
        self.window = float(window)
        self._t: deque[float] = deque(maxlen=max_samples)
        self._s: deque[float] = deque(maxlen=max_samples)

    def clear(self) -> None:
        self._t.clear()
        self._s.clear()

    def __len__(self) -> int:
        return len(self._t)

    @property
    def margins(self) -> np.ndarray:
        """The margins [deg] in the window, oldest first."""
        return np.asarray(self._s)

    def add(self, time: float, margin_deg: float) -> None:
        """Append a sample; samples older than the window are dropped."""
        if self._t and time <= self._t[-1]:
            raise ValueError(f"sample times must increase, got {time} after {self._t[-1]}")
        self._t.append(float(time))
        self._s.append(float(margin_deg))
        while self._t and self._t[0] < time - self.window - 1e-12:
            self._t.popleft()
            self._s.popleft()

    def rate_and_acceleration(self) -> tuple[float, float]:
        """(v_s [deg/s], a_s [deg/s²]) at the newest sample."""
        n = len(self._t)
        if n < 2:
            return 0.0, 0.0
        tau = np.asarray(self._t) - self._t[-1]
        s = np.asarray(self._s)
        degree = 2 if n >= 5 else 1
        coeffs = np.polynomial.polynomial.polyfit(tau, s, degree)
        rate = float(coeffs[1])
        accel = float(2.0 * coeffs[2]) if degree == 2 else 0.0
        return rate, accel
