"""Procedural IK, the baseline an animator builds by hand: Blender's IK constraint on the sample rig.

Point: the index finger's IK chain (Index1, Hand, ForeArm, Arm) reaches for a target 2.5 m along the
requested direction, so the arm and finger line up with it; the constraint's influence is keyed
0 -> 1 -> 0 with minimum-jerk ease (stroke, hold, return), which is a per-joint slerp between the start
pose and the solved pose. Wave: the hand's IK chain (Hand, ForeArm, Arm) follows a target that rises
with minimum-jerk timing and swings side to side at 2.5 Hz; the raise (70 + 90 e degrees from hanging)
and the swing (0.05 + 0.35 e arm lengths each way) scale with the exaggeration e, the same scale
trainer/motion/autolabel.py measures. Each frame is one depsgraph evaluation of the constrained rig, and
the constraint's influence follows the raise, so the clip starts and ends in the neutral pose `neutral`
(15, 3). It answers generate() like the other methods (trainer/evaluation/baselines.py).
"""
import numpy as np

from rlanimate_addon.core import frame_rate, rotations, skeleton, spaces
from rlanimate_addon.core.easing import minimum_jerk
from rlanimate_addon.core.gesture import slerp
from trainer.blender_io import rig_session
from trainer.motion import autolabel
from trainer.paths import SAMPLE_RIG_BLEND

#: Where the IK target sits along the requested pointing direction, metres from the rest shoulder.
POINT_TARGET_DISTANCE = 2.5
#: Pointing timing as fractions of the clip: stroke from..to, hold until, return until.
POINT_TIMING = (0.12, 0.38, 0.72, 0.92)
#: Waving timing: raise from..to, lower from..to, as fractions of the clip; swing frequency in Hz.
WAVE_TIMING = (0.08, 0.3, 0.72, 0.94)
WAVE_FREQUENCY = 2.5
#: Wave shape: elevation of shoulder->hand from hanging (degrees) and side-to-side swing (arm lengths).
WAVE_ELEVATION = (70.0, 90.0)  # at e = 0, added at e = 1
WAVE_SWING = (0.05, 0.35)
WAVE_REACH = 0.8  # shoulder->hand distance at the raise, in arm lengths (the elbow stays bent)


def _blend(start, end, weights):
    """Per-joint slerp from pose `start` (15, 3) to pose(s) `end` ((15, 3) or (F, 15, 3)) by (F,) weights."""
    end = np.broadcast_to(end, (len(weights),) + np.shape(start))
    q0 = np.broadcast_to(rotations.rotvec_to_quat(start), end.shape[:-1] + (4,))
    w = np.broadcast_to(np.asarray(weights)[:, None], end.shape[:-1])
    return rotations.quat_to_rotvec(slerp(q0, rotations.rotvec_to_quat(end), w))


def envelope(frame_count, rise_start, rise_end, fall_start, fall_end):
    """(F,) 0 -> 1 -> 0 with minimum-jerk rise and fall; the arguments are fractions of the clip."""
    s = np.linspace(0.0, 1.0, int(frame_count))
    rise = minimum_jerk((s - rise_start) / (rise_end - rise_start))
    fall = minimum_jerk((s - fall_start) / (fall_end - fall_start))
    return rise * (1.0 - fall)


