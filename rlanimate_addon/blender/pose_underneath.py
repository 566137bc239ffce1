"""The pose underneath a gesture, evaluated in numpy from the keys that animate it, instead of a `scene.frame_set`
per frame (which evaluates the whole scene, meshes deformed, at every frame).

It applies where the bones' pose comes from keys and the constraints below: the active action and NLA action
strips of any timing (scaled, repeated, held, blended in and out) that Replace or Combine (the layouts Generate
itself writes: blender/gestures.py), F-curves of any kind (core/nla.py says how they blend, blender/fcurve_values.py
how they are evaluated), bones that inherit fully, and Copy Transforms, Copy Rotation and Copy Location from
bones evaluated so too (core/bone_constraints.py). `sample` returns None anywhere else (other constraints,
drivers on the bones, a soloed track, a strip of another kind or with animated influence or time, a Combine of
axis-angle rotations ...), and the caller lets Blender evaluate.
"""
import re
from collections.abc import Sequence
from typing import Any

import bpy
import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from ..core import bone_constraints, nla
from ..core.rig import inverse
from ..core.rotations import euler_to_matrix, quat_to_matrix, rotvec_to_matrix
from . import action_adapter, fcurve_values

_PATH = re.compile(r'^pose\.bones\["((?:[^"\\]|\\.)*)"\]\.(location|rotation_quaternion|rotation_euler|'
                   r'rotation_axis_angle|scale)$')
_BONE_PATH = re.compile(r'^pose\.bones\["((?:[^"\\]|\\.)*)"\](.*)$')
#: The constraints' spaces evaluated here.
_SPACES = ("WORLD", "POSE")
Array = npt.NDArray[np.float64]
#: A bone's channel: (bone name, channel path).
Channel = tuple[str, str]
#: A constraint evaluated here: (kind, space, target bone, influence).
Copy = tuple[str, str, str, float]
#: An NLA track as it plays: [(ActionTarget, nla.Strip)] in time order.
Track = list[tuple[Any, nla.Strip]]


class _Unsupported(Exception):
    """Something of the rig's animation that only Blender evaluates exactly."""


def rotation_matrices(mode: str, values: Array) -> Array:
    """(N, 3, 3) rotations of (N, C) channel values in a bone's rotation mode."""
    if mode == "QUATERNION":
        return quat_to_matrix(values)
    if mode == "AXIS_ANGLE":
        axis = values[:, 1:] / np.maximum(np.linalg.norm(values[:, 1:], axis=1, keepdims=True), 1e-12)
        return rotvec_to_matrix(axis * values[:, :1])
    return euler_to_matrix(values, mode)


def sample(obj: Any, names: Sequence[str], frames: ArrayLike) -> tuple[Array, Array, dict[str, Array]] | None:
    """(basis (N, B, 4, 4), pose (N, B, 4, 4) in armature space, {bone: (N, C) rotation channel values})
    of the bones `names` at frames (N,), evaluated from their keys; None where Blender must evaluate."""
    try:
        return _sample(obj, list(names), np.asarray(frames, dtype=np.float64))
    except _Unsupported:
        return None


def _sample(obj: Any, names: list[str], frames: Array) -> tuple[Array, Array, dict[str, Array]]:
    layers = _layers(obj, frames)
    chain = _chain(obj, names)
    _check_drivers(obj, chain)
    channels = _channels(obj, chain, layers, frames)
    return _forward(obj, names, chain, channels, len(frames))


def _chain(obj: Any, names: list[str]) -> dict[str, list[Copy]]:
    """{bone: its constraints' (kind, space, target bone, influence)} of the named bones, the bones they hang
    from and the bones their constraints follow, in an order Blender can evaluate them in (each after its parent
    and its targets); _Unsupported for a bone Blender evaluates otherwise."""
    ordered, visiting = {}, set()

    def visit(name: str) -> None:
        if name in ordered:
            return
        if name in visiting:
            raise _Unsupported  # a dependency cycle
        visiting.add(name)
        bone, pose_bone = obj.data.bones[name], obj.pose.bones[name]
        if not bone.use_inherit_rotation or bone.inherit_scale != "FULL" or not bone.use_local_location:
            raise _Unsupported
        copies = [_copying(obj, c) for c in pose_bone.constraints if not c.mute]
        for dependency in ([bone.parent.name] if bone.parent else []) + [copy[2] for copy in copies]:
            visit(dependency)
        ordered[name] = copies
    for name in names:
        visit(name)
    return ordered


