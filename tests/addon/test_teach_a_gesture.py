"""docs/TRAINING.md, "Teach it a new gesture", end to end: a folder of FBX clips of a gesture the agent has
never had (RAISE_HAND: the hand raised ahead, higher with more exaggeration, made with the clip generator
and exported as the sample library's clips are), a manifest naming it beside a few point and wave clips,
`trainer/train.py` on the debug preset, the agent chosen in Preferences, the new behaviour in the panel,
and Generate: the bake check passes and the deformed hand moves."""
import json
import shutil

import pytest

pytest.importorskip("torch", reason="trains an agent: needs the trainer's torch (the LTS environments have none)")

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import addon_helpers  # noqa: E402
import real_rigs  # noqa: E402
from rlanimate_addon.blender import gestures, properties  # noqa: E402
from rlanimate_addon.core import agent_file, skeleton  # noqa: E402
from test_registration import _draw  # noqa: E402
from trainer.blender_io import rig_session  # noqa: E402
from trainer.blender_io.clip_bake import bake_clip, export_fbx  # noqa: E402
from trainer.motion.synthesis import FPS, GestureSpec, synthesise  # noqa: E402
from trainer.paths import CLIP_DIR, DEFAULT_MANIFEST  # noqa: E402
from trainer.scripts import train  # noqa: E402

#: The new gesture's clips: (arm, exaggeration), a few of each arm.
RAISES = [("LEFT", 0.0), ("LEFT", 0.5), ("LEFT", 1.0), ("RIGHT", 0.2), ("RIGHT", 0.7), ("RIGHT", 1.0)]
#: Sample-library clips trained beside them (their manifest entries as they are).
SAMPLES = ("point_left_000.fbx", "point_right_001.fbx", "wave_left_000.fbx", "wave_right_001.fbx")


def raised_hand_target(arm, exaggeration):
    """Where the raised hand reaches: ahead and out to its side, from chest height (0) to overhead (1)."""
    elevation = np.radians(10.0 + 65.0 * exaggeration)
    outward = 1.0 if arm == "LEFT" else -1.0  # +X is the character's left
    direction = np.array([0.35 * outward, -np.cos(elevation), np.sin(elevation)])
    return skeleton.shoulder_rest_position(arm) + 2.0 * direction / np.linalg.norm(direction)


def write_gesture_library(folder):
    """The new gesture's FBX clips and the sample clips in `folder`, with a manifest naming them."""
    bpy_module = rig_session.import_bpy()
    rig_session.new_empty_scene()
    rig = rig_session.load_rig()
    entries = []
    for k, (arm, exaggeration) in enumerate(RAISES):
        clip = synthesise(GestureSpec("POINT", arm, target=tuple(raised_hand_target(arm, exaggeration)), seed=k))
        name = f"raise_hand_{arm.lower()}_{k:03d}.fbx"
        action = bake_clip(rig, clip, name)
        export_fbx(bpy_module, rig, folder / name, clip.frames)
        rig.animation_data.action = None
        bpy_module.data.actions.remove(action)
        entries.append({"file": name, "behaviour": "raise_hand", "arm": arm, "exaggeration": exaggeration,
                        "frames": clip.frames})
    sample = {entry["file"]: entry for entry in json.loads(DEFAULT_MANIFEST.read_text())["clips"]}
    for name in SAMPLES:
        shutil.copy(CLIP_DIR / name, folder / name)
        entries.append({**sample[name], "split": "train"})
    (folder / "manifest.json").write_text(json.dumps({"fps": FPS, "clips": entries}, indent=1))


def test_a_new_gesture_from_fbx_clips_trains_and_bakes_from_the_panel(tmp_path):
    clips, run = tmp_path / "clips", tmp_path / "run"
    clips.mkdir()
    write_gesture_library(clips)
    assert (
        train.main(
            [
                "trainer/train.py",
                "--clips",
                str(clips),
                "--output",
                str(run),
                "--preset",
                "debug",
                "--epochs",
                "2",
                "--eval-every",
                "0",
                "--quiet",
            ]
        )
        == 0
    )
    _, metadata = agent_file.load_agent_file(run / "agent.npz")
    assert metadata["behaviours"] == [{"name": "POINT", "kind": "target"}, {"name": "WAVE", "kind": "intensity"},
                                      {"name": "RAISE_HAND", "kind": "intensity"}]
    assert set(metadata["average_frames"]) == {"POINT", "WAVE", "RAISE_HAND"}

    settings = addon_helpers.enable_addon()
    try:
        bundled = [item[0] for item in properties.behaviour_items(settings, bpy.context)]
        assert bundled[:2] == ["POINT", "WAVE"], "the bundled agent's, before the new one is chosen"
        addon_helpers.addon_preferences().agent_path = str(run / "agent.npz")
        items = properties.behaviour_items(settings, bpy.context)
        assert [(item[0], item[1]) for item in items] == [("POINT", "Point"), ("WAVE", "Wave"),
                                                          ("RAISE_HAND", "Raise Hand")]
        settings.behaviour = "RAISE_HAND"
        shown = {call[2] for call in _draw(settings) if call[0] == "prop"}
        assert "exaggeration" in shown and "target" not in shown
        rig = addon_helpers.load_sample_rig()
        assert real_rigs.measured_bones_deform(rig, settings, "RIGHT")
        start, count = 1, 90
        # Generate runs the bake check: it undoes and refuses a bake whose deformed hand does not play it.
        assert addon_helpers.generate(rig, settings, arm="RIGHT", exaggeration=0.8, start_frame=start,
                                      frame_count=count) == {"FINISHED"}
        placed = gestures.placed_gestures(rig)[0]
        assert (placed.record["behaviour"], placed.record["kind"]) == ("RAISE_HAND", "intensity")
        assert placed.action.name.startswith("RLAnimate Raise Hand Right")
        travel = real_rigs.wrist_travel(*real_rigs.played_joints(rig, settings, "RIGHT", start, count))
        assert travel > 0.1, f"the deformed hand moves ({travel:.2f} arm lengths)"
    finally:
        addon_helpers.disable_addon()
