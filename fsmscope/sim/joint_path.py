"""The arm's motion between waypoints: joint positions as a function of simulated time, on a
min-jerk time scale (smooth start and stop, no jerk at either end)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def min_jerk(s: float) -> float:
    s = min(max(s, 0.0), 1.0)
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


@dataclass
class JointPath:
    """Joint waypoints (K x 6) followed over ``duration`` s with a min-jerk time scale."""

    waypoints: np.ndarray
    t0: float
    duration: float

    def at(self, t: float) -> np.ndarray:
        k = len(self.waypoints) - 1
        if k == 0 or self.duration <= 0:
            return self.waypoints[-1]
        x = min_jerk((t - self.t0) / self.duration) * k
        i = min(int(x), k - 1)
        f = x - i
        return self.waypoints[i] * (1.0 - f) + self.waypoints[i + 1] * f

    def end_time(self) -> float:
        return self.t0 + self.duration
