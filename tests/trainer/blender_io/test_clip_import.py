"""Clip import through Blender's FBX and BVH importers: round trips, bone maps, bad clips, manifests, cache."""
import json
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from rlanimate_addon.core import kinematics, rotations, skeleton, spaces  # noqa: E402
from rlanimate_addon.core.errors import RLAnimateError  # noqa: E402
from trainer.blender_io import clip_import, import_worker, rig_session  # noqa: E402
from trainer.motion import clip_cache  # noqa: E402
from trainer.paths import SAMPLE_RIG_BLEND, SAMPLE_RIG_FBX  # noqa: E402

FRAMES = 16
FINGER = "LeftHandMiddle2"


def smooth_motion(rng):
    """(F, 15, 3) action rotations and (F, 3) of one finger: a smooth random gesture from rest."""
    t = np.linspace(0.0, 1.0, FRAMES)[:, None, None]
    rotvecs = np.sin(np.pi * t) * rng.normal(0.0, 0.5, (1, len(skeleton.ACTION_JOINTS), 3))
    finger = np.sin(np.pi * t[:, 0]) * np.array([0.9, 0.0, 0.2])
    return rotvecs, finger


def key_rig(rig, rotvecs, finger):
    for frame in range(FRAMES):
        for k, joint in enumerate(skeleton.ACTION_JOINTS):
            bone = rig.pose.bones[skeleton.PREFIX + joint]
            bone.rotation_quaternion = rotations.rotvec_to_quat(rotvecs[frame, k])
            bone.keyframe_insert("rotation_quaternion", frame=frame + 1)
        bone = rig.pose.bones[skeleton.PREFIX + FINGER]
        bone.rotation_quaternion = rotations.rotvec_to_quat(finger[frame])
        bone.keyframe_insert("rotation_quaternion", frame=frame + 1)


def export_fbx(path, objects="ARMATURE MESH"):
    bpy.ops.export_scene.fbx(filepath=str(path), object_types=set(objects.split()), add_leaf_bones=False,
                             bake_anim=True, bake_anim_use_all_actions=False, bake_anim_use_nla_strips=False,
                             bake_anim_simplify_factor=0.0, axis_forward="-Z", axis_up="Y",
                             primary_bone_axis="Y", secondary_bone_axis="X")


def export_bvh(rig, path):
    bpy.context.view_layer.objects.active = rig
    rig.select_set(True)
    bpy.ops.export_anim.bvh(filepath=str(path), frame_start=1, frame_end=FRAMES)


