"""Zero scale on a rig: an armature object, or a bone of the gesture's chain, scaled to zero on some axis
collapses what it carries and has no inverse, so no gesture can be posed or aimed on it. Checked before
Generate writes anything; bpy-free (the caller reads the matrices)."""
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike

from .errors import RLAnimateError

#: Below this, a scale factor (or a singular value of the object's world matrix) counts as zero.
MIN_SCALE = 1e-6


def check_nonzero_scale(rig_name: str, object_matrix: ArrayLike, bone_scales: Mapping[str, ArrayLike]) -> None:
    """RLAnimateError naming the armature object, or the bones, scaled to zero on some axis.

    object_matrix: the armature object's world matrix (4, 4); bone_scales: {bone name: its own pose
    scale (3,)} for the bones the gesture moves and their parents."""
    factors = np.linalg.svd(np.asarray(object_matrix, dtype=np.float64)[:3, :3], compute_uv=False)
    if not (np.all(np.isfinite(factors)) and factors.min() >= MIN_SCALE):
        raise RLAnimateError(f"The armature object {rig_name!r} has zero scale on some axis (world scale factors "
                             f"{', '.join(f'{f:.3g}' for f in factors)}), so its bones cannot be posed: set its scale "
                             "(Object Mode, N panel > Item > Scale, or Alt+S for 1) to non-zero values, and that of "
                             "any object it is parented to, then generate.")
    scales = np.array(list(bone_scales.values()), dtype=np.float64).reshape(len(bone_scales), 3)
    kept = np.all(np.abs(scales) >= MIN_SCALE, axis=1)
    zero = [(name, scale) for name, scale, ok in zip(bone_scales, scales, kept, strict=True) if not ok]
    if zero:
        shown = ", ".join(f"{name!r} {tuple(round(float(v), 3) for v in scale)}" for name, scale in zero[:3])
        raise RLAnimateError(f"Bones of {rig_name!r} are scaled to zero ({shown}), which collapses the bones they "
                             "carry: set their scale to 1 in Pose Mode (Pose > Clear Transform > Scale, or Alt+S), "
                             "or key a non-zero scale, then generate.")
