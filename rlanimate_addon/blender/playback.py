"""Frames played through Blender where numpy cannot evaluate them (blender/pose_underneath.py says where), and the
bake check's frames: the armatures evaluated, not the whole scene, each frame once.

`armature_only` switches off, while inside, the viewport evaluation of the modifiers of every object the
armatures do not depend on (a character's meshes deformed by them, other meshes), so that a frame played costs
the armature's evaluation, not the meshes' deformation; on leaving, even after an error, every modifier is as
it was. `play` reads, in one pass over the frames, every bone's matrices and rotation channels that a Generate
needs, and the target.
"""
import contextlib
from collections.abc import Callable, Iterable, Iterator, Sequence

import bpy
import numpy as np
import numpy.typing as npt

from . import action_adapter

Array = npt.NDArray[np.float64]


def _targets_of(holder) -> list:
    """The objects a constraint, a driver variable or a modifier reads."""
    found = [getattr(holder, name, None) for name in ("target", "pole_target", "object")]
    found += [t.target for t in getattr(holder, "targets", ())]
    return [obj for obj in found if isinstance(obj, bpy.types.Object)]


def _drivers_of(id_data) -> list:
    data = getattr(id_data, "animation_data", None)
    if data is None:
        return []
    return [t.id for d in data.drivers for v in d.driver.variables for t in v.targets
            if isinstance(t.id, bpy.types.Object)]


def needed(objects: Iterable[bpy.types.Object]) -> set:
    """The objects whose evaluation those given read: themselves, their parents, the targets of their
    constraints (bones' too), drivers and modifiers, and so on."""
    seen: set = set()
    stack = [obj for obj in objects if obj is not None]
    while stack:
        obj = stack.pop()
        if obj in seen:
            continue
        seen.add(obj)
        stack += [obj.parent] if obj.parent is not None else []
        holders = list(obj.constraints) + list(obj.modifiers)
        if obj.pose is not None:
            holders += [c for pose_bone in obj.pose.bones for c in pose_bone.constraints]
        stack += [target for holder in holders for target in _targets_of(holder)]
        stack += _drivers_of(obj) + _drivers_of(obj.data)
    return seen


@contextlib.contextmanager
def armature_only(view_layer: bpy.types.ViewLayer, objects: Iterable[bpy.types.Object],
                  switch: bool = True) -> Iterator[bool]:
    """While inside, the modifiers of the view layer's objects that `objects` do not depend on (`needed`) are
    off in the viewport (none without `switch`); as they were on leaving. Yields whether it switched any off
    (the caller then has the scene evaluated again once, the meshes deformed)."""
    keep = needed(objects) if switch else set()
    switched = [modifier for obj in view_layer.objects if switch and obj not in keep for modifier in obj.modifiers
                if modifier.show_viewport]
    for modifier in switched:
        modifier.show_viewport = False
    try:
        yield bool(switched)
    finally:
        for modifier in switched:
            modifier.show_viewport = True


class Played:
    """What `play` read at each frame: names' basis and pose (N, B, 4, 4) in armature space, {name: (N, C)}
    rotation channel values, (N, 3) targets, and {(bone, property): (N,)} custom properties."""

    def __init__(self, basis: Array, pose: Array, values: dict, targets: Array, properties: dict) -> None:
        self.basis, self.pose, self.values, self.targets, self.properties = basis, pose, values, targets, properties


def play(scene: bpy.types.Scene, obj: bpy.types.Object, names: Sequence[str], frames: Array, moving: bool,
         target: Callable[[], Array], properties: Sequence[tuple[str, str]] = ()) -> Played:
    """Played: the bones `names` of the armature, the target (`target()`, read at each frame) and the custom
    properties (bone, name) as Blender plays them at each frame (N,), each frame set once; when nothing moves,
    the first frame as it stands, broadcast. The caller restores the scene's frame."""
    pose_bones = [obj.pose.bones[name] for name in names]
    paths = [action_adapter.rotation_path(pose_bone.rotation_mode) for pose_bone in pose_bones]
    basis: list = []
    pose: list = []
    targets: list = []
    values: dict[str, list] = {name: [] for name in names}
    read: dict[tuple[str, str], list] = {key: [] for key in properties}
    for frame in (frames if moving else frames[:1]):
        if moving:
            scene.frame_set(int(frame))
        # Copied now: mathutils wraps the pose's own memory, which the next frame overwrites.
        basis.append(np.array([pose_bone.matrix_basis for pose_bone in pose_bones], dtype=np.float64))
        pose.append(np.array([pose_bone.matrix for pose_bone in pose_bones], dtype=np.float64))
        for pose_bone, path in zip(pose_bones, paths, strict=True):
            values[pose_bone.name].append(tuple(getattr(pose_bone, path)))
        targets.append(target())
        for bone, name in properties:
            read[bone, name].append(float(obj.pose.bones[bone][name]))
    count = len(frames)

    def spread(rows: list) -> Array:
        array = np.asarray(rows, dtype=np.float64)
        return np.broadcast_to(array, (count,) + array.shape[1:])
    return Played(spread(basis), spread(pose), {name: spread(rows) for name, rows in values.items()},
                  spread(targets), {key: spread(rows) for key, rows in read.items()})
