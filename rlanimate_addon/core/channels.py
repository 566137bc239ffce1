"""The values to key for a bone's rotation: in its own rotation mode, for an NLA Replace or Combine layer.

Blender's NLA Combine blends each channel by its kind: quaternions multiply
(result = below @ key), Euler and axis-angle channels add (result = below + key). So a Combine layer
keys the difference from the rotation underneath, and a Replace layer the rotation itself.
"""
import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from .rotations import (  # noqa: F401
    continuous,
    matrix_to_euler,
    matrix_to_quat,
    quat_multiply,
    quat_to_axis_angle,
    quat_to_matrix,
)

MODES = ("QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
BLEND_TYPES = ("REPLACE", "COMBINE")


def rotation_keys(mode: str, keyed: ArrayLike, below: ArrayLike, below_values: ArrayLike,
                  blend_type: str) -> npt.NDArray[np.float64]:
    """(N, C) values for a bone's rotation channels: 4 for QUATERNION and AXIS_ANGLE, 3 for Euler orders.

    keyed: (N, 4) the rotation the bone must have; below: (N, 4) the rotation underneath, and
    below_values: (N, C) its channel values as the animation underneath has them (the first frame's
    fix the Euler turn count, so the keys continue the animation's angles rather than jump by 2 pi).
    """
    keyed, below = np.asarray(keyed, dtype=np.float64), np.asarray(below, dtype=np.float64)
    below_values = np.asarray(below_values, dtype=np.float64)
    if mode == "QUATERNION":
        if blend_type == "COMBINE":
            inverse = below * np.array([1.0, -1.0, -1.0, -1.0])
            return continuous(quat_multiply(inverse, keyed))
        aligned = np.where(np.sum(keyed[:1] * below_values[:1]) < 0.0, -keyed, keyed)
        return continuous(aligned)
    if mode == "AXIS_ANGLE":
        start = np.where(np.sum(keyed[:1] * below[:1]) < 0.0, -keyed, keyed)
        values = quat_to_axis_angle(continuous(start))
    else:
        # Euler continuity from the animation's own angles at the first frame on.
        values = matrix_to_euler(quat_to_matrix(keyed), mode, previous=below_values[0])
    return values - below_values if blend_type == "COMBINE" else values
