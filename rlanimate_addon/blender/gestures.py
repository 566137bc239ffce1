"""An armature's RLAnimate gestures: where each one's keys play, what it owns, its record, and whether the
animator edited it.

Design: how a gesture's keys are laid out (blender/key_layers.py writes them; how the pose underneath is read
is blender/armature_io.py's and pose_underneath.py's business, not this):
  * its main action keys its arm (collar to fingers, Point's hand shape), a target behaviour's eyes and,
    made on a still rig, the other arm (from its natural standing pose), as a Replace or Combine layer (the
    Layer setting);
  * its torso action keys the turn it gives the spine, neck and head, always as a Combine layer of its own, so
    gestures on both arms at once add their turns and each one's arm plays as it did alone;
  * a gesture made on a still rig (nothing animated the character) is the rig's base: its main action is the
    active action, and from the next gesture on a HOLD strip at the bottom of the NLA, holding the standing
    pose it starts and ends in before and after it. Every other main action, and every torso action, plays
    on an NLA track of its own, a strip with no effect outside the gesture's frames;
  * the main action's custom property RECORD holds the record (`record`), the torso action's TORSO_OF the id
    of its gesture. The record lists the F-curves the gesture wrote and keeps their keys: any other F-curve in
    its actions is someone else's (Blender keys the animator's keys into the active action, a base's) and is
    never rewritten or deleted, and a key of its own that differs from what it wrote was edited (`edited`).
"""
import contextlib
import re
import time

import bpy
import numpy as np

from ..core import composition
from ..core.behaviours import KNOWN_KINDS, TARGET
from ..core.gesture import slerp
from ..core.rotations import quat_multiply
from . import action_adapter, fcurve_values

#: The custom property of a gesture's main action that holds its record.
RECORD = "rlanimate_gesture"
#: The custom property of a gesture's torso action: the id of its gesture.
TORSO_OF = "rlanimate_torso_of"
#: A gesture's layers: its main action and its torso action.
MAIN, TORSO = "main", "torso"
_BONE = re.compile(r'^pose\.bones\["((?:[^"\\]|\\.)*)"\]')


class Layer:
    """One of a gesture's actions where it plays: the active action (track None) or an NLA track's strip."""

    def __init__(self, target, track=None):
        self.target, self.track = target, track

    @property
    def action(self):
        return self.target.action

    @property
    def strip(self):
        return self.track.strips[0] if self.track is not None and len(self.track.strips) else None


class Placed:
    """A gesture as it plays on an armature: its layers, its record and its place in the layer stack (level 0
    at the bottom; the active action above every NLA track)."""

    def __init__(self, obj, main, torso, level):
        self.obj, self.main, self.torso, self.level = obj, main, torso, level

    @property
    def action(self):
        return self.main.action

    @property
    def record(self):
        return self.action[RECORD]

    @property
    def name(self):
        """The gesture's name, its main action's: how the panel's list and the selection name it."""
        return self.action.name

    @property
    def layers(self):
        """{layer name: Layer} of the layers the gesture has."""
        return {name: layer for name, layer in ((MAIN, self.main), (TORSO, self.torso)) if layer is not None}

    @property
    def still(self):
        """Whether it was made on a still rig: the base, holding the standing pose and keying the other arm."""
        return not self.record.get("animated", True)

    @property
    def span(self):
        record = self.record
        kind = record.get("kind", KNOWN_KINDS.get(record["behaviour"]))
        trim = record.get("trim")
        return composition.Span(self.name, record["arm"], int(record["start"]), int(record["end"]),
                                target=kind == TARGET, still=self.still,
                                layered=bool(record["settings"].get("keep_previous", False)), level=self.level,
                                cut=None if trim is None else int(trim["at"]))

    def memory(self, layer, expected=True):
        """The KeyMemory of the keys the gesture wrote into a layer (as trimmed, when `expected`), or None for a
        record made before gestures kept them."""
        kept = self.record.get("layers", {}).get(layer)
        if kept is None:
            return None
        return action_adapter.KeyMemory.unpack(kept["trimmed"] if expected and "trimmed" in kept else kept)

    def owned(self, layer):
        """The F-curves of a layer that the gesture wrote (all of them for a record made before gestures
        listed theirs)."""
        target = self.layers[layer].target
        kept = self.record.get("layers", {}).get(layer)
        if kept is None:
            return target.fcurves() if layer == MAIN else []
        curves = (target.find(path, index) for path, index in zip(kept["paths"], kept["indices"], strict=True))
        return [fcurve for fcurve in curves if fcurve is not None]

    def other_arm_curves(self):
        """(data path, index) of the main layer's curves that key the other arm (a base's)."""
        kept = self.record.get("layers", {}).get(MAIN)
        if kept is None:
            return set()
        return {(path, index) for path, index, other in zip(kept["paths"], kept["indices"], kept["other"], strict=True)
                if other}