def rig_missing_forearms(scene):
    """An animated armature with the canonical bones except both forearms."""
    data = bpy.data.armatures.new("NoForearms")
    rig = bpy.data.objects.new("NoForearms", data)
    scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    for bone in skeleton.BONES:
        if "ForeArm" in bone.name:
            continue
        edit = data.edit_bones.new(skeleton.PREFIX + bone.name)
        edit.head, edit.tail = bone.head, bone.tail
        parent = bone.parent
        while parent is not None and "ForeArm" in parent:
            parent = skeleton.BONE_BY_NAME[parent].parent
        if parent is not None:
            edit.parent = data.edit_bones[skeleton.PREFIX + parent]
    bpy.ops.object.mode_set(mode="OBJECT")
    for frame, angle in ((1, 0.0), (5, 0.5)):
        rig.pose.bones[skeleton.PREFIX + "Spine"].rotation_mode = "XYZ"
        rig.pose.bones[skeleton.PREFIX + "Spine"].rotation_euler = (angle, 0.0, 0.0)
        rig.pose.bones[skeleton.PREFIX + "Spine"].keyframe_insert("rotation_euler", frame=frame)
    return rig


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """Exported test clips: {name: path}, and the motion keyed into the good ones."""
    folder = tmp_path_factory.mktemp("clips")
    rotvecs, finger = smooth_motion(np.random.default_rng(0))
    scene = rig_session.new_empty_scene()
    scene.render.fps, scene.render.fps_base = 30, 1.0
    scene.frame_start, scene.frame_end = 1, FRAMES
    rig = rig_session.load_rig(SAMPLE_RIG_BLEND, with_mesh=True)
    key_rig(rig, rotvecs, finger)
    files = {"fbx": folder / "good.fbx", "bvh": folder / "good.bvh"}
    export_fbx(files["fbx"])
    export_bvh(rig, files["bvh"])
    # Without a skinned mesh an FBX has no bind pose: Blender's importer takes the pose at export time
    # (here mid-gesture) as the rest, as for the sample clip library.
    scene.frame_set(FRAMES // 2)
    files["fbx_armature_only"] = folder / "armature_only.fbx"
    export_fbx(files["fbx_armature_only"], objects="ARMATURE")
    scene.frame_set(1)
    for bone in rig.data.bones:  # the same motion, named without the mixamorig: prefix
        bone.name = skeleton.strip_prefix(bone.name)
    files["bvh_unprefixed"] = folder / "unprefixed.bvh"
    export_bvh(rig, files["bvh_unprefixed"])
    scene.render.fps = 24
    files["fps24"] = folder / "fps24.bvh"
    export_bvh(rig, files["fps24"])

    lines = files["bvh"].read_text().splitlines()
    motion = lines.index("MOTION") + 3 + FRAMES // 2  # a frame line in the middle of the clip
    values = lines[motion].split()
    values[7] = "nan"
    lines[motion] = " ".join(values)
    files["nan"] = folder / "nan.bvh"
    files["nan"].write_text("\n".join(lines) + "\n")
    values[7] = "inf"  # an infinite value is called infinite, not NaN
    lines[motion] = " ".join(values)
    files["inf"] = folder / "inf.bvh"
    files["inf"].write_text("\n".join(lines) + "\n")

    files["empty"] = folder / "empty.fbx"
    files["empty"].write_bytes(b"")
    files["garbage"] = folder / "garbage.fbx"
    files["garbage"].write_bytes(b"Kaydara FBX Binary  \x00\x1a\x00" + bytes(range(256)) * 4)
    files["truncated"] = folder / "truncated.fbx"
    files["truncated"].write_bytes(files["fbx"].read_bytes()[:5000])
    files["garbled_bvh"] = folder / "garbled.bvh"  # the hierarchy cut inside a joint
    files["garbled_bvh"].write_text("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition "
                                    "Zposition Zrotation Xrotation Yrotation\n JOINT Spine {\nMOTION\n")
    files["no_animation"] = SAMPLE_RIG_FBX  # the sample character: a rig with no action

    scene = rig_session.new_empty_scene()
    scene.render.fps = 30
    rig_missing_forearms(scene)
    files["missing"] = folder / "missing.bvh"
    export_bvh(bpy.data.objects["NoForearms"], files["missing"])
    rig_session.new_empty_scene()
    return files, rotvecs, finger


def joint_positions(rotvecs):
    """(F, B, 3) canonical bone heads (numpy FK) for action rotations (F, 15, 3)."""
    return kinematics.head_positions(kinematics.pose_matrices(
        {joint: rotvecs[:, k] for k, joint in enumerate(skeleton.ACTION_JOINTS)}))


@pytest.mark.parametrize("kind", ["fbx", "fbx_armature_only", "bvh", "bvh_unprefixed"])
def test_export_import_round_trip_reproduces_joint_positions_within_a_millimetre(library, kind):
    files, rotvecs, finger = library
    clip = clip_import.import_clip(files[kind])
    assert clip.rotvecs.shape == (FRAMES, 15, 3)
    assert clip.fps == pytest.approx(30.0, abs=1e-3)
    error = np.abs(joint_positions(clip.rotvecs) - joint_positions(rotvecs)).max()
    assert error < 1e-3
    assert np.abs(joint_positions(rotvecs)[-FRAMES // 2] - joint_positions(rotvecs)[0]).max() > 0.05  # it moves
    np.testing.assert_allclose(clip.fingers[FINGER], finger, atol=1e-4)


def test_import_leaves_the_scene_as_it_was(library):
    files, _, _ = library
    scene = rig_session.new_empty_scene()
    scene.render.fps = 25
    clip_import.import_clip(files["fbx"], expected_fps=30)
    assert len(bpy.data.objects) == 0 and len(bpy.data.actions) == 0 and len(bpy.data.armatures) == 0
    assert scene.render.fps == 25


@pytest.mark.parametrize("kind, message", [
    ("empty", "empty"),
    ("garbage", "corrupt"),
    ("truncated", "corrupt"),
    ("garbled_bvh", r"not a valid BVH file \(IndexError: list index out of range\)\. Re-export it"),
    ("no_animation", "no animation"),
    ("missing", "lacks the bones LeftForeArm, RightForeArm"),
    ("nan", "NaN values in the motion data"),
    ("inf", r": infinite values in the motion data at frames \[\d+\]\. Fix"),
    ("fps24", "runs at 24 fps, but 30 fps is expected"),
])
def test_bad_clips_raise_an_error_naming_the_file_and_the_problem(library, kind, message):
    files, _, _ = library
    with pytest.raises(RLAnimateError, match=message) as error:
        clip_import.import_clip(files[kind])
    assert str(files[kind]) in str(error.value)
    assert "Location:" not in str(error.value) and "Traceback" not in str(error.value)


@pytest.mark.parametrize("verbose", [False, True])
def test_the_fbx_importers_own_traceback_is_held_back_unless_verbose(library, capfd, verbose):
    files, _, _ = library
    with rig_session.blender_output(verbose):
        with pytest.raises(RLAnimateError, match="the file is corrupt or not a valid FBX file"):
            clip_import.import_clip(files["garbage"])
    shown = capfd.readouterr().err
    assert ("Traceback" in shown and "import_fbx.py" in shown) == verbose


def test_manifest_entries_are_checked_before_any_clip_is_imported(library, tmp_path, monkeypatch):
    files, _, _ = library
    manifest, _ = write_manifest(tmp_path, files)
    data = json.loads(manifest.read_text())
    data["clips"][0]["frames"] = "abc"
    data["clips"].append("wave_right_000.bvh")  # an entry that is a string
    manifest.write_text(json.dumps(data))
    imported = count_imports(monkeypatch)
    clips, problems = clip_import.import_clip_directory(manifest, cache_dir=False)
    assert imported == ["wave_right_000.bvh", "point_right_001.fbx"], "the bad entries are never imported"
    assert [c.name for c in clips] == ["wave_right_000"]
    assert problems[:2] == [
        f"{manifest}: entry 1 ('point_left_000.fbx'): field 'frames' is 'abc'; give the clip's frame count as a "
        "whole number of at least 2, or leave it out. The entry is skipped.",
        f"{manifest}: entry 4: the entry is 'wave_right_000.bvh', not an object; write it as "
        '{"file": "clip.fbx", "behaviour": "POINT", "arm": "LEFT", ...} (docs/CLIPS.md). The entry is skipped.']
    assert "point_right_001.fbx: the file is corrupt" in problems[2]
    assert json.loads(manifest.read_text()) == data, "the manifest is left as it was"


@pytest.mark.parametrize("where", ["entry", "top_level"])
def test_a_clip_at_another_frame_rate_than_its_manifest_gives_blames_the_manifest_too(library, tmp_path, where):
    files, _, _ = library
    shutil.copy(files["bvh"], tmp_path / "wave_right_000.bvh")  # a 30 fps clip
    entry = {"file": "wave_right_000.bvh", "behaviour": "WAVE", "arm": "RIGHT", "exaggeration": 0.3}
    manifest = {"fps": 24, "clips": [entry]} if where == "top_level" else {"clips": [dict(entry, fps=24)]}
    (tmp_path / "manifest.json").write_text(json.dumps(manifest))
    clips, (problem,) = clip_import.import_clip_directory(tmp_path / "manifest.json", cache_dir=False)
    field = "the manifest's field 'fps'" if where == "top_level" else "the entry's field 'fps'"
    assert clips == [] and problem == (
        f"{tmp_path / 'manifest.json'}: entry 1 ('wave_right_000.bvh'): the clip {tmp_path / 'wave_right_000.bvh'} "
        f"runs at 30 fps, but {field} says 24. Correct the manifest if the clip is right, or re-export the clip at "
        "24 fps.")


def test_directory_import_reports_each_bad_file_and_keeps_the_good_ones(library, tmp_path):
    files, _, _ = library
    for kind in ("fbx", "bvh", "empty", "garbage", "nan"):
        shutil.copy(files[kind], tmp_path / files[kind].name)
    clips, problems = clip_import.import_clip_directory(tmp_path, cache_dir=False)
    assert sorted(c.name for c in clips) == ["good", "good"]
    assert len(problems) == 3
    for name in ("empty.fbx", "garbage.fbx", "nan.bvh"):
        assert sum(name in p for p in problems) == 1


def write_manifest(folder, files):
    shutil.copy(files["fbx"], folder / "point_left_000.fbx")
    shutil.copy(files["bvh"], folder / "wave_right_000.bvh")
    shutil.copy(files["garbage"], folder / "point_right_001.fbx")
    target = [0.8, -1.5, 1.6]
    manifest = {"fps": 30, "rig": "../character.fbx", "clips": [
        {"file": "point_left_000.fbx", "behaviour": "POINT", "arm": "LEFT", "target": target, "direction": None,
         "exaggeration": None, "frames": FRAMES, "fps": 30, "split": "train"},
        {"file": "wave_right_000.bvh", "behaviour": "WAVE", "arm": "RIGHT", "target": None, "direction": None,
         "exaggeration": 0.35, "frames": FRAMES, "fps": 30, "split": "test"},
        {"file": "point_right_001.fbx", "behaviour": "POINT", "arm": "RIGHT", "target": target,
         "direction": None, "exaggeration": None, "frames": FRAMES, "fps": 30, "split": "train"},
    ]}
    path = folder / "manifest.json"
    path.write_text(json.dumps(manifest))
    return path, target


def test_load_clip_set_attaches_the_manifest_labels_and_split(library, tmp_path):
    files, rotvecs, _ = library
    manifest, target = write_manifest(tmp_path, files)
    clip_set = clip_import.load_clip_set(manifest)
    assert [c.name for c in clip_set.train] == ["point_left_000"]
    assert [c.name for c in clip_set.test] == ["wave_right_000"]
    assert len(clip_set.problems) == 1 and "point_right_001.fbx" in clip_set.problems[0]
    point, wave = clip_set.train[0], clip_set.test[0]
    assert (point.behaviour, point.arm, wave.behaviour, wave.arm) == ("POINT", "LEFT", "WAVE", "RIGHT")
    np.testing.assert_allclose(point.attributes, spaces.pointing_direction("LEFT", target))
    assert wave.attributes == wave.exaggeration == 0.35
    objective = spaces.PAPER_SPACE.make_objective(point.behaviour, point.arm, point.attributes, point.frames)
    assert objective.shape == (FRAMES, spaces.PAPER_SPACE.size)


def count_imports(monkeypatch):
    """A list that collects the name of every file clip_import really imports (not from its cache): in this
    process (import_clip) or in its import workers (a library's clips)."""
    imported = []
    real_import, real_workers = clip_import._import_uncached, import_worker.import_into_cache

    def counting_import(path, *args):
        imported.append(path.name)
        return real_import(path, *args)

    def counting_workers(files, *args, **kwargs):
        imported.extend(Path(path).name for path, _ in files)
        return real_workers(files, *args, **kwargs)

    monkeypatch.setattr(clip_import, "_import_uncached", counting_import)
    monkeypatch.setattr(import_worker, "import_into_cache", counting_workers)
    return imported


def test_imported_clips_are_cached_and_reused_without_reimporting(library, tmp_path, monkeypatch):
    files, _, _ = library
    manifest, _ = write_manifest(tmp_path, files)
    first = clip_import.load_clip_set(manifest)
    cached = sorted((tmp_path / clip_cache.CACHE_DIR_NAME).glob("*.npz"))
    assert len(cached) == 2  # the two good files; the bad one is not cached

    imported = count_imports(monkeypatch)
    second = clip_import.load_clip_set(manifest)
    assert imported == ["point_right_001.fbx"]  # only the bad file, which has no cache entry
    for a, b in zip(first.clips, second.clips, strict=True):
        np.testing.assert_array_equal(a.rotvecs, b.rotvecs)
        assert a.fingers.keys() == b.fingers.keys()
        assert (a.behaviour, a.split) == (b.behaviour, b.split)


def test_a_manifest_whose_frame_count_disagrees_with_the_file_is_reported(library, tmp_path):
    files, _, _ = library
    manifest, _ = write_manifest(tmp_path, files)
    data = json.loads(manifest.read_text())
    data["clips"][0]["frames"] = FRAMES + 3
    manifest.write_text(json.dumps(data))
    clips, problems = clip_import.import_clip_directory(manifest, cache_dir=False)
    assert [c.name for c in clips] == ["wave_right_000"]
    assert any(f"entry 1 ('point_left_000.fbx'): the manifest's field 'frames' says {FRAMES + 3}, but the clip" in p
               and f"has {FRAMES} frames. Correct 'frames' in the manifest" in p for p in problems)


def test_a_changed_skeleton_does_not_reuse_clips_cached_for_the_old_one(library, tmp_path, monkeypatch):
    files, _, _ = library
    clip_import.import_clip(files["fbx"], cache_dir=tmp_path)
    moved = tuple(b._replace(head=(0.06, -0.03, 1.44)) if b.name == "LeftShoulder" else b for b in skeleton.BONES)
    monkeypatch.setattr(skeleton, "BONES", moved)
    imported = count_imports(monkeypatch)
    clip_import.import_clip(files["fbx"], cache_dir=tmp_path)
    assert imported == [files["fbx"].name], "a clip cached for other rest frames must be imported again"
    assert len(list(tmp_path.glob("*.npz"))) == 2


def rezipped(entry, member, change):
    """Rewrite the zip `entry` with `change(bytes)` applied to its `member`, with valid checksums (as a tool
    that rewrites the archive, not a flipped bit, would leave it)."""
    with zipfile.ZipFile(entry) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    members[member] = change(members[member])
    with zipfile.ZipFile(entry, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)


#: Changes to one array of a cache entry, each written as a valid archive: the entry is not the clip.
ARRAY_DAMAGE = {
    "wrong_shape": ("rotvecs", lambda a: a[:, :4]),
    "nan": ("rotvecs", lambda a: a * np.nan),
    "integer_rotations": ("rotvecs", lambda a: np.round(a).astype(np.int64)),  # was read as another clip
    "fps_of_two_values": ("fps", lambda a: np.array([30.0, 30.0])),  # was a TypeError
    "finger_names_numbers": ("finger_names", lambda a: np.arange(len(a))),
    "unknown_finger_bone": ("finger_names", lambda a: np.array(["Tail"] * len(a))),
}


#: Changes to the text of rotvecs.npy's header (its shape's bracket left open, a quote lost).
HEADER_DAMAGE = {"npy_header_unclosed": (b"), }", b"  }"), "npy_header_quote": (b"'descr'", b"'descr ")}


@pytest.mark.parametrize("damage", ["truncated", "garbage", *HEADER_DAMAGE, *ARRAY_DAMAGE])
def test_a_damaged_cache_entry_is_imported_again_and_rewritten(library, tmp_path, monkeypatch, capsys, damage):
    files, _, _ = library
    first = clip_import.import_clip(files["fbx"], cache_dir=tmp_path)
    (entry,) = tmp_path.glob("*.npz")
    good = entry.read_bytes()
    if damage == "truncated":
        entry.write_bytes(good[:len(good) // 2])
    elif damage == "garbage":
        entry.write_bytes(b"not an archive at all")
    elif damage in HEADER_DAMAGE:  # the npy header's text: "unclosed" was a TokenError on every run
        old, new = HEADER_DAMAGE[damage]
        rezipped(entry, "rotvecs.npy", lambda data: data.replace(old, new, 1))
    else:
        with np.load(entry) as data:
            arrays = dict(data)
        name, change = ARRAY_DAMAGE[damage]
        arrays[name] = change(arrays[name])
        np.savez(entry, **arrays)
    imported = count_imports(monkeypatch)
    again = clip_import.import_clip(files["fbx"], cache_dir=tmp_path)
    assert imported == [files["fbx"].name], "the damaged entry is imported again"
    assert f"The import cache entry {entry} is damaged" in capsys.readouterr().err
    np.testing.assert_array_equal(again.rotvecs, first.rotvecs)
    assert entry.read_bytes() == good, "and rewritten"
    imported.clear()
    clip_import.import_clip(files["fbx"], cache_dir=tmp_path)
    assert imported == [], "the rewritten entry is used"


def test_a_clip_folder_without_a_manifest_is_named_with_what_training_needs(library, tmp_path):
    files, _, _ = library
    shutil.copy(files["fbx"], tmp_path / "point_left_000.fbx")
    with pytest.raises(RLAnimateError, match=rf"The folder {tmp_path} has 1 FBX/BVH clips but no manifest\.json, "
                                             r"and training needs each clip's labels"):
        clip_import.load_clip_set(tmp_path / "manifest.json")
    with pytest.raises(RLAnimateError, match=rf"{tmp_path / 'elsewhere'} does not exist"):
        clip_import.load_clip_set(tmp_path / "elsewhere")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["point_left_000.fbx"], "nothing was written"


def test_two_entries_of_one_file_keep_their_own_labels(library, tmp_path):
    files, _, _ = library
    manifest, _ = write_manifest(tmp_path, files)
    data = json.loads(manifest.read_text())
    data["clips"].append(dict(data["clips"][0], behaviour="JUMP", split="test"))  # the same file again
    manifest.write_text(json.dumps(data))
    clips, _ = clip_import.import_clip_directory(manifest, cache_dir=False)
    assert [(c.name, c.behaviour, c.split) for c in clips] == [
        ("point_left_000", "POINT", "train"), ("wave_right_000", "WAVE", "test"), ("point_left_000", "JUMP", "test")]
