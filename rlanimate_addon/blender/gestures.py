"""An armature's RLAnimate gestures: found, replaced in place, and recorded for Follow Target.

Each gesture's action carries a record (the custom property RECORD): its behaviour, arm and frames,
the settings it was made from, the rotations underneath its bones where they do not move, where it
aimed, and a hash of its keys. Generate finds the gesture it overlaps (same arm, overlapping frames;
the topmost, the active action first) and bakes the new one into the same action and NLA track:
the animation underneath is untouched, and the same settings give the same keys however many times
Generate runs. Follow Target re-bakes the last Point gesture from its record while its keys still
hash as they were written (`edited_by_hand`).
"""
import contextlib

import bpy
import numpy as np

from ..core.behaviours import KNOWN_KINDS, TARGET
from . import action_adapter, armature_io

#: The custom property of a gesture's action that holds its record.
RECORD = "rlanimate_gesture"


class Placed:
    """A gesture's action where it plays: the active action (track None) or the strip of an NLA track."""

    def __init__(self, obj, target, track=None):
        self.obj, self.target, self.track = obj, target, track

    @property
    def action(self):
        return self.target.action

    @property
    def record(self):
        return self.action[RECORD]


def placed_gestures(obj):
    """The armature's recorded gestures as Placed, topmost first (the active action, then the NLA
    tracks from the top)."""
    data = obj.animation_data
    if data is None:
        return []
    found = []
    active = action_adapter.active_target(obj)
    if active is not None and RECORD in active.action:
        found.append(Placed(obj, active))
    for track in reversed(data.nla_tracks):
        for strip in track.strips:
            if strip.action is not None and RECORD in strip.action:
                found.append(Placed(obj, action_adapter.strip_target(strip), track))
    return found


def overlapping(obj, arm, start, end):
    """The topmost gesture of the armature on the same arm whose frames overlap start-end, or None."""
    return next((g for g in placed_gestures(obj)
                 if g.record["arm"] == arm and g.record["start"] <= end and start <= g.record["end"]), None)


def last_targeted(obj):
    """The armature's topmost gesture of a target behaviour (Point), or None."""
    return next((g for g in placed_gestures(obj)
                 if g.record.get("kind", KNOWN_KINDS.get(g.record["behaviour"])) == TARGET), None)


@contextlib.contextmanager
def detached(gesture, view_layer):
    """While inside, the armature plays without `gesture` (None: nothing changes): an active action is
    unassigned, or its NLA track muted, and the bones that stood still beneath it are put back where
    they stood (and stay there: the gesture replacing it may key fewer bones). The gesture plays again
    on leaving; after an error the pose is as it was, too."""
    if gesture is None:
        yield
        return
    data = gesture.obj.animation_data
    muted = gesture.track.mute if gesture.track is not None else None
    if gesture.track is None:
        data.action = None
    else:
        gesture.track.mute = True
    # A bone nothing else animates keeps the gesture's last pose once it stops playing.
    standing = {}
    for bone, values in gesture.record.get("under", {}).items():
        pose_bone = gesture.obj.pose.bones.get(bone)
        if pose_bone is not None:
            path = armature_io.rotation_path(pose_bone.rotation_mode)
            standing[pose_bone, path] = tuple(getattr(pose_bone, path))
            setattr(pose_bone, path, list(values))
    view_layer.update()
    try:
        yield
    except BaseException:
        for (pose_bone, path), values in standing.items():
            setattr(pose_bone, path, values)
        raise
    finally:
        if gesture.track is None:
            action_adapter.assign(gesture.obj, gesture.target)
        else:
            gesture.track.mute = muted


def replace(gesture, name, start_frame, keys, blend_type, digest=None, properties=None):
    """Bake the keys into the gesture's own action, renamed `name`, where it plays: as the active
    action, or as the one strip of its NLA track from start_frame (armature_io.key_action's keys,
    digest and properties)."""
    gesture.target.clear_fcurves()
    armature_io.key_action(gesture.target, start_frame, keys, digest, properties)
    gesture.action.name = name
    if gesture.track is None:
        gesture.obj.animation_data.action_blend_type = blend_type
        return gesture.action
    for strip in list(gesture.track.strips):
        gesture.track.strips.remove(strip)
    gesture.track.name = name
    action_adapter.fill_track(gesture.track, gesture.target, start_frame, name).blend_type = blend_type
    return gesture.action


