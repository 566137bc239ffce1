"""The pose underneath a gesture, evaluated in numpy from the F-curves that animate it, instead of a
`scene.frame_set` per frame (which evaluates the whole scene, meshes deformed, at every frame).

It applies where the bones' pose comes only from keys: the active action and NLA strips that
replace (full influence, no blending in or out, not reversed), F-curves with constant, linear or
Bezier keys and constant extrapolation (any other curve is evaluated by Blender's own
`FCurve.evaluate`, frame by frame), and no constraints, drivers or unusual inheritance on the bones
or their parents. `sample` returns None anywhere else, and the caller lets Blender evaluate.

Blender's Bezier segments are cubic in both the frame and the value: each frame is solved for the
curve parameter by Newton's method on the segment (each handle first shortened to the segment's length,
as Blender's `BKE_fcurve_correct_bezpart` does), all curves' frames at once.
"""
import re

import bpy
import numpy as np

from ..core.rig import inverse
from ..core.rotations import euler_to_matrix, quat_to_matrix, rotvec_to_matrix
from . import action_adapter

_PATH = re.compile(r'^pose\.bones\["((?:[^"\\]|\\.)*)"\]\.(location|rotation_quaternion|rotation_euler|'
                   r'rotation_axis_angle|scale)$')
_CHANNELS = ("location", "rotation_quaternion", "rotation_euler", "rotation_axis_angle", "scale")
_INTERPOLATION = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items
_CONSTANT, _LINEAR, _BEZIER = (_INTERPOLATION[name].value for name in ("CONSTANT", "LINEAR", "BEZIER"))
#: Newton steps solving a Bezier segment's frame for its curve parameter, from the linear guess.
_NEWTON_STEPS = 8


def _chain(obj, names):
    """The bones named and all their parents, parents first."""
    bones = obj.data.bones
    wanted = set()
    for name in names:
        bone = bones[name]
        while bone is not None and bone.name not in wanted:
            wanted.add(bone.name)
            bone = bone.parent
    return [bone.name for bone in bones if bone.name in wanted]  # Blender lists parents before children


def _layers(obj):
    """[(ActionTarget, frame mapping)] bottom first, each mapping scene frames (N,) to (action frames
    (N,), played (N,) bool); None when something other than replacing strips and an action plays."""
    data = obj.animation_data
    if data is None or data.use_tweak_mode or data.drivers or any(t.is_solo for t in data.nla_tracks):
        return None
    layers = []
    for track in data.nla_tracks:
        if track.mute:
            continue
        # A strip whose F-curves are all muted (a gesture set aside while it is baked again) plays nothing.
        strips = [s for s in track.strips if not s.mute and s.action is not None
                  and any(not f.mute for f in action_adapter.strip_target(s).fcurves())]
        if any(not _plain_strip(s) for s in strips):
            return None
        layers += [(action_adapter.strip_target(s), _strip_mapping(s, k == 0)) for k, s in enumerate(strips)]
    active = action_adapter.active_target(obj)
    if active is not None:
        if data.action_blend_type != "REPLACE" or data.action_influence != 1.0 \
                or data.action_extrapolation != "HOLD" or active.action.use_frame_range:
            return None
        layers.append((active, lambda frames: (frames, np.ones(len(frames), dtype=bool))))
    return layers


def _plain_strip(strip):
    # A strip's influence is only read when it is animated.
    return (strip.type == "CLIP" and strip.blend_type == "REPLACE"
            and not strip.use_animated_influence and not strip.use_animated_time and not strip.use_reverse
            and strip.blend_in == 0.0 and strip.blend_out == 0.0 and strip.scale > 0.0)


def _strip_mapping(strip, first):
    """Scene frames -> (action frames, played) for one strip, as Blender's NLA maps time: repeats
    included, held before it (the first strip of a track, HOLD) and after it (HOLD, HOLD_FORWARD)."""
    start, end = strip.frame_start, strip.frame_end
    action_start, action_end = strip.action_frame_start, strip.action_frame_end
    length = max(action_end - action_start, 1e-6) * strip.scale
    whole = float(strip.repeat).is_integer()

    def mapping(frames):
        held = np.clip(frames, start, end)
        times = action_start + np.fmod(held - start, length) / strip.scale
        if whole:
            times = np.where(held >= end, action_end, times)
        played = (frames >= start) & (frames <= end)
        if strip.extrapolation in ("HOLD", "HOLD_FORWARD"):
            played |= frames > end
        if strip.extrapolation == "HOLD" and first:
            played |= frames < start
        return times, played
    return mapping


