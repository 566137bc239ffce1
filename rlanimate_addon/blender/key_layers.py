"""Writing a gesture's keys where they play (blender/gestures.py describes the layout): a new gesture's
actions placed on the rig, a gesture's own keys rewritten in place, a gesture trimmed where a later one on its
arm takes over, a gesture deleted; and a backup that puts a gesture back as it was.

Only the F-curves a gesture wrote (its record lists them) are ever rewritten or removed: keys others put in
its actions stay as they are and keep playing. Keys are written in bulk (`keyframe_points.add` +
`foreach_set`, blender/action_adapter.py), one per frame, or a few Bezier keys with Editable Keys.
"""
import bpy
import numpy as np

from ..core import behaviours, easing, key_reduction
from . import action_adapter
from .gestures import MAIN, RECORD, TORSO, TORSO_OF, Layer

#: What a gesture's torso layer is called after its main one.
TORSO_SUFFIX = " (torso)"


def key_action(target, start_frame, keys, memory=None, properties=None):
    """Key a gesture from start_frame into an ActionTarget. keys: {bone name: (rotation mode, (N, C) channel
    values per frame, kept frame indices or None)}: with kept indices, Bezier keys on those frames only
    (core.key_reduction), else a linear key on every frame. properties: {data path: (N,) values} of other
    channels to key on every frame (a Rigify arm's IK-FK switch). Every key is remembered by `memory` (an
    action_adapter.KeyMemory)."""
    for bone, (mode, values, kept) in keys.items():
        frames = start_frame + np.arange(len(values))
        path = f'pose.bones["{bpy.utils.escape_identifier(bone)}"].{action_adapter.rotation_path(mode)}'
        tangents = None if kept is None else key_reduction.slopes(values)
        for channel in range(values.shape[1]):
            fcurve = target.new_fcurve(path, channel, bone)
            if kept is None:
                action_adapter.write_keys(fcurve, frames, values[:, channel], memory)
            else:
                action_adapter.write_bezier_keys(fcurve, frames[kept], values[kept, channel], tangents[kept, channel],
                                                 memory)
    for path, values in (properties or {}).items():
        fcurve = target.new_fcurve(path, 0, path.split('"')[1])
        action_adapter.write_keys(fcurve, start_frame + np.arange(len(values)), values, memory)


def key_values(fcurves, start_frame, keys, memory, properties=None):
    """Overwrite the values of the F-curves `fcurves` (of one action, unedited) with `key_action`'s keys (one
    linear key a frame from start_frame, no kept frames), remembered by `memory`; False, writing nothing, unless
    the curves are exactly those `key_action` would make, keying the same frames."""
    values = {}
    for bone, (mode, rotation, kept) in keys.items():
        if kept is not None:
            return False
        path = f'pose.bones["{bpy.utils.escape_identifier(bone)}"].{action_adapter.rotation_path(mode)}'
        values.update({(path, channel): rotation[:, channel] for channel in range(rotation.shape[1])})
    values.update({(path, 0): np.asarray(series) for path, series in (properties or {}).items()})
    curves = {(f.data_path, f.array_index): f for f in fcurves}
    count = len(next(iter(values.values()))) if values else 0
    frames = start_frame + np.arange(count)
    ends = [(f.keyframe_points[0].co[0], f.keyframe_points[-1].co[0]) for f in fcurves if len(f.keyframe_points)]
    if curves.keys() != values.keys() or any(len(f.keyframe_points) != count for f in fcurves) \
            or set(ends) != {(frames[0], frames[-1])}:
        return False  # unedited curves keying the frames from the first to the last one each hold one a frame
    for key, series in values.items():
        action_adapter.overwrite_values(curves[key], frames, series, memory)
    fcurves[0].id_data.update_tag()  # the action's evaluated copy takes the new values
    return True


def _frames(start, layers):
    count = len(next(iter(layers[MAIN].values()))[1])
    return start, start + count - 1


