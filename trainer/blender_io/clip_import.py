"""Motion-clip import: FBX and BVH through Blender's own importers, brought onto the canonical rig.

    import_clip(path)                       -> MotionClip (raises RLAnimateError naming file and fix)
    import_clip_directory(dir_or_manifest)  -> (clips, problems): goes on past bad files
    load_clip_set(manifest_path)            -> ClipSet with the manifest's labels and split

A clip's `rotvecs` (F, 15, 3) are local rotations of skeleton.ACTION_JOINTS relative to the canonical
rest frames (the action space before its [0, 1] mapping); `fingers` holds the other hand bones when the
source has them. Bone names go through core.bone_maps (Mixamo with any `prefix:`, Bandai Namco);
trainer/motion/canonicalise.py turns the source's world bone frames into canonical local rotations.
Imported clips are cached (trainer/motion/clip_cache.py) in a git-ignored `.import_cache/` beside the
clips; manifests are read by trainer/motion/manifest.py. The clips of a library (import_clip_directory)
that the cache lacks are imported by worker processes (trainer/blender_io/import_worker.py), `workers` at
once, each clip under a memory cap and a time limit, into the cache (a temporary one when there is none, or
it cannot be written), and then read from it: the same clips however many workers import them, and a file
that would take the machine's memory or hang is skipped with a note.
"""
import io
import sys
import tempfile
from contextlib import contextmanager, nullcontext, redirect_stderr
from dataclasses import replace
from pathlib import Path
from typing import IO

import numpy as np
from tqdm import tqdm

from rlanimate_addon.core import bone_maps, frame_rate, rotations, skeleton
from rlanimate_addon.core.errors import RLAnimateError, operator_error_reason
from trainer.blender_io import import_worker, rig_session
from trainer.blender_io.import_worker import ImportLimits
from trainer.motion import canonicalise, clip_cache
from trainer.motion.clip import ClipSet, MotionClip
from trainer.motion.hands import with_hand
from trainer.motion.manifest import ManifestEntry, checked_entries, labelled, read_manifest

#: The frame rate a clip is read at when neither the call nor the manifest gives one: the agent's.
EXPECTED_FPS = frame_rate.AGENT_FPS
CLIP_SUFFIXES = (".fbx", ".bvh")
_FINGER_BONES = tuple(b.name for b in skeleton.BONES
                      if "Hand" in b.name and b.name not in skeleton.ACTION_JOINTS)


@contextmanager
def _importer_output():
    """Send what an importer prints through Python (its traceback when it fails) where Blender's own prints
    go, file descriptor 2: held back by rig_session.blender_output unless --verbose, as its C-level output is.
    The RLAnimateError raised for the failure names the reason."""
    stream = sys.__stderr__ or io.StringIO()
    try:
        with redirect_stderr(stream):
            yield
    finally:
        stream.flush()


class FrameRateMismatch(RLAnimateError):
    """A clip whose frame rate is not the expected one (import_clip_directory names the manifest that expects it)."""

    def __init__(self, path, fps, expected):
        super().__init__(f"{path}: the clip runs at {round(fps, 2):g} fps, but {expected:g} fps is expected. "
                         f"Re-export or resample it at {expected:g} fps.")
        self.path, self.fps, self.expected = path, fps, expected


def _import_file(bpy, path):
    """Run Blender's importer on `path`; return the armature objects it created."""
    before = set(bpy.data.objects)
    suffix = path.suffix.lower()
    try:
        with _importer_output():
            if suffix == ".fbx":
                bpy.ops.import_scene.fbx(filepath=str(path), use_anim=True)
            else:
                bpy.ops.import_anim.bvh(filepath=str(path), update_scene_fps=True, update_scene_duration=False)
    except (RuntimeError, ValueError, IndexError) as error:
        raise RLAnimateError(f"{path}: the file is corrupt or not a valid {suffix[1:].upper()} file "
                             f"({operator_error_reason(error)}). Re-export it from your animation tool.") from error
    return [o for o in bpy.data.objects if o not in before and o.type == "ARMATURE"]


