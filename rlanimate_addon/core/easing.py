"""Easing curves shared by the gesture generator, the baselines and aim correction."""
import numpy as np
from numpy.typing import ArrayLike


def minimum_jerk(s: ArrayLike) -> np.ndarray:
    """Minimum-jerk progress 10s^3 - 15s^4 + 6s^5 on s in [0, 1] (clipped): bell-shaped speed, zero
    velocity and acceleration at both ends."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s * s)