def _copying(obj: Any, constraint: Any) -> Copy:
    """(kind, space, target bone, influence) of a constraint evaluated here; _Unsupported for any other."""
    kind = constraint.type
    if kind not in bone_constraints.COPYING or not constraint.is_valid or constraint.target is not obj \
            or not constraint.subtarget or constraint.owner_space != constraint.target_space \
            or constraint.owner_space not in _SPACES or getattr(constraint, "head_tail", 0.0) != 0.0:
        raise _Unsupported
    mixing = getattr(constraint, "mix_mode", "REPLACE") != "REPLACE" or getattr(constraint, "use_offset", False) \
        or getattr(constraint, "remove_target_shear", False)
    axes = [getattr(constraint, f"{use}_{axis}", value) for use, value in (("use", True), ("invert", False))
            for axis in "xyz"]
    if mixing or axes != [True] * 3 + [False] * 3 or getattr(constraint, "euler_order", "AUTO") != "AUTO":
        raise _Unsupported
    return kind, constraint.owner_space, constraint.subtarget, float(constraint.influence)


def _check_drivers(obj: Any, chain: dict[str, list[Copy]]) -> None:
    """_Unsupported when a driver sets anything of a bone of the chain, or the armature's own data is animated."""
    data, armature = obj.animation_data, obj.data.animation_data
    if armature is not None and (armature.action is not None or len(armature.drivers)):
        raise _Unsupported
    for driver in data.drivers if data is not None else ():
        match = _BONE_PATH.match(driver.data_path)
        if match and bpy.utils.unescape_identifier(match.group(1)) in chain and not driver.mute:
            raise _Unsupported


def _layers(obj: Any, frames: Array) -> list[Track]:
    """The tracks of what plays at frames (N,), bottom first: the NLA's tracks and, above them, the active
    action; without NLA, the active action as a strip that plays its keys as they are on every frame (at full
    influence, whatever the action's blend settings: Blender does so). _Unsupported for what only Blender plays."""
    data = obj.animation_data
    if data is None or data.use_tweak_mode or any(t.is_solo for t in data.nla_tracks):
        raise _Unsupported
    tracks = [[(action_adapter.strip_target(s), _strip(s)) for s in track.strips if s.action is not None]
              for track in data.nla_tracks if not track.mute] if data.use_nla else []
    tracks = [track for track in tracks if track]
    active = action_adapter.active_target(obj)
    if active is None:
        return tracks
    if not tracks:
        first, last = float(frames.min()), float(frames.max()) + 1.0
        return [[(active, nla.Strip(first, last, first, last, influence=1.0))]]
    if data.action_extrapolation != "HOLD" or active.action.use_frame_range:
        raise _Unsupported
    first, last = active.action.curve_frame_range
    last = max(last, first + 1.0)  # Blender's BKE_nla_clip_length_ensure_nonzero
    tracks.append([(active, nla.Strip(first, last, first, last, blend_type=_blend_type(data.action_blend_type),
                                      influence=float(data.action_influence)))])
    return tracks


def _strip(strip: Any) -> nla.Strip:
    """The nla.Strip of an action strip Blender plays as core/nla.py does; _Unsupported for any other."""
    if strip.type != "CLIP" or strip.use_reverse or strip.use_animated_influence or strip.use_animated_time:
        raise _Unsupported
    return nla.Strip(strip.frame_start, strip.frame_end, strip.action_frame_start, strip.action_frame_end,
                     strip.scale, strip.repeat, strip.extrapolation, abs(strip.blend_in), abs(strip.blend_out),
                     _blend_type(strip.blend_type), strip.mute)


def _blend_type(name: str) -> str:
    if name not in nla.BLEND_TYPES:
        raise _Unsupported
    return name


def _chain_curves(target: Any, chain: dict[str, list[Copy]]) -> list[tuple[Any, Channel]]:
    """[(F-curve, (bone, channel))] of the target's F-curves Blender evaluates that key a channel of a chain bone;
    _Unsupported for one keying anything else of a chain bone (a constraint's influence) but custom properties."""
    found = []
    for fcurve in target.fcurves():
        match = _BONE_PATH.match(fcurve.data_path)
        if match is None or bpy.utils.unescape_identifier(match.group(1)) not in chain:
            continue
        if fcurve.mute or (fcurve.group is not None and fcurve.group.mute) or not len(fcurve.keyframe_points):
            continue  # Blender does not evaluate it
        channel = _PATH.match(fcurve.data_path)
        if channel is None:
            if match.group(2).startswith('["'):
                continue  # a custom property: it moves no bone (no driver on a chain bone reads it)
            raise _Unsupported
        found.append((fcurve, (bpy.utils.unescape_identifier(channel.group(1)), channel.group(2))))
    return found


