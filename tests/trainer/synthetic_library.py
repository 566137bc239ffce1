"""A tiny synthetic clip library for trainer tests: smooth point and wave clips on the canonical rig,
labelled like the clip importer's clips, with a train/test split."""
from types import SimpleNamespace

import numpy as np

from rlanimate_addon.core import skeleton, spaces
from trainer.motion.clip import MotionClip

_ARM_JOINT = {arm: skeleton.ACTION_JOINTS.index(skeleton.ARM_PREFIX[arm] + "Arm") for arm in skeleton.ARMS}
_FOREARM_JOINT = {arm: skeleton.ACTION_JOINTS.index(skeleton.ARM_PREFIX[arm] + "ForeArm") for arm in skeleton.ARMS}


def _bell(frames):
    """(F,) 0 -> 1 -> 0 minimum-jerk rise, hold and return."""
    s = np.clip(np.linspace(0.0, 3.0, frames), 0.0, 3.0)
    rise = np.clip(s, 0, 1)
    fall = np.clip(s - 2, 0, 1)
    jerk = lambda x: 10 * x**3 - 15 * x**4 + 6 * x**5  # noqa: E731
    return jerk(rise) - jerk(fall)


def make_clip(name, behaviour, arm, value, frames, frequency=2.5):
    """A clip pointing at `value` (a target (3,) in the character frame) or waving with exaggeration `value`
    at `frequency` Hz."""
    side = 1.0 if arm == "LEFT" else -1.0
    envelope = _bell(frames)[:, None]  # (F, 1)
    rotvecs = np.zeros((frames, len(skeleton.ACTION_JOINTS), 3))
    if behaviour == "POINT":
        attributes = spaces.pointing_direction(arm, value)
        rotvecs[:, _ARM_JOINT[arm]] = envelope * np.array([0.4 * attributes[2], 0.0, -side * 0.8 * attributes[1]])
    else:
        attributes = float(value)
        t = np.arange(frames) / 30.0
        rotvecs[:, _ARM_JOINT[arm]] = envelope * np.array([0.0, 0.0, side * (0.6 + 0.4 * value)])
        rotvecs[:, _FOREARM_JOINT[arm], 2] = envelope[:, 0] * (0.3 + 0.3 * value) * np.sin(2 * np.pi * frequency * t)
    return MotionClip(name=name, source=name, fps=30.0, rotvecs=rotvecs, behaviour=behaviour, arm=arm,
                      attributes=attributes)


def make_library(seed=0, per_behaviour=4):
    """SimpleNamespace(train=[...], test=[...]): `per_behaviour` training clips of each behaviour and
    one held-out clip per behaviour and arm, 36 to 54 frames long."""
    rng = np.random.default_rng(seed)

    def clip(k, behaviour, arm):
        frames = int(rng.integers(36, 55))
        value = (np.array([rng.uniform(-1, 1), -2.0, rng.uniform(1.0, 2.0)]) if behaviour == "POINT"
                 else rng.uniform(0, 1))
        return make_clip(f"{behaviour.lower()}_{arm.lower()}_{k}", behaviour, arm, value, frames)

    train = [clip(k, b, skeleton.ARMS[k % 2]) for b in spaces.PAPER_SPACE.names for k in range(per_behaviour)]
    test = [clip(100 + k, b, arm) for b in spaces.PAPER_SPACE.names for k, arm in enumerate(skeleton.ARMS)]
    return SimpleNamespace(train=train, test=test)
