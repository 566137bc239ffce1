"""The one place that knows how Blender versions store keyframes.

Blender 4.2 keeps F-curves on the action (`action.fcurves`). Blender 4.4+ (and 5.0, which removed
`action.fcurves`) uses layered actions: an action has slots, one per animated data-block, and its
F-curves live in a channelbag of a keyframe strip of a layer, one channelbag per slot. Callers get
an `ActionTarget` (the action and, where slots exist, the slot) and never touch either layout.
"""
import math
import zlib

import bpy
import numpy as np

LAYERED = "slots" in bpy.types.Action.bl_rna.properties
#: Blender 5.0's `ChannelbagFCurves.new` takes the channel group's name; 4.4 and 4.5 group the F-curve after.
_NEW_FCURVE_TAKES_GROUP = LAYERED and (
    "group_name" in bpy.types.ActionChannelbagFCurves.bl_rna.functions["new"].parameters)
_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value
_BEZIER = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["BEZIER"].value
_FREE = bpy.types.Keyframe.bl_rna.properties["handle_left_type"].enum_items["FREE"].value
#: A linear key's interpolation, as Keyframe.interpolation stores it.
LINEAR_KEY = _LINEAR
#: Pose-bone property keyed for each rotation mode (the Euler orders key rotation_euler).
_ROTATION_PATHS = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}


def rotation_path(mode: str) -> str:
    """The pose-bone property a bone in rotation mode `mode` keys its rotation on."""
    return _ROTATION_PATHS.get(mode, "rotation_euler")


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

    def find(self, data_path, index):
        """The F-curve of this target for the channel, or None."""
        fcurves = self._fcurves()
        return None if fcurves is None else fcurves.find(data_path, index=index)

    def remove(self, fcurve):
        """Remove one F-curve of this target."""
        self._fcurves().remove(fcurve)


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


class KeyMemory:
    """The keys written to F-curves, curve by curve: each key's frame and value, its interpolation and a
    Bezier curve's handles. Fed as keys are written (`write_keys`, `write_bezier_keys`), it is kept (`pack`)
    to tell later which curves and frames anyone changed since (`changed_frames`)."""

    def __init__(self):
        self.curves = []  # [(data path, array index, co (K, 2) float32, interpolation (K,) uint8, handles)]

    def add(self, fcurve, co, interpolation, handles=()):
        """co: (K, 2) float32; interpolation: (K,); handles: the Bezier keys' left and right (K, 2) float32."""
        self.add_keys(fcurve.data_path, fcurve.array_index, co, interpolation,
                      np.concatenate(handles, axis=1) if len(handles) else None)

    def add_keys(self, data_path, index, co, interpolation, handles=None):
        """As `add`, for the channel (data path, index); handles: (K, 4) left and right, or None."""
        self.curves.append((data_path, int(index), np.array(co, dtype=np.float32),
                            np.asarray(interpolation, dtype=np.uint8),
                            None if handles is None else np.array(handles, dtype=np.float32)))

    def pack(self):
        """The keys as a record keeps them: {"paths", "indices", "counts", "bezier": per curve, "keys": bytes}."""
        data = b"".join(part.tobytes() for _, _, co, interpolation, handles in self.curves
                        for part in (co, interpolation) + (() if handles is None else (handles,)))
        return {"paths": [path for path, *_ in self.curves], "indices": [i for _, i, *_ in self.curves],
                "counts": [len(co) for _, _, co, *_ in self.curves],
                "bezier": [handles is not None for *_, handles in self.curves], "keys": zlib.compress(data, 1)}

    @classmethod
    def unpack(cls, kept):
        """The KeyMemory that `pack` returned (`kept`)."""
        memory, data, offset = cls(), zlib.decompress(kept["keys"]), 0

        def take(dtype, shape):
            nonlocal offset
            array = np.frombuffer(data, dtype=dtype, count=int(np.prod(shape)), offset=offset).reshape(shape)
            offset += array.nbytes
            return array
        for path, index, count, bezier in zip(kept["paths"], kept["indices"], kept["counts"], kept["bezier"],
                                              strict=True):
            co, interpolation = take(np.float32, (count, 2)), take(np.uint8, (count,))
            handles = take(np.float32, (count, 4)) if bezier else None
            memory.curves.append((path, int(index), co, interpolation, handles))
        return memory


def read_keys(fcurve):
    """(co (K, 2) float32, interpolation (K,) uint8, handles (K, 4) float32 or None when no key is Bezier) of
    an F-curve's keys as they are now."""
    points = fcurve.keyframe_points
    count = len(points)
    co = np.empty((count, 2), dtype=np.float32)
    points.foreach_get("co", co.ravel())
    interpolation = np.empty(count, dtype=np.uint8)
    points.foreach_get("interpolation", interpolation)
    if not (interpolation == _BEZIER).any():
        return co, interpolation, None
    handles = np.empty((count, 4), dtype=np.float32)
    for k, side in enumerate(("handle_left", "handle_right")):
        values = np.empty((count, 2), dtype=np.float32)
        points.foreach_get(side, values.ravel())
        handles[:, 2 * k:2 * k + 2] = values
    return co, interpolation, handles


def holds_still(fcurve):
    """Whether the F-curve plays one value on every frame: no modifiers, every key and Bezier handle at one value
    (any extrapolation is then flat too)."""
    if len(fcurve.modifiers) or not len(fcurve.keyframe_points):
        return not len(fcurve.modifiers)
    co, _, handles = read_keys(fcurve)
    values = co[:, 1] if handles is None else np.concatenate([co[:, 1], handles[:, 1], handles[:, 3]])
    return bool((values == values[0]).all())