class _SceneSnapshot:
    """Removes the datablocks an import adds and restores the scene settings it changes."""

    _COLLECTIONS = ("objects", "meshes", "armatures", "actions", "materials", "images", "textures",
                    "cameras", "lights", "collections")

    def __init__(self, bpy):
        self.bpy = bpy
        self.scene = bpy.context.scene
        self.before = {name: set(getattr(bpy.data, name)) for name in self._COLLECTIONS}
        render = self.scene.render
        self.settings = (render.fps, render.fps_base, self.scene.frame_start, self.scene.frame_end,
                         self.scene.frame_current)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        new = [block for name in self._COLLECTIONS for block in getattr(self.bpy.data, name)
               if block not in self.before[name]]
        if new:
            self.bpy.data.batch_remove(new)
        render = self.scene.render
        render.fps, render.fps_base, self.scene.frame_start, self.scene.frame_end, current = self.settings
        self.scene.frame_set(current)
        return False


def _orthonormal(matrices):
    """(..., 3, 3) -> the nearest rotations (removes scale and rounding)."""
    u, _, vt = np.linalg.svd(matrices)
    return u @ vt


def _matrices(collection, attribute):
    """(B, 4, 4) of a bone collection's matrix attribute ('matrix' of pose bones, 'matrix_local' of bones)."""
    flat = np.zeros(len(collection) * 16, dtype=np.float64)
    collection.foreach_get(attribute, flat)
    return flat.reshape(-1, 4, 4).transpose(0, 2, 1)  # Blender hands matrices over column-major


def _tail_children():
    """{canonical bone: the canonical child whose head is its tail} (e.g. Hand -> HandMiddle1)."""
    result = {}
    for bone in skeleton.BONES:
        for child in skeleton.BONES:
            if child.parent == bone.name and np.allclose(child.head, bone.tail, atol=1e-6):
                result[bone.name] = child.name
    return result


_TAIL_CHILD = _tail_children()


def _alignments(canonical, bones, rest):
    """(K, 3, 3) per mapped bone, in its own rest frame, turning its Y axis onto the direction the
    canonical bone means: towards the head of the child its canonical tail touches when the source has
    it (Blender's BVH importer aims a bone with several children between them).

    Otherwise identity, except for a leaf bone shorter than a tenth of its parent: Blender's BVH
    importer gives a joint whose End Site has zero length an arbitrary tail, so such a bone continues
    its parent's rest direction (in the Bandai Namco zero pose every joint lies on its parent's line).
    """
    index = {name: k for k, name in enumerate(canonical)}
    result = np.tile(np.eye(3), (len(bones), 1, 1))
    for k, (name, bone) in enumerate(zip(canonical, bones, strict=True)):
        frame = rest[k, :3, :3]
        child = _TAIL_CHILD.get(name)
        if child in index:
            direction = rest[index[child], :3, 3] - rest[k, :3, 3]
        elif bone.parent is not None and not bone.children and bone.length < 0.1 * bone.parent.length:
            direction = np.asarray(bone.parent.matrix_local, dtype=np.float64)[:3, 1]
        else:
            continue
        result[k] = frame.T @ canonicalise.swing(frame[:, 1], direction) @ frame
    return result


def _clip_fps(scene):
    return scene.render.fps / scene.render.fps_base


def _check_bvh_numbers(path):
    """Raise RLAnimateError for NaN or infinite values in a BVH's motion data.

    Blender's BVH importer turns a NaN rotation into the rest pose without a word, so the text is read."""
    _, found, motion = path.read_text(errors="replace").partition("MOTION")
    if not found:
        return  # not a BVH with motion: the importer says what is wrong
    bad, kinds = [], set()
    for frame, line in enumerate(motion.strip().splitlines()[2:], start=1):  # after Frames: and Frame Time:
        try:
            values = np.array(line.split(), dtype=np.float64)
        except ValueError:
            continue  # not numbers: the importer reports it
        if not np.all(np.isfinite(values)):
            bad.append(frame)
            kinds |= _non_finite_kinds(values)
    if bad:
        raise RLAnimateError(f"{path}: {' and '.join(sorted(kinds))} values in the motion data at frames {bad[:10]}"
                             f"{' and more' if len(bad) > 10 else ''}. Fix or re-export the clip.")