def _channels(obj: Any, chain: dict[str, list[Copy]], layers: list[Track], frames: Array) -> dict[Channel, Array]:
    """{(bone, channel): (N, C) values} of every channel of the chain's bones that the animation keys, as it
    plays at frames (N,): each keyed component from its default value, each layer blended in (core/nla.py);
    components nothing keys keep the bone's value."""
    keyed = [[(strip, _chain_curves(target, chain)) for target, strip in track] for track in layers]
    channels = _starting(obj, [item for track in keyed for _, curves in track for item in curves], len(frames))
    for track in keyed:
        index, at = nla.playing([strip for strip, _ in track], frames)
        for k, (strip, curves) in enumerate(track):
            plays = index == k
            if plays.any() and curves:
                _blend_layer(channels, curves, nla.strip_time(strip, at[plays]), strip.blend_type,
                             nla.influence(strip, at[plays]), plays)
    return channels


def _starting(obj: Any, curves: list[tuple[Any, Channel]], count: int) -> dict[Channel, Array]:
    """{(bone, channel): (N, C) values before any layer blends in}: a keyed component's default, the bone's own
    value for the others; _Unsupported for a quaternion keyed in part (Blender's Combine reads its defaults)."""
    domains: dict[Channel, npt.NDArray[np.bool_]] = {}
    for fcurve, key in curves:
        size = len(nla.DEFAULTS[key[1]])
        if fcurve.array_index < size:
            domains.setdefault(key, np.zeros(size, dtype=bool))[fcurve.array_index] = True
    channels = {}
    for (bone, channel), domain in domains.items():
        if channel in ("rotation_quaternion", "rotation_axis_angle") and not domain.all():
            raise _Unsupported
        own = np.array(getattr(obj.pose.bones[bone], channel), dtype=np.float64)
        channels[bone, channel] = np.tile(np.where(domain, nla.DEFAULTS[channel], own), (count, 1))
    return channels


def _blend_layer(channels: dict[Channel, Array], curves: list[tuple[Any, Channel]], times: Array, blend_type: str,
                 weight: Array, plays: npt.NDArray[np.bool_]) -> None:
    """Blend one layer's curves, evaluated at `times` (one per frame where it plays: `plays` (N,)), into
    `channels` with influence `weight`."""
    rows = fcurve_values.evaluate_fcurves([fcurve for fcurve, _ in curves], times)  # (F, P)
    values: dict[Channel, Array] = {}
    keyed: dict[Channel, npt.NDArray[np.bool_]] = {}
    for (fcurve, key), row in zip(curves, rows, strict=True):
        size = channels[key].shape[1]
        if fcurve.array_index >= size:
            continue  # Blender evaluates no channel there
        values.setdefault(key, np.zeros((len(times), size)))[:, fcurve.array_index] = row
        keyed.setdefault(key, np.zeros(size, dtype=bool))[fcurve.array_index] = True
    for key, value in values.items():
        if blend_type == "COMBINE" and not nla.combinable(key[1], keyed[key]):
            raise _Unsupported
        channels[key][plays] = nla.blend(blend_type, key[1], channels[key][plays], value, weight, keyed[key])


def _basis(pose_bone: Any, channels: dict[Channel, Array], count: int) -> Array | None:
    """(N, 4, 4) the bone's basis matrix from its channels' values (the animation's where keyed), or None when
    nothing keys it, or its keys hold it where it stands (as Blender last evaluated it)."""
    name = pose_bone.name
    paths = ("location", "scale", action_adapter.rotation_path(pose_bone.rotation_mode))
    own = {path: np.array(getattr(pose_bone, path), dtype=np.float64) for path in paths}
    if all((channels[name, path] == own[path]).all() for path in paths if (name, path) in channels):
        return None  # keyed to stand as it stands on every frame: Blender's own pose of it holds
    value = {path: channels.get((name, path), np.broadcast_to(own[path], (count, len(own[path])))) for path in paths}
    basis = np.tile(np.eye(4), (count, 1, 1))
    basis[:, :3, :3] = rotation_matrices(pose_bone.rotation_mode, value[paths[2]]) * value["scale"][:, None, :]
    basis[:, :3, 3] = value["location"]
    return basis


