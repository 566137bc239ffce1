"""Generated gestures rendered by Blender: the add-on's Generate Gesture on the sample character, key
frames rendered with Cycles (CPU), as PNG files for a contact sheet.

Each request is baked on its own frame range of one character (Generate keys only its own frames)
through the registered operator, exactly as an animator runs it from the panel; a composition
(`render_compositions`) bakes several gestures on overlapping frames of one character, in order.
"""
from dataclasses import dataclass, field
from pathlib import Path

from trainer.blender_io.rig_session import blender_output, import_bpy, load_rig, new_empty_scene
from trainer.paths import SAMPLE_RIG_BLEND

ADDON = "rlanimate_addon"
#: Where each request's gesture starts: far enough apart that no two overlap.
FRAME_SPACING = 300
#: Key frames shown per request, as fractions of the gesture.
KEY_FRACTIONS = (0.1, 0.25, 0.4, 0.55, 0.7, 0.9)


@dataclass
class RenderRequest:
    """One Generate Gesture call: the panel's settings (Scene.rlanimate names) and a row title."""
    title: str
    settings: dict
    #: character-frame position of a target sphere for a target behaviour (POINT, GUIDE)
    target: tuple[float, ...] | None = None
    frames: list = field(default_factory=list)  # filled by render_requests: (frame, png path)


def _stage(bpy):
    """Camera (orthographic, three-quarter front), sun, grey world; Cycles on the CPU at low samples."""
    import mathutils  # Blender's own module, importable once bpy is

    scene = bpy.context.scene
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 3.0
    camera.location = (1.6, -5.0, 1.3)
    look = mathutils.Vector((-0.45, 0.0, 1.2)) - camera.location
    camera.rotation_euler = look.to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.7, 0.2, 0.5)
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):  # 5.0 worlds and materials always use nodes
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.16, 0.17, 0.19, 1.0)
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 12
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 300, 300
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"


def _target_sphere(bpy, name, location):
    """A small red sphere at `location`: the object Generate Gesture points at."""
    import bmesh  # Blender's own module, importable once bpy is

    mesh = bpy.data.meshes.new(name)
    shape = bmesh.new()
    bmesh.ops.create_uvsphere(shape, u_segments=16, v_segments=8, radius=0.06)
    shape.to_mesh(mesh)
    shape.free()
    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    material.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.1, 0.05, 1.0)
    mesh.materials.append(material)
    sphere = bpy.data.objects.new(name, mesh)
    sphere.location = location
    bpy.context.scene.collection.objects.link(sphere)
    return sphere


@dataclass
class Composition:
    """Gestures baked in order on one character (each its panel settings, with start_frame, and a target
    position or None), and the frames rendered of them, with a row title."""
    title: str
    gestures: list
    shown: tuple
    frames: list = field(default_factory=list)  # filled by render_compositions: (frame, png path)


def _staged_rig(agent_path, rig_path):
    """A fresh scene with the add-on enabled (and the agent file chosen), the character and the stage; returns
    the armature."""
    bpy = import_bpy()
    import addon_utils  # Blender's own module, importable once bpy is
    new_empty_scene()
    addon_utils.enable(ADDON, default_set=True)
    if agent_path is not None:
        bpy.context.preferences.addons[ADDON].preferences.agent_path = str(agent_path)
    rig = load_rig(rig_path, with_mesh=True)
    _stage(bpy)
    return rig


def _render(bpy, frame, path):
    scene = bpy.context.scene
    scene.frame_set(frame)
    scene.render.filepath = str(path)
    with blender_output():  # Cycles' progress and 'Saved: ...' lines
        bpy.ops.render.render(write_still=True)


def render_compositions(compositions, out_dir, agent_path=None, rig_path=SAMPLE_RIG_BLEND):
    """Bake each Composition's gestures in order with Generate Gesture on a character of its own (a fresh
    scene) and render its `shown` frames into out_dir; returns the compositions with `frames` filled."""
    bpy = import_bpy()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for k, composition in enumerate(compositions):
        rig = _staged_rig(agent_path, rig_path)
        settings = bpy.context.scene.rlanimate
        for j, (values, target) in enumerate(composition.gestures):
            for key, value in values.items():
                setattr(settings, key, value)
            settings.target = None if target is None else _target_sphere(bpy, f"Target{j}", target)
            bpy.context.view_layer.objects.active = rig
            if bpy.ops.rlanimate.generate_gesture() != {"FINISHED"}:
                raise RuntimeError(f"Generate Gesture failed for {composition.title!r}")
        composition.frames = []
        for frame in composition.shown:
            path = out_dir / f"composition{k:02d}_frame{frame:05d}.png"
            _render(bpy, frame, path)
            composition.frames.append((frame, path))
    return compositions


def render_requests(requests, out_dir, agent_path=None, rig_path=SAMPLE_RIG_BLEND):
    """Bake each RenderRequest with Generate Gesture and render its KEY_FRACTIONS frames into out_dir;
    returns the requests with `frames` filled. agent_path: an agent file for the add-on's preferences
    (default: the bundled agent)."""
    bpy = import_bpy()
    rig = _staged_rig(agent_path, rig_path)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    scene = bpy.context.scene
    settings = scene.rlanimate
    for k, request in enumerate(requests):
        start = 1 + FRAME_SPACING * k
        for key, value in request.settings.items():
            setattr(settings, key, value)
        settings.start_frame = start
        target = None
        if request.target is not None:
            target = _target_sphere(bpy, f"Target{k}", request.target)
            settings.target = target
        bpy.context.view_layer.objects.active = rig
        if bpy.ops.rlanimate.generate_gesture() != {"FINISHED"}:
            raise RuntimeError(f"Generate Gesture failed for {request.title!r}")
        request.frames = []
        for fraction in KEY_FRACTIONS:
            frame = start + int(round(fraction * (settings.frame_count - 1)))
            path = out_dir / f"request{k:02d}_frame{frame:05d}.png"
            _render(bpy, frame, path)
            request.frames.append((frame - start, path))
        if target is not None:
            target.hide_render = True  # only this request's target shows in its own frames
    return requests
