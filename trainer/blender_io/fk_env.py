"""The forward-kinematics environment: Blender poses the rig and reports the real description d'_t.

The rig is loaded into the current bpy session and copied into `instances` armature objects that
share one armature datablock and each hold their own pose. A batch of P poses is evaluated
`instances` at a time: bulk-write every instance's quaternions, tag it, run one view-layer
(depsgraph) update, bulk-read every instance's pose-bone matrices. Results are in the character
frame: the armature's object space with its scale removed, in metres.

Runs the same under `blender -b -P` and under `python` with the bpy module.
"""
from collections import namedtuple

import numpy as np

from rlanimate_addon.core import rotations, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError

from trainer.blender_io import rig_session

#: descriptions (P, 42), joint_positions (P, 10, 3) of skeleton.DESCRIPTION_JOINTS, bone_heads
#: (P, n_bones, 3) in FKEnvironment.bone_names order; all in the character frame, metres.
FKResult = namedtuple("FKResult", "descriptions joint_positions bone_heads")

_COLLECTION_NAME = "RLAnimate_FK_instances"


class FKEnvironment:
    """Blender as a batched FK function from local joint rotations to descriptions and joint positions."""

    def __init__(self, rig_path=rig_session.SAMPLE_RIG_BLEND, instances=8):
        """Load the rig at `rig_path` (.blend or .fbx) and make `instances` armature objects of it.

        8 instances measured fastest on one core (docs/BENCHMARKS.md, "FK environment"): each depsgraph
        update pays a cost per armature object in the scene, so more instances are slower per pose.
        """
        if int(instances) < 1:
            raise RLAnimateError(f"FKEnvironment needs at least 1 instance, got {instances}.")
        self._bpy = rig_session.import_bpy()
        self.rig = rig_session.load_rig(rig_path)
        self.rig.animation_data_clear()  # an action would override the poses we write
        _reset_pose(self.rig)
        self._bpy.context.view_layer.update()  # matrix_world is stale until the depsgraph runs
        self.scale = float(np.mean(self.rig.matrix_world.to_scale()))  # object units -> metres
        rig_names = [skeleton.strip_prefix(b.name) for b in self.rig.data.bones]
        #: Bone names (prefix stripped), the order of bone_heads: skeleton.BONE_NAMES order, then any
        #: bones the canonical skeleton lacks in the rig's order.
        self.bone_names = tuple([n for n in skeleton.BONE_NAMES if n in rig_names]
                                + [n for n in rig_names if n not in skeleton.BONE_BY_NAME])
        self._bone_index = {name: i for i, name in enumerate(self.bone_names)}
        pose_names = [skeleton.strip_prefix(b.name) for b in self.rig.pose.bones]
        self._pose_index = {name: k for k, name in enumerate(pose_names)}  # pose bones are in hierarchy order
        self._pose_to_bone = np.array([self._bone_index[name] for name in pose_names])
        self._action_slots = np.array([self._pose_index[j] for j in skeleton.ACTION_JOINTS])
        self._collection = self._bpy.data.collections.new(_COLLECTION_NAME)
        self._bpy.context.scene.collection.children.link(self._collection)
        self.objects = [self.rig] + [self._instance(k) for k in range(1, int(instances))]
        self._matrices = np.zeros(len(pose_names) * 16, dtype=np.float32)

    @property
    def instances(self):
        return len(self.objects)

    def _instance(self, k):
        obj = self.rig.copy()  # shares the armature data; the pose is per object
        obj.name = f"{self.rig.name}_fk{k:03d}"
        self._collection.objects.link(obj)
        return obj

    def evaluate(self, action_rotvecs, extra_rotvecs=None):
        """FKResult for P poses.

        action_rotvecs: (P, 15, 3) local rotation vectors of skeleton.ACTION_JOINTS, relative to rest.
        extra_rotvecs: optional {bone name: (P, 3)} for other bones (e.g. fingers); the rest stay at rest.
        """
        rotvecs = self._checked(action_rotvecs, extra_rotvecs)  # (P, B, 3) pose-bone order
        count = len(rotvecs)
        quats = rotations.rotvec_to_quat(rotvecs).astype(np.float32)  # (P, B, 4)
        bone_count = len(self.bone_names)
        heads = np.empty((count, bone_count, 3))
        eye_axes = {eye: np.empty((count, 3)) for eye in ("LeftEye", "RightEye")}
        eye_slots = {eye: self._bone_index[eye] for eye in eye_axes}
        for start in range(0, count, self.instances):
            batch = self.objects[:min(self.instances, count - start)]
            for obj, pose_quats in zip(batch, quats[start:start + len(batch)]):
                obj.pose.bones.foreach_set("rotation_quaternion", pose_quats.ravel())
                obj.update_tag(refresh={"DATA"})  # foreach_set does not tag the pose for evaluation
            self._bpy.context.view_layer.update()
            for offset, obj in enumerate(batch):
                obj.pose.bones.foreach_get("matrix", self._matrices)
                # Blender hands matrices over column-major: transpose to (B, 4, 4) row-major.
                pose = np.empty((bone_count, 4, 4))
                pose[self._pose_to_bone] = self._matrices.reshape(-1, 4, 4).transpose(0, 2, 1)
                heads[start + offset] = pose[:, :3, 3] * self.scale
                for eye, slot in eye_slots.items():
                    eye_axes[eye][start + offset] = pose[slot, :3, 1]
        positions = {name: heads[:, i] for i, name in enumerate(self.bone_names)}
        descriptions = spaces.describe(positions, eye_axes)
        return FKResult(descriptions, spaces.description_joint_positions(descriptions), heads)

    def describe_actions(self, actions01, bounds=spaces.DEFAULT_ACTION_BOUNDS):
        """FKResult for (P, 45) actions in [0, 1], decoded with `bounds` (45, 2) by spaces.decode_action."""
        actions = np.asarray(actions01, dtype=np.float64)
        if actions.ndim != 2 or actions.shape[1] != spaces.ACTION_SIZE:
            raise RLAnimateError(f"Actions must have shape (P, {spaces.ACTION_SIZE}), got {actions.shape}.")
        return self.evaluate(spaces.decode_action(actions, bounds))

    def _checked(self, action_rotvecs, extra_rotvecs):
        """Validate the inputs and return (P, B, 3) rotation vectors in pose-bone order."""
        actions = np.asarray(action_rotvecs, dtype=np.float64)
        joints = len(skeleton.ACTION_JOINTS)
        if actions.ndim != 3 or actions.shape[1:] != (joints, 3):
            raise RLAnimateError(f"Action rotations must have shape (P, {joints}, 3), got {actions.shape}.")
        if not np.all(np.isfinite(actions)):
            raise RLAnimateError("Action rotations contain NaN or infinity: check the agent's output.")
        rotvecs = np.zeros((len(actions), len(self._pose_index), 3))
        rotvecs[:, self._action_slots] = actions
        for name, values in (extra_rotvecs or {}).items():
            bone = skeleton.strip_prefix(name)
            if bone not in self._pose_index:
                raise RLAnimateError(f"The rig has no bone {name!r}: use names of skeleton.BONES.")
            values = np.asarray(values, dtype=np.float64)
            if values.shape != (len(actions), 3):
                raise RLAnimateError(f"Rotations of {name!r} must have shape ({len(actions)}, 3), "
                                     f"got {values.shape}.")
            if not np.all(np.isfinite(values)):
                raise RLAnimateError(f"Rotations of {name!r} contain NaN or infinity.")
            rotvecs[:, self._pose_index[bone]] = values
        return rotvecs


def _reset_pose(rig):
    """Quaternion rotation mode and rest location and scale on every pose bone, so that only the
    quaternions evaluate() writes move the rig."""
    bones = rig.pose.bones
    for bone in bones:
        bone.rotation_mode = "QUATERNION"
    bones.foreach_set("location", np.zeros(3 * len(bones), dtype=np.float32))
    bones.foreach_set("scale", np.ones(3 * len(bones), dtype=np.float32))
