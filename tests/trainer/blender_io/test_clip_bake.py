"""Baking synthesised clips and exporting them as FBX: they reimport as the generator made them."""
import json

import numpy as np

from rlanimate_addon.core import kinematics, skeleton
from trainer.blender_io import clip_bake, rig_session
from trainer.motion.library_plan import plan_library
from trainer.motion.synthesis import synthesise
from trainer.paths import CLIP_DIR, DEFAULT_MANIFEST
from trainer.scripts import clip_library


def imported_heads(bpy, path, bones):
    """Armature-space heads (F, len(bones), 3) of every frame of an FBX clip, via Blender's importer."""
    rig_session.new_empty_scene()
    bpy.ops.import_scene.fbx(filepath=str(path), use_anim=True)
    rig = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    start, end = (int(round(v)) for v in rig.animation_data.action.frame_range)
    heads = []
    for frame in range(start, end + 1):
        bpy.context.scene.frame_set(frame)
        heads.append([tuple(rig.pose.bones[skeleton.PREFIX + b].head) for b in bones])
    return np.array(heads)


def test_exported_clip_reimports_within_a_millimetre(tmp_path):
    plan = plan_library()
    bpy = rig_session.import_bpy()
    bones = [b for _, b in skeleton.DESCRIPTION_JOINTS] + ["LeftHandIndex4", "RightHandIndex4", "Head"]
    for planned in (plan[1], plan[75], plan[130], plan[175]):  # point, wave, guide, raise hand
        clip = synthesise(planned.spec)
        rig_session.new_empty_scene()
        rig = rig_session.load_rig()
        clip_bake.bake_clip(rig, clip, "clip")
        path = tmp_path / planned.file
        clip_bake.export_fbx(bpy, rig, path, clip.frames)
        heads = imported_heads(bpy, path, bones)
        expected = kinematics.head_positions(kinematics.pose_matrices(clip.rotvecs))
        expected = expected[:, [kinematics.bone_index(b) for b in bones]]
        assert heads.shape == expected.shape
        assert np.abs(heads - expected).max() < 1e-3


def test_the_command_regenerates_a_committed_clip_identically(tmp_path):
    name = "wave_right_006.fbx"
    clip_library.main(["clip_library", "--out", str(tmp_path), "--only", name])
    fresh = json.loads((tmp_path / "manifest.json").read_text())["clips"]
    committed = [e for e in json.loads(DEFAULT_MANIFEST.read_text())["clips"] if e["file"] == name]
    assert fresh == committed
    bpy = rig_session.import_bpy()
    bones = [b for _, b in skeleton.DESCRIPTION_JOINTS]
    np.testing.assert_allclose(imported_heads(bpy, tmp_path / name, bones),
                               imported_heads(bpy, CLIP_DIR / name, bones), atol=1e-6)