def _forward(obj: Any, names: list[str], chain: dict[str, list[Copy]], channels: dict[Channel, Array],
             count: int) -> tuple[Array, Array, dict[str, Array]]:
    """(basis, pose, {bone: rotation channel values}) of the named bones (`sample`'s), by forward kinematics of
    the chain (parents, then constraints) from the channels' values."""
    bones, pose_bones = obj.data.bones, obj.pose.bones
    world = np.array(obj.matrix_world, dtype=np.float64)
    basis: dict[str, Array | None] = {}
    pose: dict[str, Array] = {}
    moving: set[str] = set()
    for name, copies in chain.items():
        bone, pose_bone = bones[name], pose_bones[name]
        keyed = basis[name] = _basis(pose_bone, channels, count)
        parent = bone.parent.name if bone.parent else None
        if keyed is None and parent not in moving and not moving.intersection(c[2] for c in copies):
            # as Blender last evaluated it, on every frame
            pose[name] = np.array(pose_bone.matrix, dtype=np.float64)[None]
            continue
        local = np.array(pose_bone.matrix_basis, dtype=np.float64)[None] if keyed is None else keyed
        if bone.use_connect:  # a connected bone's location does not move it
            local = np.array(local)
            local[:, :3, 3] = 0.0
        rest = np.array(bone.matrix_local, dtype=np.float64)
        offset = rest if parent is None else _rigid_inverse(np.array(bones[parent].matrix_local)) @ rest
        placed = np.broadcast_to(offset @ local, (count, 4, 4))
        pose[name] = placed if parent is None else np.broadcast_to(pose[parent], (count, 4, 4)) @ placed
        pose[name] = _constrained(pose[name], copies, pose, world, bone.use_connect)
        moving.add(name)
    return _outputs(obj, names, channels, basis, pose, count)


def _rigid_inverse(matrix: Array) -> Array:
    """The inverse of a (4, 4) rotation and translation (a bone's rest matrix)."""
    out = np.eye(4)
    out[:3, :3] = matrix[:3, :3].T
    out[:3, 3] = -matrix[:3, :3].T @ matrix[:3, 3]
    return out


def _constrained(own: Array, copies: list[Copy], pose: dict[str, Array], world: Array, connected: bool) -> Array:
    """(N, 4, 4) a bone's pose after its constraints (`copies`), solved as Blender solves them: each in its
    space, blended by its influence in world space; a connected bone keeps its head."""
    if not copies:
        return own
    head = own[:, :3, 3].copy()
    unworld = inverse(world)
    for kind, space, target, weight in copies:
        if weight <= 0.0:
            continue  # Blender skips it
        before = world @ own
        owner = before if space == "WORLD" else own
        followed = np.broadcast_to(pose[target], own.shape)
        followed = world @ followed if space == "WORLD" else followed
        if bone_constraints.unsupported(owner) or bone_constraints.unsupported(followed):
            raise _Unsupported
        after = bone_constraints.copy(kind, owner, followed)
        after = after if space == "WORLD" else world @ after
        if weight < 1.0:
            after = bone_constraints.interpolate(before, after, weight)
        own = unworld @ after
    if connected:
        own = np.array(own)
        own[:, :3, 3] = head
    return own


def _outputs(obj: Any, names: list[str], channels: dict[Channel, Array], basis: dict[str, Array | None],
             pose: dict[str, Array], count: int) -> tuple[Array, Array, dict[str, Array]]:
    """`sample`'s result: the named bones' basis and pose (N, B, 4, 4) and rotation channel values."""
    pose_bones = obj.pose.bones
    values, bases = {}, []
    for name in names:
        pose_bone = pose_bones[name]
        path = action_adapter.rotation_path(pose_bone.rotation_mode)
        own = np.array(getattr(pose_bone, path), dtype=np.float64)
        values[name] = channels.get((name, path), np.broadcast_to(own, (count, len(own))))
        keyed = basis[name]
        fixed = np.array(pose_bone.matrix_basis, dtype=np.float64)[None] if keyed is None else keyed
        bases.append(np.broadcast_to(fixed, (count, 4, 4)))
    poses = [np.broadcast_to(pose[name], (count, 4, 4)) for name in names]
    return np.stack(bases, axis=1), np.stack(poses, axis=1), values