def place(obj, name, start, layers, blend_type, played, properties, still, gesture_id):
    """Key a new gesture: layers {MAIN: keys, TORSO: keys} (`key_action`'s) from frame `start` into new actions
    named `name` and name + TORSO_SUFFIX. On a still rig the main action becomes the active action; otherwise
    the active action (if any) is pushed down to the NLA, as Blender's Push Down does, playing as before over
    its keys and the `played` frames (first, last), and the main action goes on a new NLA track above it with
    the blend type ('REPLACE' or 'COMBINE'). The torso action goes on a track of its own, Combine. Returns
    (the main action, {layer: KeyMemory} of the keys written)."""
    frames = _frames(start, layers)
    memories = {layer: action_adapter.KeyMemory() for layer in layers}
    main = action_adapter.new_action(name, obj)
    key_action(main, start, layers[MAIN], memories[MAIN], properties)
    if still:
        action_adapter.assign(obj, main)
        below = None
    else:
        action_adapter.push_down(obj, played)
        strip = action_adapter.add_strip(obj, main, frames, name)
        strip.blend_type, below = blend_type, obj.animation_data.nla_tracks[-1]
    torso = action_adapter.new_action(name + TORSO_SUFFIX, obj)
    torso.action[TORSO_OF] = gesture_id
    key_action(torso, start, layers[TORSO], memories[TORSO])
    action_adapter.add_strip(obj, torso, frames, name + TORSO_SUFFIX, below=below).blend_type = "COMBINE"
    return main.action, memories


def rewrite(gesture, name, start, layers, blend_type, properties, gesture_id, in_place=False):
    """Bake new keys (`place`'s layers) into the gesture's own actions where they play, renamed after `name`:
    the F-curves it wrote are replaced, any other F-curve of its actions is kept. A gesture without a torso layer
    (made before gestures had one, or its torso action deleted) gets one. in_place (Follow Target's previews of
    an unedited gesture): where the gesture's curves already key those channels on those frames, one key a
    frame, their values are overwritten (`key_values`). Returns {layer: KeyMemory}."""
    frames = _frames(start, layers)
    memories = {}
    given = generated_name(gesture.record)  # what it was called, unless the animator renamed it since
    if TORSO not in gesture.layers:
        torso = action_adapter.new_action(name + TORSO_SUFFIX, gesture.obj)
        torso.action[TORSO_OF] = gesture_id
        action_adapter.add_strip(gesture.obj, torso, frames, name + TORSO_SUFFIX).blend_type = "COMBINE"
        gesture.torso = Layer(torso, gesture.obj.animation_data.nla_tracks[-1])
    for layer_name, keys in layers.items():
        layer = gesture.layers[layer_name]
        memories[layer_name] = action_adapter.KeyMemory()
        extra = properties if layer_name == MAIN else None
        owned = gesture.owned(layer_name)
        if not (in_place and key_values(owned, start, keys, memories[layer_name], extra)):
            for fcurve in owned:
                layer.target.remove(fcurve)
            key_action(layer.target, start, keys, memories[layer_name], extra)
        suffix = "" if layer_name == MAIN else TORSO_SUFFIX
        layer_label = _renamed(layer.action, given + suffix, name + suffix)
        if layer.track is None:  # the active action: a base on a still rig
            gesture.obj.animation_data.action_blend_type = blend_type
            continue
        _renamed(layer.track, given + suffix, layer_label)
        base = gesture.still and layer_name == MAIN
        _fit_strip(layer, frames, layer.track.name, "COMBINE" if layer_name == TORSO else blend_type, base)
    return memories


def generated_name(record):
    """The name Generate gives a gesture's main action: 'RLAnimate Point Right'."""
    return f"RLAnimate {behaviours.title(record['behaviour'])} {str(record['arm']).title()}"