def _non_finite_kinds(values):
    """{'NaN', 'infinite'}, or the one of them, that the array `values` holds: a message calls inf infinite."""
    return {word for word, test in (("NaN", np.isnan), ("infinite", np.isinf)) if np.any(test(values))}


def _action_fcurves(action):
    """Every F-curve of `action`: Action.fcurves on Blender 4.2, slots' channelbags on 5.0 (layered actions)."""
    if hasattr(action, "fcurves"):
        return list(action.fcurves)
    return [curve for layer in action.layers for strip in layer.strips
            for bag in strip.channelbags for curve in bag.fcurves]


def _check_finite_keys(action, path):
    """Raise RLAnimateError naming the channels and frames whose keyframes are NaN or infinite.

    Blender's pose evaluation hides NaN keys (a NaN rotation evaluates as rest), so the keys are read."""
    bad, kinds = {}, set()
    for curve in _action_fcurves(action):
        points = np.zeros(len(curve.keyframe_points) * 2)
        curve.keyframe_points.foreach_get("co", points)
        points = points.reshape(-1, 2)
        broken = ~np.all(np.isfinite(points), axis=1)
        if np.any(broken):
            kinds |= _non_finite_kinds(points[broken])
            frames = bad.setdefault(curve.data_path, set())
            frames.update(int(f) if np.isfinite(f) else -1 for f in points[broken, 0])
    if bad:
        channels = "; ".join(f"{name} at frames {sorted(frames)[:5]}" for name, frames in sorted(bad.items())[:5])
        raise RLAnimateError(f"{path}: {' and '.join(sorted(kinds))} values in the animation ({channels}). Fix or "
                             "re-export the clip.")


def _frame_range(obj, path):
    action = obj.animation_data.action if obj.animation_data else None
    if action is None:
        raise RLAnimateError(f"{path}: the armature {obj.name!r} has no animation. Export the clip "
                             "with its animation baked (FBX: 'Bake Animation' on).")
    _check_finite_keys(action, path)
    start, end = (int(round(v)) for v in action.frame_range)
    if end - start < 1:
        raise RLAnimateError(f"{path}: the animation has only one frame. Export the whole clip, "
                             "at least 2 frames.")
    return range(start, end + 1)


def _read_armature(bpy, obj, bone_map, frames):
    """The mapped bones' world motion over `frames`: (canonical names, frames (F, K, 3, 3),
    calibration frames (K, 3, 3), calibration heads (K, 3)). A frame's Y axis is the bone's direction."""
    names = [b.name for b in obj.data.bones]
    matched = bone_maps.match_bones(names, bone_map)  # {canonical: source name}
    canonical = list(matched)
    order = [names.index(matched[c]) for c in canonical]
    scene = bpy.context.scene
    pose = np.empty((len(frames), len(canonical), 4, 4))
    for k, frame in enumerate(frames):
        scene.frame_set(frame)
        pose[k] = _matrices(obj.pose.bones, "matrix")[order]
    object_matrix = np.asarray(obj.matrix_world, dtype=np.float64)
    object_rotation = _orthonormal(object_matrix[:3, :3])
    rest = _matrices(obj.data.bones, "matrix_local")[order]  # (K, 4, 4) armature space
    rest[:, :3, :3] = _orthonormal(rest[:, :3, :3])
    align = _alignments(canonical, [obj.data.bones[i] for i in order], rest)

    def world(matrices):  # (..., K, 4, 4) armature space -> frames (..., K, 3, 3), heads (..., K, 3)
        heads = matrices[..., :3, 3] @ object_matrix[:3, :3].T + object_matrix[:3, 3]
        return object_rotation @ _orthonormal(matrices[..., :3, :3]) @ align, heads

    calibration_frames, calibration_heads = world(rest) if bone_map.calibration == "rest" else world(pose[0])
    return canonical, world(pose)[0], calibration_frames, calibration_heads


