"""Real time at any frame rate: a gesture lasts the same seconds and waves at the same Hz at 24, 30
and 60 fps (core/frame_rate.py), measured on the hand as Blender plays it."""
import bpy
import numpy as np
import pytest

from addon_helpers import bone_heads, generate, load_sample_rig, rig_bone
from rlanimate_addon.core import behaviour_metrics, skeleton


def _played_wave(rig, settings, fps):
    """(frames, wave measures) of the default-length Wave baked and played at `fps`."""
    bpy.context.scene.render.fps, bpy.context.scene.render.fps_base = fps, 1.0
    if rig.animation_data is not None:
        for action in {rig.animation_data.action} | {s.action for t in rig.animation_data.nla_tracks for s in t.strips}:
            if action is not None:
                bpy.data.actions.remove(action)
        rig.animation_data_clear()
    count = settings.frame_count
    assert generate(rig, settings, behaviour="WAVE", arm="RIGHT", start_frame=1, exaggeration=0.6) == {"FINISHED"}
    bones = [rig_bone(rig, bone) for _, bone in skeleton.DESCRIPTION_JOINTS]
    positions = bone_heads(rig, bones, range(1, count + 1))  # (F, 10, 3), metres, the character frame
    return count, behaviour_metrics.wave_measures(positions, "RIGHT", fps)


def test_a_wave_lasts_the_same_seconds_and_swings_at_the_same_hz_at_24_30_and_60_fps(settings):
    rig = load_sample_rig()
    played = {fps: _played_wave(rig, settings, fps) for fps in (24, 30, 60)}
    count, at_30 = played[30]
    assert at_30["strokes"] >= 3 and at_30["frequency"] > 0.5, f"the 30 fps wave does not wave: {at_30}"
    for fps, (frames, measures) in played.items():
        assert abs((frames - 1) / fps - (count - 1) / 30) <= 1.0 / fps, \
            f"{frames} frames at {fps} fps last {(frames - 1) / fps:.2f} s, at 30 fps {(count - 1) / 30:.2f} s"
        assert np.isclose(measures["frequency"], at_30["frequency"], rtol=0.05), \
            f"{fps} fps waves at {measures['frequency']:.2f} Hz, 30 fps at {at_30['frequency']:.2f} Hz"


def test_a_wave_swings_at_the_tempo_asked_as_blender_plays_it_and_an_unlearned_tempo_is_refused(settings):
    rig = load_sample_rig()
    played = {}
    for tempo in (0.0, 1.8, 3.0):
        settings.tempo = tempo
        frames, played[tempo] = _played_wave(rig, settings, 30)
    own = played[0.0]["frequency"]
    for tempo in (1.8, 3.0):
        assert played[tempo]["strokes"] >= 3, f"at {tempo} Hz the wave does not wave: {played[tempo]}"
        assert np.isclose(played[tempo]["frequency"], tempo, rtol=0.1), \
            f"asked {tempo} Hz, the hand swings at {played[tempo]['frequency']:.2f} Hz (its own tempo: {own:.2f} Hz)"
    actions = sorted(a.name for a in bpy.data.actions)
    settings.tempo = 8.0
    with pytest.raises(RuntimeError, match=r"A tempo of 8\.00 Hz is outside what this agent learned: set Tempo "
                                           r"between \d\.\d\d and \d\.\d\d Hz, or to 0"):
        bpy.ops.rlanimate.generate_gesture()
    assert sorted(a.name for a in bpy.data.actions) == actions
