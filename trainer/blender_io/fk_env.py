"""The forward-kinematics environment: Blender poses the rig and reports the real description d'_t.

The rig is loaded into the current bpy session and copied into `instances` armature objects that
share one armature datablock and each hold their own pose. A batch of P poses is evaluated
`instances` at a time: bulk-write every instance's quaternions, tag it, run one view-layer
(depsgraph) update, bulk-read every instance's pose-bone matrices. Results are in the character
frame: the armature's object space with its scale removed, in metres.

Runs the same under `blender -b -P` and under `python` with the bpy module. Its interface, input
checks and results are trainer/motion/fk.py's, which also holds the numpy environment.
"""
import numpy as np

from rlanimate_addon.core import rotations, skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io import rig_session
from trainer.motion.fk import FKEnvironmentBase
from trainer.paths import SAMPLE_RIG_BLEND

_COLLECTION_NAME = "RLAnimate_FK_instances"


class FKEnvironment(FKEnvironmentBase):
    """Blender as a batched FK function from local joint rotations to descriptions and joint positions."""

    def __init__(self, rig_path=SAMPLE_RIG_BLEND, instances=8):
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
        self._pose_names = tuple(skeleton.strip_prefix(b.name) for b in self.rig.pose.bones)  # hierarchy order
        self._pose_to_bone = np.array([self._bone_index[name] for name in self._pose_names])
        self._collection = self._bpy.data.collections.new(_COLLECTION_NAME)
        self._bpy.context.scene.collection.children.link(self._collection)
        self.objects = [self.rig] + [self._instance(k) for k in range(1, int(instances))]
        self._matrices = np.zeros(len(self._pose_names) * 16, dtype=np.float32)

    @property
    def instances(self):
        return len(self.objects)

    def _instance(self, k):
        obj = self.rig.copy()  # shares the armature data; the pose is per object
        obj.name = f"{self.rig.name}_fk{k:03d}"
        self._collection.objects.link(obj)
        return obj

    def _pose(self, rotvecs):
        """(P, B, 3) rotation vectors in pose-bone order -> bone heads (P, n_bones, 3), eye Y axes {eye: (P, 3)}."""
        count = len(rotvecs)
        quats = rotations.rotvec_to_quat(rotvecs).astype(np.float32)  # (P, B, 4)
        bone_count = len(self.bone_names)
        heads = np.empty((count, bone_count, 3))
        eye_axes = {eye: np.empty((count, 3)) for eye in ("LeftEye", "RightEye")}
        eye_slots = {eye: self._bone_index[eye] for eye in eye_axes}
        for start in range(0, count, self.instances):
            batch = self.objects[:min(self.instances, count - start)]
            for obj, pose_quats in zip(batch, quats[start:start + len(batch)], strict=True):
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
        return heads, eye_axes


def _reset_pose(rig):
    """Quaternion rotation mode and rest location and scale on every pose bone, so that only the
    quaternions evaluate() writes move the rig."""
    bones = rig.pose.bones
    for bone in bones:
        bone.rotation_mode = "QUATERNION"
    bones.foreach_set("location", np.zeros(3 * len(bones), dtype=np.float32))
    bones.foreach_set("scale", np.ones(3 * len(bones), dtype=np.float32))