def _fcurve_keys(fcurve):
    """(co (K, 2), right handles (K, 2), left handles (K, 2), interpolation (K,)) of an F-curve."""
    points = fcurve.keyframe_points
    count = len(points)
    arrays = []
    for field in ("co", "handle_right", "handle_left"):
        values = np.empty(2 * count, dtype=np.float32)
        points.foreach_get(field, values)
        arrays.append(values.reshape(count, 2).astype(np.float64))
    return (*arrays, action_adapter.read_enum(points, "interpolation"))


def _numpy_evaluable(fcurve, interpolation):
    return (not fcurve.modifiers and fcurve.extrapolation == "CONSTANT" and len(interpolation) > 0
            and ((interpolation == _CONSTANT) | (interpolation == _LINEAR) | (interpolation == _BEZIER)).all())


def evaluate_fcurves(fcurves, frames):
    """(F, N) values of F-curves at frames (N,), as Blender evaluates them."""
    frames = np.asarray(frames, dtype=np.float64)
    out = np.empty((len(fcurves), len(frames)))
    segments = []  # Bezier segments to solve: (curve, frame mask, p0, p1, p2, p3)
    for row, fcurve in enumerate(fcurves):
        co, right, left, interpolation = _fcurve_keys(fcurve)
        if not _numpy_evaluable(fcurve, interpolation):
            out[row] = [fcurve.evaluate(float(f)) for f in frames]
            continue
        x, y = co[:, 0], co[:, 1]
        k = np.clip(np.searchsorted(x, frames, side="right") - 1, 0, max(len(x) - 2, 0))
        nxt = np.minimum(k + 1, len(x) - 1)
        span = np.where(x[nxt] > x[k], x[nxt] - x[k], 1.0)
        u = np.clip((frames - x[k]) / span, 0.0, 1.0)
        value = np.where(interpolation[k] == _CONSTANT, y[k], y[k] + u * (y[nxt] - y[k]))
        value = np.where(frames <= x[0], y[0], np.where(frames >= x[-1], y[-1], value))
        out[row] = value
        bezier = (interpolation[k] == _BEZIER) & (frames > x[0]) & (frames < x[-1])
        if bezier.any():
            segments.append((row, bezier, co[k[bezier]], right[k[bezier]], left[nxt[bezier]], co[nxt[bezier]]))
    if segments:
        _solve_bezier(out, frames, segments)
    return out


def _solve_bezier(out, frames, segments):
    """Write each Bezier segment's values at its frames into out, all segments solved at once."""
    p0, p1, p2, p3 = (np.concatenate([s[i] for s in segments]) for i in range(2, 6))  # (S, 2) each
    # Each handle shortened to reach no further than the segment (BKE_fcurve_correct_bezpart).
    h1, h2 = p0 - p1, p3 - p2
    length = (p3[:, 0] - p0[:, 0])[:, None]
    p1 = p0 - np.minimum(1.0, length / np.maximum(np.abs(h1[:, :1]), 1e-12)) * h1
    p2 = p3 - np.minimum(1.0, length / np.maximum(np.abs(h2[:, :1]), 1e-12)) * h2
    wanted = np.concatenate([frames[s[1]] for s in segments])
    # x(t) and y(t) as cubic polynomials in t: a t^3 + b t^2 + c t + p0.
    c = 3.0 * (p1 - p0)
    b = 3.0 * (p2 - p1) - c
    a = p3 - p0 - c - b
    t = (wanted - p0[:, 0]) / np.maximum(p3[:, 0] - p0[:, 0], 1e-12)  # the linear guess
    for _ in range(_NEWTON_STEPS):  # x(t) rises monotonically once the handles are shortened
        x = ((a[:, 0] * t + b[:, 0]) * t + c[:, 0]) * t + p0[:, 0]
        slope = (3.0 * a[:, 0] * t + 2.0 * b[:, 0]) * t + c[:, 0]
        t = np.clip(t - (x - wanted) / np.maximum(slope, 1e-9), 0.0, 1.0)
    values = ((a[:, 1] * t + b[:, 1]) * t + c[:, 1]) * t + p0[:, 1]
    start = 0
    for row, mask, *_ in segments:
        count = int(mask.sum())
        out[row, mask] = values[start:start + count]
        start += count


def _matrices(collection, field, names):
    """(len(names), 4, 4) float64 matrices `field` of the named items of a bone collection, read at once."""
    flat = np.empty(16 * len(collection), dtype=np.float32)
    collection.foreach_get(field, flat)
    order = {name: k for k, name in enumerate(collection.keys())}
    return flat.reshape(-1, 4, 4).transpose(0, 2, 1)[[order[name] for name in names]].astype(np.float64)