def _to_canonical(canonical, frames, calibration_frames, calibration_heads, bone_map):
    """(rotvecs (F, 15, 3), fingers {bone: (F, 3)}) from the source's world motion (_read_armature)."""
    index = {name: i for i, name in enumerate(canonical)}
    source_calibration = {name: calibration_frames[i] for name, i in index.items()}
    if (bone_map.calibration == "rest" and "Hips" in index
            and canonicalise.carries_canonical_axes(source_calibration,
                                                    {n: calibration_heads[i] for n, i in index.items()})):
        # The bones carry the canonical axes (a rig built from core.skeleton, like the sample
        # character): their world frames are canonical frames whatever the file's rest, and the hips
        # give the facing. That matters because an FBX without a skinned mesh has no bind pose, and
        # Blender's importer then takes the pose at export time as the rest, which need not be a T-pose.
        facing = canonicalise.canonical_rest_frame("Hips") @ source_calibration["Hips"].T
        calibration = {name: canonicalise.canonical_rest_frame(name) for name in index}
    else:
        landmarks = ("Hips" if "Hips" in index else "Spine", "Head", "LeftArm", "RightArm")
        facing = canonicalise.source_to_character_frame(*(calibration_heads[index[name]] for name in landmarks))
        calibration = {name: facing @ frame for name, frame in source_calibration.items()}
    bases = canonicalise.local_rotations({name: facing @ frames[:, i] for name, i in index.items()},
                                         calibration, bone_map.shared_bend)
    fingers = {name: rotations.matrix_to_rotvec(bases[name]) for name in _FINGER_BONES if name in index}
    return canonicalise.action_rotvecs(bases), fingers


def _check_file(path: Path) -> None:
    """RLAnimateError for a clip path that is no file, not FBX or BVH, or empty."""
    if not path.is_file():
        raise RLAnimateError(f"{path}: no such file. Check the path or the manifest entry.")
    if path.suffix.lower() not in CLIP_SUFFIXES:
        raise RLAnimateError(f"{path}: unsupported file type {path.suffix!r}. Export clips as FBX or BVH.")
    if path.stat().st_size == 0:
        raise RLAnimateError(f"{path}: the file is empty. Re-export the clip.")


def _import_uncached(path, expected_fps, bone_map):
    bpy = rig_session.import_bpy()
    _check_file(path)
    if path.suffix.lower() == ".bvh":
        _check_bvh_numbers(path)
    with _SceneSnapshot(bpy):
        armatures = _import_file(bpy, path)
        if not armatures:
            raise RLAnimateError(f"{path}: the file has no armature. Export the character's skeleton "
                                 "with the animation.")
        names_of = {o: [b.name for b in o.data.bones] for o in armatures}
        obj = max(armatures, key=lambda o: len(bone_maps.match_bones(names_of[o], bone_map
                                                                      or bone_maps.best_bone_map(names_of[o]))))
        chosen_map = bone_map or bone_maps.best_bone_map(names_of[obj])
        missing = bone_maps.missing_bones(names_of[obj], chosen_map)
        if missing:
            raise RLAnimateError(f"{path}: the {chosen_map.name} armature {obj.name!r} lacks the bones "
                                 f"{', '.join(missing)}. Export a skeleton that has them, or add a bone "
                                 "map for this skeleton to rlanimate_addon/core/bone_maps.py.")
        frames = _frame_range(obj, path)  # no animation is the problem to report, whatever the frame rate
        fps = _clip_fps(bpy.context.scene)
        if abs(fps - expected_fps) > 1e-3:
            raise FrameRateMismatch(path, fps, expected_fps)
        motion = _read_armature(bpy, obj, chosen_map, frames)
    rotvecs, fingers = _to_canonical(*motion, chosen_map)
    return MotionClip(name=path.stem, source=str(path), fps=float(fps), rotvecs=rotvecs, fingers=fingers)


def import_clip(path, expected_fps=EXPECTED_FPS, bone_map=None, cache_dir=None):
    """Import one FBX or BVH clip as a MotionClip (no labels).

    bone_map: a core.bone_maps.BoneMap, or None to pick the one that recognises the most bones.
    cache_dir: where to keep imported clips as .npz keyed by the file's hash (None: no cache).
    Raises RLAnimateError naming the file, the problem and the fix.
    """
    path = Path(path)
    if cache_dir is None or not path.is_file():
        return _import_uncached(path, float(expected_fps), bone_map)
    cache_file = _cache_file(path, expected_fps, bone_map, cache_dir)
    cached = _read_cache(cache_file, path)
    if cached is not None:
        return cached
    clip = _import_uncached(path, float(expected_fps), bone_map)
    try:
        clip_cache.save_cached(cache_file, clip)
    except OSError as error:  # a read-only clip folder: import without caching
        tqdm.write(f"clip_import: not caching {path.name}: {error}", file=sys.stderr)
    return clip