def bone_of(data_path):
    """The bone a pose channel's data path names, or None."""
    match = _BONE.match(data_path)
    return None if match is None else bpy.utils.unescape_identifier(match.group(1))


def placed_gestures(obj):
    """The armature's recorded gestures as Placed, bottom of the layer stack first (the active action last)."""
    data = obj.animation_data
    if data is None:
        return []
    mains, torsos = [], {}
    for level, track in enumerate(data.nla_tracks):
        for strip in track.strips:
            action = strip.action
            if action is not None and RECORD in action:
                mains.append((level, Layer(action_adapter.strip_target(strip), track)))
            elif action is not None and TORSO_OF in action:
                torsos[action[TORSO_OF]] = Layer(action_adapter.strip_target(strip), track)
    active = action_adapter.active_target(obj)
    if active is not None and RECORD in active.action:
        mains.append((len(data.nla_tracks), Layer(active)))
    return [Placed(obj, layer, torsos.get(layer.action[RECORD].get("id", -1)), level) for level, layer in mains]


def find(obj, name):
    """The armature's gesture called `name` (its main action's name), or None."""
    return next((g for g in placed_gestures(obj) if g.name == name), None)


def selected(obj):
    """The name of the armature's gesture selected in the panel's list, which Generate bakes again; "" when
    none is (or it is gone)."""
    name = obj.rlanimate.gesture
    return name if name and find(obj, name) is not None else ""


def renamed(obj, old, new):
    """Keep the panel's selection on a gesture whose main action was renamed from `old` to `new`."""
    if old and obj.rlanimate.gesture == old:
        obj.rlanimate.gesture = new


def in_timeline_order(obj):
    """The armature's gestures by start frame (then stack level)."""
    return sorted(placed_gestures(obj), key=lambda g: (int(g.record["start"]), g.level))


def last_targeted(obj):
    """The armature's topmost gesture of a target behaviour (Point), or None."""
    return next((g for g in reversed(placed_gestures(obj)) if g.span.target), None)


def next_id(obj):
    """An id for a new gesture of the armature: above every id its gestures have."""
    return 1 + max((int(g.record.get("id", 0)) for g in placed_gestures(obj)), default=0)


@contextlib.contextmanager
def detached(placed, view_layer):
    """While inside, the armature plays without the gestures `placed`: the F-curves they wrote are muted (keys
    others put in their actions keep playing), and bones that stood still beneath them are put back where
    they stood (and stay there: the gesture replacing one may key fewer bones). As they were on leaving; after
    an error the pose is as it was, too."""
    muted = [(fcurve, fcurve.mute) for gesture in placed for layer in gesture.layers
             for fcurve in gesture.owned(layer)]
    for fcurve, _ in muted:
        fcurve.mute = True
    standing = {}
    for gesture in placed:
        for bone, values in gesture.record.get("under", {}).items():
            pose_bone = gesture.obj.pose.bones.get(bone)
            if pose_bone is not None:
                path = action_adapter.rotation_path(pose_bone.rotation_mode)
                standing.setdefault((pose_bone, path), tuple(getattr(pose_bone, path)))
                setattr(pose_bone, path, list(values))
    view_layer.update()
    try:
        yield
    except BaseException:
        for (pose_bone, path), values in standing.items():
            setattr(pose_bone, path, values)
        raise
    finally:
        for fcurve, state in muted:
            fcurve.mute = state


