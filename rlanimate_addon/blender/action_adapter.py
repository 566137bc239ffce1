"""The one place that knows how Blender versions store keyframes.

Blender 4.2 keeps F-curves on the action (`action.fcurves`). Blender 4.4+ (and 5.0, which removed
`action.fcurves`) uses layered actions: an action has slots, one per animated data-block, and its
F-curves live in a channelbag of a keyframe strip of a layer, one channelbag per slot. Callers get
an `ActionTarget` (the action and, where slots exist, the slot) and never touch either layout.
"""
import hashlib
import math

import bpy
import numpy as np

LAYERED = "slots" in bpy.types.Action.bl_rna.properties
#: Blender 5.0's `ChannelbagFCurves.new` takes the channel group's name; 4.4 and 4.5 group the F-curve after.
_NEW_FCURVE_TAKES_GROUP = LAYERED and (
    "group_name" in bpy.types.ActionChannelbagFCurves.bl_rna.functions["new"].parameters)
_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value
_BEZIER = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["BEZIER"].value
_FREE = bpy.types.Keyframe.bl_rna.properties["handle_left_type"].enum_items["FREE"].value


class ActionTarget:
    """An action and the slot whose channels it writes (None before layered actions)."""

    def __init__(self, action, slot=None):
        self.action, self.slot = action, slot
        self._channelbag = None

    def _fcurves(self, create=False):
        if not LAYERED:
            return self.action.fcurves
        if self._channelbag is None:
            self._channelbag = _channelbag(self.action, self.slot, create)
        return None if self._channelbag is None else self._channelbag.fcurves

    def new_fcurve(self, data_path, index, group):
        """A new F-curve of this target, in the named channel group."""
        fcurves = self._fcurves(create=True)
        if not LAYERED:
            return fcurves.new(data_path, index=index, action_group=group)
        if _NEW_FCURVE_TAKES_GROUP:
            return fcurves.new(data_path, index=index, group_name=group)
        fcurve = fcurves.new(data_path, index=index)
        groups = self._channelbag.groups
        fcurve.group = groups.get(group) or groups.new(group)
        return fcurve

    def fcurves(self):
        """The F-curves of this target (a list, empty when there are none)."""
        fcurves = self._fcurves()
        return [] if fcurves is None else list(fcurves)

    def clear_fcurves(self):
        """Remove every F-curve of this target (the action and its slot stay)."""
        fcurves = self._fcurves()
        if fcurves is not None:
            fcurves.clear()


def _channelbag(action, slot, create):
    if slot is None:
        return None
    if not action.layers:
        if not create:
            return None
        action.layers.new("Layer")
    layer = action.layers[0]
    if not layer.strips:
        if not create:
            return None
        layer.strips.new(type="KEYFRAME")
    return layer.strips[0].channelbag(slot, ensure=create)


def new_action(name, obj):
    """A new, empty action for `obj` (with a slot for it on layered actions)."""
    action = bpy.data.actions.new(name)
    if LAYERED:
        return ActionTarget(action, action.slots.new(id_type=obj.id_type, name=obj.name))
    action.id_root = obj.id_type
    return ActionTarget(action)


class KeyDigest:
    """A hash of F-curves' keys, in F-curve order: each key's frame, value and interpolation, and a
    Bezier curve's handles. Fed as keys are written (`write_keys`, `write_bezier_keys`) or read back
    (`read_digest`), it comes out the same until anyone edits them."""

    def __init__(self):
        self._sha = hashlib.sha1()

    def add(self, fcurve, co, interpolation, handles=()):
        """co: (K, 2) float32; interpolation: (K,) int32; handles: the Bezier keys' left and right (K, 2) float32."""
        self._sha.update(f"{fcurve.data_path}[{fcurve.array_index}]".encode())
        for values in (co, interpolation, *handles):
            self._sha.update(np.ascontiguousarray(values).tobytes())

    def hexdigest(self):
        return self._sha.hexdigest()


def read_digest(fcurves):
    """The KeyDigest of the F-curves' keys as they are now."""
    digest = KeyDigest()
    for fcurve in fcurves:
        points = fcurve.keyframe_points
        count = len(points)
        co = np.empty((count, 2), dtype=np.float32)
        points.foreach_get("co", co.ravel())
        interpolation = read_enum(points, "interpolation")
        handles = ()
        if (interpolation == _BEZIER).any():
            handles = (np.empty((count, 2), dtype=np.float32), np.empty((count, 2), dtype=np.float32))
            points.foreach_get("handle_left", handles[0].ravel())
            points.foreach_get("handle_right", handles[1].ravel())
        digest.add(fcurve, co, interpolation, handles)
    return digest


def _stored(enum_values):
    """Keyframe enum values (interpolation, handle types) as the bytes Blender stores them in: foreach_set
    then copies them straight in, 3 to 6 times quicker than from int32 (4.2 and 5.0 alike)."""
    return np.asarray(enum_values, dtype=np.uint8)


def read_enum(points, name):
    """(K,) int32 values of keyframe enum `name` of keyframe points, read as the bytes Blender stores them in."""
    stored = np.empty(len(points), dtype=np.uint8)
    points.foreach_get(name, stored)
    return stored.astype(np.int32)