class Backup:
    """A gesture about to be replaced, as it is: a copy of its action and where its strip plays, put back
    by `restore` when the bake replacing it is undone (blender/bake_check.py), else `discard`ed. Make
    it before bake_check.BakeUndo records the file, so that undoing the bake keeps the copy."""

    def __init__(self, gesture):
        self.gesture, self.name = gesture, gesture.action.name
        self.copy = gesture.action.copy()
        strip = gesture.track.strips[0] if gesture.track is not None and len(gesture.track.strips) else None
        self.strip = None if strip is None else (int(strip.frame_start), strip.blend_type, strip.extrapolation,
                                                 strip.name, gesture.track.name)

    def restore(self):
        gesture = self.gesture
        replaced = gesture.action
        target = action_adapter.ActionTarget(self.copy, self.copy.slots[0] if action_adapter.LAYERED else None)
        if gesture.track is None:
            action_adapter.assign(gesture.obj, target)
        else:
            for strip in list(gesture.track.strips):
                gesture.track.strips.remove(strip)
            start, blend_type, extrapolation, strip_name, track_name = self.strip
            strip = action_adapter.fill_track(gesture.track, target, start, strip_name)
            strip.blend_type, strip.extrapolation, gesture.track.name = blend_type, extrapolation, track_name
        bpy.data.actions.remove(replaced)
        self.copy.name = self.name

    def discard(self):
        bpy.data.actions.remove(self.copy)


def record(action, settings, kind, start, end, under, aimed_at, keys, influence_before=None, animated=True):
    """Write the action's record: settings (a mapping of Scene.rlanimate's names to values), kind (the
    behaviour's, behaviours.TARGET or INTENSITY), under
    ({bone: channel values} of bones that stand still underneath), aimed_at ((N, 3) armature-space
    targets per frame, or None), keys (the hex KeyDigest of the keys written), influence_before
    ({influence path: {frame: value}} of the constraints it muted, before it muted them, on every frame
    it keyed: constraints.mute), animated (whether it was baked over animation, not on a still rig)."""
    action[RECORD] = {
        "behaviour": settings["behaviour"], "kind": kind, "arm": settings["arm"], "start": int(start),
        "end": int(end),
        "settings": settings, "under": {bone: list(map(float, values)) for bone, values in under.items()},
        "aimed_at": [] if aimed_at is None else np.asarray(aimed_at, dtype=np.float64).ravel().tolist(),
        "keys": keys, "note": "", "animated": bool(animated), "influence_before": [
            {"path": path, "frames": [int(f) for f in prior], "values": [float(v) for v in prior.values()]}
            for path, prior in (influence_before or {}).items()]}


def influence_before(gesture):
    """{influence path: {frame: value}} the gesture's mute overwrote (`record`; none in a record made before
    Generate kept them; a record made before it kept their frames holds values from the gesture's start)."""
    start = gesture.record["start"]
    return {
        item["path"]: dict(
            zip(item.get("frames", range(start, start + len(item["values"]))), item["values"], strict=True)
        )
        for item in gesture.record.get("influence_before", [])
    }


def edited_by_hand(gesture):
    """Whether the gesture's keys changed since Generate wrote them."""
    return action_adapter.read_digest(action_adapter.all_fcurves(gesture.action)).hexdigest() != gesture.record["keys"]


def snapshot(settings):
    """{name: value} of every setting of a Scene.rlanimate group, or of a recorded one Follow Target bakes
    again (a namespace), that has one (the target as the object itself; no target, none)."""
    if not hasattr(settings, "bl_rna"):
        values = vars(settings)
    else:
        values = {p.identifier: getattr(settings, p.identifier) for p in settings.bl_rna.properties
                  if p.identifier != "rna_type"}
    return {name: value for name, value in values.items() if value is not None}