def _influence(strip, frames):
    """(N,) the influence of an NLA strip at scene frames: 1 over it, ramped over its blend in and out, 0 outside
    (no extrapolation: the strips of gestures' torso layers)."""
    start, end = strip.frame_start, strip.frame_end
    rise = (frames - start) / strip.blend_in if strip.blend_in > 0 else np.ones(len(frames))
    fall = (end - frames) / strip.blend_out if strip.blend_out > 0 else np.ones(len(frames))
    return np.where((frames >= start) & (frames <= end), np.clip(np.minimum(rise, fall), 0.0, 1.0), 0.0)


def torso_layers(obj, values, frames, above=None):
    """(bare, turns above): the bones of `values` ({bone: (N, C) rotation channel values as the armature plays at
    frames (N,)}) that gestures' torso layers turn, as the animation without those layers plays them ({bone: (N,
    C)}), and, of quaternion bones, the turn of the layers above the track `above` (a gesture's own torso track;
    None: above every layer) ({bone: (N, 4)}). A Combine layer multiplies a quaternion key in by its influence, in
    the order of the stack, and adds an Euler or axis-angle one (core/channels.py); muted curves (a gesture set
    aside while it is baked again) add nothing."""
    frames = np.asarray(frames, dtype=np.float64)
    identity = np.tile([1.0, 0.0, 0.0, 0.0], (len(frames), 1))
    below, over = {}, {}  # {bone: (N, C) the layers' turns, composed in stack order}
    tracks = list(obj.animation_data.nla_tracks) if obj.animation_data is not None else []
    level = None if above is None else tracks.index(above)
    for gesture in placed_gestures(obj):  # bottom first
        layer = gesture.torso
        strip = None if layer is None or layer.track.mute else layer.strip
        curves = [] if strip is None or strip.mute else [f for f in gesture.owned(TORSO)
                                                          if not f.mute and bone_of(f.data_path) in values]
        influence = _influence(strip, frames) if curves else np.zeros(len(frames))
        if not influence.any():
            continue
        keys = {}
        for fcurve, row in zip(curves, fcurve_values.evaluate_fcurves(curves, frames), strict=True):
            bone = bone_of(fcurve.data_path)
            keys.setdefault(bone, np.zeros_like(values[bone]))[:, fcurve.array_index] = row
        added = over if level is not None and tracks.index(layer.track) > level else below
        for bone, key in keys.items():
            if obj.pose.bones[bone].rotation_mode == "QUATERNION":
                added[bone] = quat_multiply(added.get(bone, identity), slerp(identity, key, influence))
            else:
                added[bone] = added.get(bone, 0.0) + key * influence[:, None]
    conjugate = np.array([1.0, -1.0, -1.0, -1.0])
    bare = {}
    for bone in below.keys() | over.keys():
        if obj.pose.bones[bone].rotation_mode == "QUATERNION":
            turn = quat_multiply(below.get(bone, identity), over.get(bone, identity))
            bare[bone] = quat_multiply(values[bone], turn * conjugate)
        else:
            bare[bone] = values[bone] - below.get(bone, 0.0) - over.get(bone, 0.0)
    return bare, over


def animator_bones(obj):
    """(whether anything but RLAnimate gestures animates the armature, the names of the bones it animates): F-curves
    of its other actions and strips, keys others put in gestures' actions, and drivers."""
    data = obj.animation_data
    if data is None:
        return False, set()
    gestures = placed_gestures(obj)
    own = {g.layers[layer].action.as_pointer(): {(f.data_path, f.array_index) for f in g.owned(layer)}
           for g in gestures for layer in g.layers}
    targets = action_adapter.strip_targets(obj) + [t for t in [action_adapter.active_target(obj)] if t is not None]
    paths = [f.data_path for t in targets for f in t.fcurves()
             if (f.data_path, f.array_index) not in own.get(t.action.as_pointer(), ())]
    paths += [d.data_path for d in data.drivers]
    return bool(paths), {bone_of(path) for path in paths} - {None}