def write_keys(fcurve, frames, values, digest=None):
    """Bulk-write keys (frames (N,), values (N,)) into an empty F-curve, linear between frames, fed to
    the KeyDigest given.

    The keys arrive sorted, one per frame, with linear interpolation, so no handles need recomputing.
    """
    count = len(frames)
    points = fcurve.keyframe_points
    points.add(count)
    co = np.empty((count, 2), dtype=np.float32)
    co[:, 0], co[:, 1] = frames, values
    interpolation = np.full(count, _LINEAR, dtype=np.int32)
    points.foreach_set("co", co.ravel())
    points.foreach_set("interpolation", _stored(interpolation))
    if digest is not None:
        digest.add(fcurve, co, interpolation)


def write_bezier_keys(fcurve, frames, values, tangents, digest=None):
    """Bulk-write Bezier keys (frames (K,), values (K,), slopes per frame (K,)) into an empty F-curve,
    fed to the KeyDigest given.

    Each key's handles sit a third of the way to its neighbouring keys along its slope (free handles,
    so Blender keeps them): every segment then plays the cubic Hermite curve core.key_reduction predicts.
    """
    frames, values, tangents = (np.asarray(a, dtype=np.float64) for a in (frames, values, tangents))
    gaps = np.diff(frames) / 3.0
    left = np.concatenate([gaps[:1], gaps])
    right = np.concatenate([gaps, gaps[-1:]])
    count = len(frames)
    points = fcurve.keyframe_points
    points.add(count)
    written = {name: data.astype(np.float32) for name, data in (
        ("co", np.column_stack([frames, values])),
        ("handle_left", np.column_stack([frames - left, values - tangents * left])),
        ("handle_right", np.column_stack([frames + right, values + tangents * right])))}
    for name, data in written.items():
        points.foreach_set(name, data.ravel())
    for name, value in (("interpolation", _BEZIER), ("handle_left_type", _FREE), ("handle_right_type", _FREE)):
        points.foreach_set(name, _stored(np.full(count, value)))
    if digest is not None:
        digest.add(fcurve, written["co"], np.full(count, _BEZIER, dtype=np.int32),
                   (written["handle_left"], written["handle_right"]))


def all_fcurves(action):
    """Every F-curve of the action, of every slot."""
    if not LAYERED:
        return list(action.fcurves)
    return [fcurve for layer in action.layers for strip in layer.strips for bag in strip.channelbags
            for fcurve in bag.fcurves]


def active_target(obj):
    """The ActionTarget the object's active action plays through, or None without one."""
    data = obj.animation_data
    if data is None or data.action is None:
        return None
    return ActionTarget(data.action, data.action_slot if LAYERED else None)


def strip_target(strip):
    """The ActionTarget an NLA strip with an action plays."""
    return ActionTarget(strip.action, getattr(strip, "action_slot", None) if LAYERED else None)


def strip_targets(obj):
    """ActionTargets of every NLA strip of the object, bottom track first."""
    data = obj.animation_data
    if data is None:
        return []
    return [strip_target(strip) for track in data.nla_tracks for strip in track.strips if strip.action is not None]


def is_animated(obj):
    """True when the object has an active action, NLA strips or drivers."""
    data = obj.animation_data
    return data is not None and (data.action is not None or len(data.drivers) > 0
                                 or any(len(track.strips) for track in data.nla_tracks))


def assign(obj, target):
    """Make `target` the object's active action."""
    data = obj.animation_data or obj.animation_data_create()
    data.action = target.action
    if LAYERED:
        data.action_slot = target.slot


def push_down(obj, frames):
    """Move the object's active action onto a new NLA track, as Blender's Push Down does; keys untouched.

    The strip maps each frame to itself over the action's keys and the `frames` (first, last) given
    (the scene's range and the gesture's), so there the action plays as it did: keys on sub-frames,
    F-curve modifiers (a Cycles loop) and extrapolation included, and a manual frame range ignored, as
    it is for an active action. Beyond that span the strip holds its end values.
    """
    data = obj.animation_data
    target = active_target(obj)
    if target is None:
        return
    first, last = target.action.curve_frame_range
    start = math.floor(min(first, frames[0]))
    end = max(last, frames[1], start + 1.0)
    track = data.nla_tracks.new()
    track.name = target.action.name
    strip = _new_strip(track, target, start)
    strip.action_frame_start, strip.action_frame_end = start, end
    strip.frame_end = strip.frame_start + (end - start)
    strip.blend_type = data.action_blend_type
    strip.extrapolation = "HOLD"
    data.action = None


def add_strip(obj, target, start_frame, name):
    """Put `target` on a new NLA track on top, starting at start_frame, with no effect outside it."""
    data = obj.animation_data or obj.animation_data_create()
    track = data.nla_tracks.new()
    track.name = name
    return fill_track(track, target, start_frame, name)


def fill_track(track, target, start_frame, name):
    """Put `target` on the track as a strip called `name` from start_frame, with no effect outside it."""
    strip = _new_strip(track, target, start_frame)
    strip.name = name
    strip.extrapolation = "NOTHING"
    return strip


def _new_strip(track, target, start):
    strip = track.strips.new(target.action.name, int(start), target.action)
    if LAYERED:
        strip.action_slot = target.slot
    return strip
