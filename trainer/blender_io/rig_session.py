"""The Blender session the trainer works in: the `bpy` module, an empty scene, and rigs loaded into it.

The same under `blender -b -P` and under `python` with the bpy module.
"""
import os
import sys
import tempfile
from contextlib import contextmanager, redirect_stderr, redirect_stdout
from pathlib import Path

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer.paths import SAMPLE_RIG_BLEND

#: Name of the sample character's armature object and data.
SAMPLE_RIG_NAME = "RLAnimate_Character"


def import_bpy():
    """Return the `bpy` module, or raise RLAnimateError saying how to get it."""
    try:
        import bpy
    except ImportError as error:
        raise RLAnimateError("Blender's Python module is missing: run under `blender -b -P` or "
                             "`pip install bpy==5.0.1` into Python 3.11.") from error
    return bpy


@contextmanager
def blender_output(verbose=False):
    """Send what Blender prints (its importers' `FBX version: 7400` per file on stdout, and any C-level output)
    to a discarded temporary file, unless `verbose`. Python's sys.stderr (the trainer's own notes) still
    reaches the terminal; the stream yielded is it, for progress bars."""
    if verbose:
        yield sys.stderr
        return
    sys.stdout.flush()
    sys.stderr.flush()
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    terminal = os.fdopen(os.dup(saved[2]), "w")
    with tempfile.TemporaryFile("w+") as sink, redirect_stdout(sink), redirect_stderr(terminal):
        for fd in saved:
            os.dup2(sink.fileno(), fd)
        try:
            yield terminal
        finally:
            sink.flush()
            for fd, copy in saved.items():
                os.dup2(copy, fd)
                os.close(copy)
            terminal.close()


def new_empty_scene():
    """Reset Blender to factory settings with an empty scene; returns bpy.context.scene."""
    bpy = import_bpy()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene


def is_rig(obj, required=skeleton.REQUIRED_BONES):
    """True when `obj` is an armature object with every required bone (any `prefix:` naming)."""
    if obj is None or obj.type != "ARMATURE":
        return False
    names = {skeleton.strip_prefix(b.name) for b in obj.data.bones}
    return set(required) <= names


def find_armature(objects, required=skeleton.REQUIRED_BONES):
    """The first armature object among `objects` that has every required bone.

    Raises RLAnimateError naming the missing bones of the best candidate when none has them all.
    """
    armatures = [o for o in objects if o.type == "ARMATURE"]
    for obj in armatures:
        if is_rig(obj, required):
            return obj
    if not armatures:
        raise RLAnimateError("No armature found: load a rig with Mixamo bone names.")
    best = max(armatures, key=lambda o: len({skeleton.strip_prefix(b.name) for b in o.data.bones}
                                            & set(required)))
    present = {skeleton.strip_prefix(b.name) for b in best.data.bones}
    missing = sorted(set(required) - present)
    raise RLAnimateError(f"Armature {best.name!r} lacks the bones {', '.join(missing)}: "
                         "use a rig with Mixamo bone names.")


def load_rig(path=SAMPLE_RIG_BLEND, with_mesh=False):
    """Bring the rig at `path` (.blend or .fbx) into the current scene and return its armature object.

    From a .blend only the armature object is appended unless `with_mesh`, so pose evaluation does
    not deform meshes; from an .fbx, Blender's importer brings everything and meshes are removed
    unless `with_mesh`.
    """
    bpy = import_bpy()
    path = Path(path)
    if not path.is_file():
        raise RLAnimateError(f"Rig file {path} does not exist: run `python sample_rigs/build_character.py` "
                             "or choose another file.")
    before = set(bpy.data.objects)
    if path.suffix.lower() == ".blend":
        try:
            with bpy.data.libraries.load(str(path), link=False) as (source, target):
                target.objects = list(source.objects)
        except OSError as error:
            raise RLAnimateError(f"Could not read {path}: {error}. Choose a .blend saved by Blender.") from error
        loaded = [o for o in target.objects if o is not None]
        if not with_mesh:
            for obj in [o for o in loaded if o.type != "ARMATURE"]:
                bpy.data.objects.remove(obj)
            loaded = [o for o in bpy.data.objects if o not in before]
        for obj in loaded:
            bpy.context.scene.collection.objects.link(obj)
    elif path.suffix.lower() == ".fbx":
        try:
            bpy.ops.import_scene.fbx(filepath=str(path), use_anim=False)
        except RuntimeError as error:
            raise RLAnimateError(f"Could not import {path}: {error}") from error
        loaded = [o for o in bpy.data.objects if o not in before]
        if not with_mesh:
            for obj in [o for o in loaded if o.type == "MESH"]:
                bpy.data.objects.remove(obj)
            loaded = [o for o in bpy.data.objects if o not in before]
    else:
        raise RLAnimateError(f"Rig file {path} is neither .blend nor .fbx: save the rig in one of those.")
    return find_armature(loaded)
