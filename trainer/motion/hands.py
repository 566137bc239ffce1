"""The hand put on a capture without fingers: the synthesised clips' relaxed hand (numpy)."""
import functools
from dataclasses import replace

import numpy as np

from rlanimate_addon.core import skeleton
from trainer.motion.clip import MotionClip
from trainer.motion.synthesis import FINGER_BONES, neutral_pose


@functools.cache
def _relaxed_hand() -> dict[str, np.ndarray]:
    """{finger bone: (3,) rotation vector} of the synthesised neutral pose's relaxed hands."""
    return {name: rotvec for name, rotvec in neutral_pose().items() if name in FINGER_BONES}


def relaxed_hand(clip: MotionClip) -> MotionClip:
    """`clip` with the synthesised clips' relaxed hand (synthesis.neutral_pose) on both sides, for a capture
    without fingers: Index1 in its rotvecs, the other finger bones in .fingers."""
    rotvecs = np.array(clip.rotvecs, dtype=np.float64)
    fingers = dict(clip.fingers)
    for name, rotvec in _relaxed_hand().items():
        if name in skeleton.ACTION_JOINTS:
            rotvecs[:, skeleton.ACTION_JOINTS.index(name)] = rotvec
        else:
            fingers[name] = np.tile(rotvec, (len(rotvecs), 1))
    return replace(clip, rotvecs=rotvecs, fingers=fingers)


def with_hand(clip: MotionClip) -> MotionClip:
    """`clip` as it is when its source has finger bones, else with the relaxed hand (a capture without fingers,
    such as the Bandai Namco takes: its index base would otherwise hang straight from the wrist)."""
    return clip if clip.fingers else relaxed_hand(clip)
