"""Real time at any frame rate: a gesture lasts the same seconds and waves at the same Hz at 24, 30
and 60 fps (core/frame_rate.py), measured on the hand as Blender plays it."""
import bpy
import numpy as np

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