def _cache_file(path, expected_fps, bone_map, cache_dir):
    map_tag = "auto" if bone_map is None else bone_map.name.replace(" ", "_")
    return Path(cache_dir) / f"{clip_cache.file_hash(path)}_{map_tag}_{float(expected_fps):g}.npz"


def _read_cache(cache_file: Path, path: Path) -> MotionClip | None:
    """The clip of `path` cached in `cache_file`, or None when there is none or it is damaged (then said, so
    that it is imported again and overwritten)."""
    if cache_file.is_file():
        try:
            return clip_cache.load_cached(cache_file, path)
        except RLAnimateError as error:
            tqdm.write(f"clip_import: {error} Importing {path.name} again.", file=sys.stderr)  # above the bar
    return None


def import_into_cache_file(path: Path, fps: float, cache_dir: Path) -> None:
    """Import the clip at `path` afresh (the bone map its bone names pick) into the cache folder `cache_dir`:
    what an import worker does (trainer/blender_io/import_worker.py)."""
    clip = _import_uncached(Path(path), float(fps), None)
    try:
        clip_cache.save_cached(_cache_file(Path(path), fps, None, cache_dir), clip)
    except OSError as error:
        raise RLAnimateError(f"{path}: cannot write its import cache entry in {cache_dir} ({error}).") from error


def import_clip_directory(path_or_manifest, expected_fps=None, cache_dir=None, progress=None, workers=1,
                          limits=None):
    """Import every clip of a directory (its manifest.json when it has one, else every .fbx/.bvh) or
    of a manifest file. Returns (clips, problems): the clips that imported, and one message per file
    that did not. Clips listed in a manifest carry its labels; a clip without finger data gets the relaxed hand
    (motion/hands.py). cache_dir: where imported clips are
    cached (default: `.import_cache/` beside a manifest; no cache for a folder without one, so that
    shared data folders stay untouched); False imports afresh without caching. progress: a stream to
    show a progress bar on (None: no bar). The files the cache lacks are imported by `workers` import
    workers at once, each clip within `limits` (an ImportLimits; None: the default 2 GB and 60 s)."""
    path = Path(path_or_manifest)
    manifest_path = path / "manifest.json" if path.is_dir() and (path / "manifest.json").is_file() else path
    if manifest_path.is_file() and manifest_path.suffix.lower() == ".json":
        manifest = read_manifest(manifest_path)
        folder = manifest_path.parent
        default_fps = float(expected_fps or manifest.get("fps") or EXPECTED_FPS)
        entries, problems = checked_entries(manifest, manifest_path, default_fps)
    elif path.is_dir():
        folder, manifest_path, problems = path, None, []
        entries = [ManifestEntry(k, p.name, behaviour=None, kind=None, arm=None,
                                 fps=float(expected_fps or EXPECTED_FPS))
                   for k, p in enumerate(sorted(path.iterdir()), start=1) if p.suffix.lower() in CLIP_SUFFIXES]
    else:
        raise _no_library(path)
    if cache_dir is None:  # cache beside a manifest's clips; never write into a plain folder such as
        cache_dir = folder / clip_cache.CACHE_DIR_NAME if manifest_path is not None else False  # ../shared/realmocap
    imported = _import_files([(folder / entry.file, entry.fps) for entry in entries],
                             Path(cache_dir) if cache_dir else None, workers, limits or ImportLimits(), progress)
    clips = []
    for entry in entries:
        try:
            clip = imported[folder / entry.file, entry.fps]
            if isinstance(clip, RLAnimateError):
                raise clip
            clip = with_hand(clip)  # a new clip when it gets the relaxed hand
            if manifest_path is not None:  # a copy: two entries may name one file
                clip = labelled(replace(clip), entry, manifest_path)
            clips.append(clip)
        except FrameRateMismatch as error:
            problems.append(str(error) if manifest_path is None else _manifest_fps_problem(error, entry, manifest,
                                                                                            manifest_path))
        except RLAnimateError as error:
            problems.append(str(error))
    return clips, problems