def _renamed(named, given, name):
    """Rename an action or a track from `given` (Generate's name for it, or that name with the number Blender
    adds to a name taken: 'RLAnimate Point Right.001') to `name`; one the animator renamed keeps its name.
    Returns its name."""
    number = named.name[len(given) + 1:]
    if named.name != name and (named.name == given or (named.name.startswith(given + ".") and number.isdigit())):
        named.name = name
    return named.name


def _fit_strip(layer, frames, name, blend_type, base):
    """Have the layer's strip play the gesture's frames: a base's HOLD strip is widened to them where they
    leave it (it keeps holding before and after); any other strip plays exactly them, untrimmed."""
    strip = layer.strip
    if base:
        first, last = min(frames[0], strip.action_frame_start), max(frames[1], strip.action_frame_end)
        if (first, last) != (strip.action_frame_start, strip.action_frame_end):
            settings = strip.blend_type, strip.extrapolation
            layer.track.strips.remove(strip)
            strip = action_adapter.fill_track(layer.track, layer.target, (first, last), name)
            strip.blend_type, strip.extrapolation = settings
        strip.name = name
        return
    strips = list(layer.track.strips)
    if len(strips) == 1 and _plays(strips[0], layer.target, frames, blend_type):
        if strips[0].name != name:
            strips[0].name = name
        return  # as it is: no new strip (on a large rig, Blender's next frame rebuilds its whole evaluation)
    for old in strips:
        layer.track.strips.remove(old)
    action_adapter.fill_track(layer.track, layer.target, frames, name).blend_type = blend_type


def _plays(strip, target, frames, blend_type):
    """Whether the strip plays exactly what action_adapter.fill_track would have it play, with that blend type."""
    slot = getattr(strip, "action_slot", None) if action_adapter.LAYERED else None
    return (strip.action == target.action and slot == target.slot and not strip.mute
            and (strip.frame_start, strip.frame_end) == tuple(frames)
            and (strip.action_frame_start, strip.action_frame_end) == tuple(frames)
            and strip.scale == 1.0 and strip.repeat == 1.0 and strip.blend_in == 0.0 and strip.blend_out == 0.0
            and strip.extrapolation == "NOTHING" and strip.blend_type == blend_type and not strip.use_reverse)


def trim(gesture, at, fade):
    """Have the gesture play until frame `at`, where a later gesture on its arm takes over, and fade out over
    the `fade` frames after it. Its NLA strips end there, faded by the NLA (blend out); a base instead fades
    its own keys of its arm and eyes to its end pose, which it holds after (its other arm plays on). Keys it
    wrote up to `at` are kept exactly."""
    record = gesture.record
    end = min(int(record["end"]), int(at) + int(fade))
    for layer_name, layer in gesture.layers.items():
        if layer_name == MAIN and gesture.still:
            _fade_keys(gesture, layer, at, end)
        elif layer.strip is not None:
            action_adapter.set_action_range(layer.strip, int(record["start"]), end)
            layer.strip.blend_out = end - at
    record["trim"] = {"at": int(at), "fade": int(end - at)}


def _fade_keys(gesture, layer, at, end):
    """A base's own curves, but the other arm's, rebuilt from the keys it wrote: kept up to `at`, then eased to
    their last value by frame `end` (minimum jerk), linear keys; the record keeps what they now hold."""
    written = gesture.memory(MAIN, expected=False)
    other = gesture.other_arm_curves()
    trimmed = action_adapter.KeyMemory()
    for path, index, co, interpolation, handles in written.curves:
        fcurve = layer.target.find(path, index)
        if (path, index) not in other and fcurve is not None:
            co, interpolation, handles = _faded(fcurve, (co, interpolation, handles), at, end)
            action_adapter.write_points(fcurve, co, interpolation, handles)
        trimmed.add_keys(path, index, co, interpolation, handles)
    gesture.record["layers"][MAIN]["trimmed"] = trimmed.pack()