class ProceduralIK:
    """IK-constraint gestures on the sample rig, loaded into the current bpy session beside anything
    already there (such as the FK environment's rigs)."""

    def __init__(self, neutral, rig_path=SAMPLE_RIG_BLEND):
        self.neutral = np.asarray(neutral, dtype=np.float64)  # (15, 3)
        self._bpy = rig_session.import_bpy()
        self.rig = rig_session.load_rig(rig_path)
        self.rig.animation_data_clear()
        self.rig.name = "RLAnimate_ProceduralIK"
        self.target = self._bpy.data.objects.new("RLAnimate_ProceduralIK_target", None)
        self._bpy.context.scene.collection.objects.link(self.target)
        self._bpy.context.view_layer.update()
        self.scale = float(np.mean(self.rig.matrix_world.to_scale()))  # object units -> metres
        self._pose_bones = {skeleton.strip_prefix(b.name): b for b in self.rig.pose.bones}
        bones = {skeleton.strip_prefix(b.name): b for b in self.rig.data.bones}
        self._rest = {n: np.asarray(b.matrix_local, dtype=np.float64)[:3, :3] for n, b in bones.items()}
        self._parent = {n: (skeleton.strip_prefix(b.parent.name) if b.parent else None) for n, b in bones.items()}
        self._constraint = None

    def _constrain(self, bone, chain_count):
        if self._constraint is not None:
            self._constraint[0].constraints.remove(self._constraint[1])
        pose_bone = self._pose_bones[bone]
        constraint = pose_bone.constraints.new("IK")
        constraint.target = self.target
        constraint.chain_count = chain_count
        constraint.use_tail = True
        constraint.use_stretch = False
        self._constraint = (pose_bone, constraint)

    def _set_pose(self, rotvecs):
        for joint, rotvec in zip(skeleton.ACTION_JOINTS, rotvecs, strict=True):
            bone = self._pose_bones[joint]
            bone.rotation_mode = "QUATERNION"
            bone.rotation_quaternion = rotations.rotvec_to_quat(rotvec)

    def _solve(self, target_position):
        """(15, 3) local rotations of the constrained pose with the IK target at `target_position` (3,),
        character frame in metres, starting from the neutral pose."""
        local = np.append(np.asarray(target_position) / self.scale, 1.0)  # object space, homogeneous
        world = np.asarray(self.rig.matrix_world, dtype=np.float64) @ local
        self.target.location = world[:3]
        self._bpy.context.view_layer.update()
        pose = {n: np.asarray(b.matrix, dtype=np.float64)[:3, :3] for n, b in self._pose_bones.items()}
        local = []
        for joint in skeleton.ACTION_JOINTS:
            parent = self._parent[joint]
            bind = pose[parent] @ self._rest[parent].T @ self._rest[joint]
            local.append(rotations.matrix_to_rotvec(bind.T @ pose[joint]))
        return np.stack(local)

    def generate(self, behaviour, arm, attributes, frame_count, tempo=None):
        """A wave swings at `tempo` (Hz; None: WAVE_FREQUENCY)."""
        spaces.PAPER_SPACE.check_request(behaviour, arm, frame_count)
        self._set_pose(self.neutral)
        side = skeleton.ARM_PREFIX[arm]
        if spaces.PAPER_SPACE.behaviour(behaviour).aims:
            direction = np.asarray(attributes, dtype=np.float64)
            direction = direction / np.linalg.norm(direction)
            self._constrain(side + "HandIndex1", 4)
            solved = self._solve(skeleton.shoulder_rest_position(arm) + POINT_TARGET_DISTANCE * direction)
            return _blend(self.neutral, solved, envelope(frame_count, *POINT_TIMING))
        exaggeration = float(np.ravel(attributes)[0])
        self._constrain(side + "Hand", 3)
        solved = np.stack([self._solve(p) for p in self.wave_targets(arm, exaggeration, frame_count, tempo)])
        return _blend(self.neutral, solved, envelope(frame_count, *WAVE_TIMING))

    def wave_targets(self, arm, exaggeration, frame_count, tempo=None):
        """(F, 3) hand targets of a wave swinging at `tempo` Hz (None: WAVE_FREQUENCY), character frame in
        metres."""
        side = skeleton.ARM_PREFIX[arm]
        sign = 1.0 if arm == "LEFT" else -1.0
        shoulder = skeleton.shoulder_rest_position(arm)
        length = autolabel.arm_length(side)
        raised = envelope(frame_count, *WAVE_TIMING)  # (F,)
        hang = shoulder + np.array([0.05 * sign, -0.05, -0.9 * length])
        elevation = np.radians(WAVE_ELEVATION[0] + WAVE_ELEVATION[1] * exaggeration)
        up = shoulder + WAVE_REACH * length * np.array([sign * np.sin(elevation) * 0.7,
                                                        -np.sin(elevation) * 0.7, -np.cos(elevation)])
        t = np.arange(frame_count) / frame_rate.AGENT_FPS
        frequency = WAVE_FREQUENCY if tempo is None else tempo
        swing = (WAVE_SWING[0] + WAVE_SWING[1] * exaggeration) * length * np.sin(2 * np.pi * frequency * t)
        positions = hang + raised[:, None] * (up - hang)  # (F, 3)
        positions[:, 0] += raised**2 * swing  # side to side, only once the arm is up
        return positions