def record(action, fields, memories, other_arm=()):
    """Write the action's record: `fields` ({"id", "behaviour", "kind", "arm", "start", "end", "settings" (a
    mapping of Scene.rlanimate's names to values), "under" ({bone: channel values} of bones that stand still
    underneath), "aimed_at" ((N, 3) armature-space targets per frame, or None), "influence_before" ({influence
    path: {frame: value}} of the constraints it muted, before it muted them: constraints.mute), "animated"
    (baked over animation, not on a still rig)}), and the keys written ({layer: KeyMemory}; other_arm: the
    (data path, index) of curves that key the other arm)."""
    layers = {}
    for name, memory in memories.items():
        layers[name] = memory.pack()
        layers[name]["other"] = [(path, index) in other_arm for path, index, *_ in memory.curves]
    action[RECORD] = {
        "id": int(fields["id"]), "behaviour": fields["behaviour"], "kind": fields["kind"], "arm": fields["arm"],
        "start": int(fields["start"]), "end": int(fields["end"]), "settings": fields["settings"],
        "under": {bone: list(map(float, values)) for bone, values in fields["under"].items()},
        "aimed_at": ([] if fields["aimed_at"] is None
                     else np.asarray(fields["aimed_at"], dtype=np.float64).ravel().tolist()),
        "note": "", "animated": bool(fields["animated"]), "layers": layers,
        "influence_before": [{"path": path, "frames": [int(f) for f in prior],
                              "values": [float(v) for v in prior.values()]}
                             for path, prior in (fields["influence_before"] or {}).items()]}


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


def edited(gesture):
    """{(data path, index): frames} of the keys the gesture wrote that differ now: edited by hand (a moved
    Bezier handle counts); {} when none (and for a record made before gestures kept their keys)."""
    found = {}
    for layer in gesture.layers:
        memory = gesture.memory(layer)
        if memory is None:
            continue
        target = gesture.layers[layer].target
        for path, index, co, interpolation, handles in memory.curves:
            fcurve = target.find(path, index)
            frames = action_adapter.changed_frames((co, interpolation, handles),
                                                   None if fcurve is None else action_adapter.read_keys(fcurve))
            if frames:
                found[path, index] = frames
    return found


_edited_cache: dict[int, tuple[float, bool]] = {}
#: Seconds the panel's "edited" mark of a gesture is reused before its keys are read again.
EDITED_CACHE_SECONDS = 1.0


def edited_lately(gesture):
    """Whether the gesture was edited by hand (`edited`), read at most once a second per gesture: the panel
    asks on every redraw."""
    key = gesture.action.as_pointer()
    now = time.monotonic()
    cached = _edited_cache.get(key)
    if cached is None or now - cached[0] > EDITED_CACHE_SECONDS:
        cached = _edited_cache[key] = (now, bool(edited(gesture)))
    return cached[1]


def describe_edits(found, named=3):
    """'mixamorig:RightForeArm (frames 40-52), mixamorig:RightHand (frame 60)' of `edited`'s result: the
    first `named` bones, then a count."""
    frames = {}
    for (path, _), changed in found.items():
        frames.setdefault(bone_of(path) or path, set()).update(changed)
    parts = [f"{bone} ({_frame_ranges(sorted(f))})" for bone, f in list(frames.items())[:named]]
    more = f" and {len(frames) - named} more bones" if len(frames) > named else ""
    return ", ".join(parts) + more


def _frame_ranges(frames):
    runs, first = [], frames[0]
    for previous, frame in zip(frames, frames[1:] + [None], strict=True):
        if frame != previous + 1:
            runs.append(f"{first}" if first == previous else f"{first}-{previous}")
            first = frame
    return ("frame " if len(frames) == 1 else "frames ") + ", ".join(runs)


def snapshot(settings):
    """{name: value} of every setting of a Scene.rlanimate group, or of a recorded one baked again (a
    namespace), that has one (the target as the object itself; no target, none)."""
    if not hasattr(settings, "bl_rna"):
        values = vars(settings)
    else:
        values = {p.identifier: getattr(settings, p.identifier) for p in settings.bl_rna.properties
                  if p.identifier != "rna_type"}
    return {name: value for name, value in values.items() if value is not None}