def _faded(fcurve, keys, at, end):
    """(co, interpolation, handles) of written keys cut at frame `at` and eased from their value there to the
    last one by frame `end`."""
    co, interpolation, handles = keys
    action_adapter.write_points(fcurve, co, interpolation, handles)  # as written, to read its value at `at`
    value_at, last = float(fcurve.evaluate(float(at))), float(co[-1, 1])
    kept = co[:, 0] < at
    frames = np.arange(at, end + 1, dtype=np.float64)
    ease = easing.minimum_jerk((frames - at) / max(end - at, 1))
    tail = np.column_stack([frames, value_at + (last - value_at) * ease]).astype(np.float32)
    new_co = np.concatenate([co[kept], tail])
    new_interpolation = np.concatenate([interpolation[kept],
                                        np.full(len(tail), action_adapter.LINEAR_KEY, dtype=np.uint8)])
    if handles is None:
        return new_co, new_interpolation, None
    return new_co, new_interpolation, np.concatenate([handles[kept], np.tile(tail, 2)])


def remove(gesture, keep_standing):
    """Delete the gesture's own keys, its record and its layers' tracks and actions where nothing else is
    left in them (keys others put there stay, in a plain action). With keep_standing (a base, with other
    gestures above it), its main curves keep their last key, the standing pose it held, so the character still
    stands there: its action becomes 'RLAnimate Standing Pose'."""
    obj = gesture.obj
    owned = {layer_name: gesture.owned(layer_name) for layer_name in gesture.layers}
    for layer_name, layer in gesture.layers.items():
        standing = keep_standing and layer_name == MAIN
        for fcurve in owned[layer_name]:
            if standing:
                points = fcurve.keyframe_points
                while len(points) > 1:
                    points.remove(points[0], fast=True)
                fcurve.update()
            else:
                layer.target.remove(fcurve)
        action = layer.action
        for prop in (RECORD, TORSO_OF):
            if prop in action:
                del action[prop]
        if standing:
            action.name = "RLAnimate Standing Pose"
        elif not action_adapter.all_fcurves(action):
            if layer.track is None:
                obj.animation_data.action = None
            else:
                obj.animation_data.nla_tracks.remove(layer.track)
            bpy.data.actions.remove(action)
        else:
            action.name = f"{obj.name} keys"


#: The strip settings a Backup keeps, in the order they are put back.
_STRIP = ("blend_type", "extrapolation", "blend_in", "blend_out", "mute", "name")


class Backup:
    """A gesture as it is: a copy of each of its actions and where their strips play, put back by `restore`
    when the bake that changes it is undone (blender/bake_check.py), else `discard`ed. Make it before
    bake_check.BakeUndo records the file, so that undoing the bake keeps the copies."""

    def __init__(self, gesture):
        self.gesture, self.layers = gesture, []
        for layer in gesture.layers.values():
            strip = layer.strip
            placed = None if strip is None else (strip.frame_start, strip.action_frame_start,
                                                 strip.action_frame_end, [getattr(strip, k) for k in _STRIP],
                                                 layer.track.name)
            self.layers.append((layer, layer.action.name, layer.action.copy(), placed))

    def restore(self):
        obj = self.gesture.obj
        for layer, name, copy, placed in self.layers:
            replaced = layer.action
            target = action_adapter.ActionTarget(copy, copy.slots[0] if action_adapter.LAYERED else None)
            if placed is None:
                action_adapter.assign(obj, target)
            else:
                start, first, last, settings, track_name = placed
                for strip in list(layer.track.strips):
                    layer.track.strips.remove(strip)
                strip = action_adapter.fill_track(layer.track, target, (first, last), settings[-1])
                strip.frame_start = start
                for key, value in zip(_STRIP, settings, strict=True):
                    setattr(strip, key, value)
                layer.track.name = track_name
            bpy.data.actions.remove(replaced)
            copy.name = name

    def discard(self):
        for _, _, copy, _ in self.layers:
            bpy.data.actions.remove(copy)
