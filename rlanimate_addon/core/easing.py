"""Easing curves shared by the gesture generator, the baselines and aim correction."""
import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike


def minimum_jerk(s: ArrayLike) -> npt.NDArray[np.float64]:
    """Minimum-jerk progress 10s^3 - 15s^4 + 6s^5 on s in [0, 1] (clipped): bell-shaped speed, zero
    velocity and acceleration at both ends."""
    t = np.clip(np.asarray(s, dtype=np.float64), 0.0, 1.0)
    return t**3 * (10.0 - 15.0 * t + 6.0 * t * t)