def rotation_matrices(mode, values):
    """(N, 3, 3) rotations of (N, C) channel values in a bone's rotation mode."""
    if mode == "QUATERNION":
        return quat_to_matrix(values)
    if mode == "AXIS_ANGLE":
        axis = values[:, 1:] / np.maximum(np.linalg.norm(values[:, 1:], axis=1, keepdims=True), 1e-12)
        return rotvec_to_matrix(axis * values[:, :1])
    return euler_to_matrix(values, mode)


def _rotation_path(mode):
    return {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}.get(mode, "rotation_euler")


def _standing(pose_bone, path, count):
    """(count, C) the channel `path`'s value as the bone stands now, on every frame (read-only)."""
    value = np.array(getattr(pose_bone, path), dtype=np.float64)
    return np.broadcast_to(value, (count, len(value)))


def sample(obj, names, frames):
    """(basis (N, B, 4, 4), pose (N, B, 4, 4) in armature space, {bone: (N, C) rotation channel values})
    of the bones `names` at frames (N,), evaluated from their keys; None where Blender must evaluate."""
    chain = _chain(obj, names)
    layers = _layers(obj)
    if layers is None:
        return None
    bones, pose_bones = obj.data.bones, obj.pose.bones
    for name in chain:
        bone = bones[name]
        if len(pose_bones[name].constraints) or not bone.use_inherit_rotation or bone.inherit_scale != "FULL" \
                or not bone.use_local_location:
            return None
    frames = np.asarray(frames, dtype=np.float64)
    count = len(frames)
    in_chain = set(chain)
    channels, covered = {}, {}  # {(bone, channel path): (N, C) values, (N,) frames some layer plays it}
    for target, mapping in layers:
        curves = []
        for fcurve in target.fcurves():
            match = None if fcurve.mute else _PATH.match(fcurve.data_path)
            key = None if match is None else (bpy.utils.unescape_identifier(match.group(1)), match.group(2))
            if key is None or key[0] not in in_chain:
                continue
            if key not in channels:  # starts at the bone's own value; each layer replaces what it keys
                channels[key] = _standing(pose_bones[key[0]], key[1], count).copy()
                covered[key] = np.zeros(count, dtype=bool)
            if fcurve.array_index < channels[key].shape[1]:
                curves.append((fcurve, key))
        if not curves:
            continue
        times, played = mapping(frames)
        values = evaluate_fcurves([f for f, _ in curves], times)  # (F, N)
        for (fcurve, key), row in zip(curves, values, strict=True):
            channels[key][played, fcurve.array_index] = row[played]
            covered[key] |= played
    # A channel the NLA plays on some frames only, or a connected bone's location: Blender's call.
    if any(not played.all() for played in covered.values()) \
            or any(bones[name].use_connect for name, path in covered if path == "location"):
        return None
    keyed = {name for name, _ in channels}
    index = {name: k for k, name in enumerate(chain)}
    parents = np.array([index[bones[name].parent.name] if bones[name].parent else -1 for name in chain])
    rest = _matrices(bones, "matrix_local", chain)  # (C, 4, 4)
    offsets = np.where((parents < 0)[:, None, None], rest, inverse(rest[parents]) @ rest)  # parent rest -> rest
    # Bones neither keyed nor below a keyed bone stand as Blender last evaluated them.
    basis, pose = (np.tile(_matrices(pose_bones, field, chain), (count, 1, 1, 1))
                   for field in ("matrix_basis", "matrix"))  # (N, C, 4, 4)
    moving = np.zeros(len(chain), dtype=bool)
    for column, name in enumerate(chain):
        parent = parents[column]
        moving[column] = name in keyed or (parent >= 0 and moving[parent])
        if not moving[column]:
            continue
        if name in keyed:
            pose_bone = pose_bones[name]
            path = _rotation_path(pose_bone.rotation_mode)
            value = {p: channels[name, p] if (name, p) in channels else _standing(pose_bone, p, count)
                     for p in ("location", "scale", path)}
            rotation = rotation_matrices(pose_bone.rotation_mode, value[path])
            basis[:, column, :3, :3] = rotation * value["scale"][:, None, :]
            basis[:, column, :3, 3] = value["location"]
        frames = slice(None) if name in keyed else slice(0, 1)  # an unkeyed bone's basis is the same every frame
        local = offsets[column] @ basis[frames, column]
        pose[:, column] = local if parent < 0 else pose[:, parent] @ local
    columns = [index[name] for name in names]
    values = {}
    for name in names:
        path = _rotation_path(pose_bones[name].rotation_mode)
        values[name] = channels[name, path] if (name, path) in channels else _standing(pose_bones[name], path, count)
    return basis[:, columns], pose[:, columns], values