def changed_frames(written, now):
    """Frames (sorted ints) at which keys differ: written and now are `read_keys` triples (now None for a
    curve that is gone: every written frame)."""
    if now is None:
        return sorted({int(round(f)) for f in written[0][:, 0]})
    if all(a is None and b is None or a is not None and b is not None and np.array_equal(a, b)
           for a, b in zip(written, now, strict=True)):
        return []

    def by_frame(co, interpolation, handles):
        rows = [co, interpolation[:, None].astype(np.float32)] + ([] if handles is None else [handles])
        return {float(row[0]): row[1:].tobytes() for row in np.concatenate(rows, axis=1)}
    before, after = by_frame(*written), by_frame(*now)
    frames = {f for f in before.keys() | after.keys() if before.get(f) != after.get(f)}
    return sorted({int(round(f)) for f in frames})


def _stored(enum_values):
    """Keyframe enum values (interpolation, handle types) as the bytes Blender stores them in: foreach_set
    then copies them straight in, 3 to 6 times quicker than from int32 (4.2 and 5.0 alike)."""
    return np.asarray(enum_values, dtype=np.uint8)


def read_enum(points, name):
    """(K,) int32 values of keyframe enum `name` of keyframe points, read as the bytes Blender stores them in."""
    stored = np.empty(len(points), dtype=np.uint8)
    points.foreach_get(name, stored)
    return stored.astype(np.int32)


def write_keys(fcurve, frames, values, memory=None):
    """Bulk-write keys (frames (N,), values (N,)) into an empty F-curve, linear between frames, remembered by
    the KeyMemory given.

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
    if memory is not None:
        memory.add(fcurve, co, interpolation)


def overwrite_values(fcurve, frames, values, memory=None):
    """Overwrite the values of an F-curve's linear keys, one on each of `frames` (N,) already, with values (N,)
    (the write `write_keys` makes), remembered by the KeyMemory given. The caller tags the action for update."""
    co = np.empty((len(frames), 2), dtype=np.float32)
    co[:, 0], co[:, 1] = frames, values
    fcurve.keyframe_points.foreach_set("co", co.ravel())
    if memory is not None:
        memory.add(fcurve, co, np.full(len(frames), _LINEAR, dtype=np.int32))


def write_bezier_keys(fcurve, frames, values, tangents, memory=None):
    """Bulk-write Bezier keys (frames (K,), values (K,), slopes per frame (K,)) into an empty F-curve,
    remembered by the KeyMemory given.

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
    if memory is not None:
        memory.add(fcurve, written["co"], np.full(count, _BEZIER), (written["handle_left"], written["handle_right"]))


def write_points(fcurve, co, interpolation, handles=None):
    """Replace an F-curve's keys with co (K, 2), interpolation (K,) and, where some are Bezier, free handles
    (K, 4: left, right); without handles each key's handles sit on it."""
    points = fcurve.keyframe_points
    points.clear()
    points.add(len(co))
    co = np.asarray(co, dtype=np.float32)
    points.foreach_set("co", co.ravel())
    points.foreach_set("interpolation", _stored(interpolation))
    left, right = (co, co) if handles is None else (handles[:, :2], handles[:, 2:])
    for name, data in (("handle_left", left), ("handle_right", right)):
        points.foreach_set(name, np.ascontiguousarray(data, dtype=np.float32).ravel())
    for name in ("handle_left_type", "handle_right_type"):
        points.foreach_set(name, _stored(np.full(len(co), _FREE)))


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


def plays(obj):
    """True when anything of the object's animation plays: an unmuted F-curve of its active action or of an
    unmuted NLA strip, or an unmuted driver (`is_animated` counts muted ones too)."""
    data = obj.animation_data
    if data is None:
        return False
    if any(not d.mute for d in data.drivers):
        return True
    targets = [strip_target(s) for t in data.nla_tracks if not t.mute for s in t.strips
               if not s.mute and s.action is not None]
    active = active_target(obj)
    return any(not f.mute for t in targets + ([active] if active is not None else []) for f in t.fcurves())


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


def add_strip(obj, target, frames, name, below=None):
    """Put `target` on a new NLA track (on top, or right above the track `below`), playing its frames
    (first, last) at those same frames with no effect outside them; returns the strip."""
    data = obj.animation_data or obj.animation_data_create()
    track = data.nla_tracks.new(prev=below)
    track.name = name
    return fill_track(track, target, frames, name)


def fill_track(track, target, frames, name):
    """Put `target` on the track as a strip called `name` playing its frames (first, last) at those same
    frames (keys of others in the action elsewhere do not shift it), with no effect outside them."""
    strip = _new_strip(track, target, frames[0])
    set_action_range(strip, *frames)
    strip.name = name
    strip.extrapolation = "NOTHING"
    return strip


def set_action_range(strip, first, last):
    """Have the strip play its action's frames first-last, unscaled, from its start frame."""
    if first > strip.action_frame_end:
        strip.action_frame_end = last
        strip.action_frame_start = first
    else:
        strip.action_frame_start = first
        strip.action_frame_end = last


def _new_strip(track, target, start):
    strip = track.strips.new(target.action.name, int(start), target.action)
    if LAYERED:
        strip.action_slot = target.slot
    return strip