def _import_files(files: list[tuple[Path, float]], cache: Path | None, workers: int, limits: ImportLimits,
                  progress: IO | None) -> dict[tuple[Path, float], MotionClip | RLAnimateError]:
    """{(path, fps): its MotionClip, or the RLAnimateError of its file}, read from the cache folder `cache`
    (None, or one that cannot be written: a temporary folder), the clips it lacks imported into it by
    import workers first."""
    results: dict[tuple[Path, float], MotionClip | RLAnimateError] = {}
    with nullcontext(str(cache)) if _writable(cache) else tempfile.TemporaryDirectory() as folder:
        store = Path(folder)
        missing: dict[tuple[Path, float], Path] = {}  # the files the cache lacks: their cache file
        for path, fps in dict.fromkeys((Path(path), float(fps)) for path, fps in files):
            try:
                _check_file(path)
                cache_file = _cache_file(path, fps, None, store)  # hashes the file: once per file
                cached = _read_cache(cache_file, path)
            except RLAnimateError as error:
                results[path, fps] = error
                continue
            if cached is None:
                missing[path, fps] = cache_file
            else:
                results[path, fps] = cached
        failed = import_worker.import_into_cache(list(missing), store, workers, limits, progress)
        for (path, fps), cache_file in missing.items():
            result = failed.get((path, fps)) or _read_cache(cache_file, path)
            results[path, fps] = result or RLAnimateError(f"{path}: its import left no readable cache entry in "
                                                          f"{store}. Import it again.")
    return results


def _writable(folder: Path | None) -> bool:
    """Whether the folder `folder` (None: no folder) exists or can be made, and a file can be written in it."""
    if folder is None:
        return False
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def _manifest_fps_problem(error, entry, manifest, manifest_path):
    """The message for a clip whose frame rate is not the one its manifest gives: the manifest may be wrong."""
    field = "the entry's field 'fps'" if "fps" in manifest["clips"][entry.number - 1] else \
        "the manifest's field 'fps'" if manifest.get("fps") is not None else f"the default {EXPECTED_FPS:g} fps"
    return (f"{entry.describe(manifest_path)}: the clip {error.path} runs at {round(error.fps, 2):g} fps, but "
            f"{field} says {error.expected:g}. Correct the manifest if the clip is right, or re-export the clip "
            f"at {error.expected:g} fps.")


def _no_library(path):
    """The RLAnimateError for a path that is neither a clip folder nor an existing manifest .json."""
    folder = path.parent if path.name == "manifest.json" else path
    if folder.is_dir():
        count = sum(p.suffix.lower() in CLIP_SUFFIXES for p in folder.iterdir())
        return RLAnimateError(f"The folder {folder} has {count} FBX/BVH clips but no manifest.json, and training "
                              "needs each clip's labels (behaviour, arm, target or exaggeration, train or test "
                              "split): write a manifest.json there as docs/CLIPS.md describes, or use a clip "
                              "library that has one.")
    if path.exists():
        return RLAnimateError(f"{path} is not a clip manifest (.json) or a folder of clips: use a clip library's "
                              "manifest.json or the folder that holds it.")
    return RLAnimateError(f"{path} does not exist: use a clip library's manifest.json or the folder that holds it.")


def load_clip_set(manifest_path, progress=None, workers=1, limits=None):
    """The labelled clip library of `manifest_path` (or of the directory holding manifest.json), with a
    progress bar on the stream `progress` (None: none). Bad files are listed in ClipSet.problems; raises
    RLAnimateError when none imports. What the cache lacks is imported by `workers` import workers, each
    clip within `limits` (import_clip_directory)."""
    clips, problems = import_clip_directory(manifest_path, progress=progress, workers=workers, limits=limits)
    if not clips:
        raise RLAnimateError(f"{manifest_path}: no clip could be imported ({len(problems)} problems: "
                             f"{'; '.join(problems[:3])}). Regenerate the clip library.")
    return ClipSet(clips, problems)
