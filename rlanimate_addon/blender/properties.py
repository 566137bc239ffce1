"""`Scene.rlanimate`: the gesture settings the panel shows and Generate Gesture reads.

The names behaviour, arm, target, exaggeration, tempo, frame_count, start_frame, seed and exact_aim are a
contract that outside tools and checks use: keep them. Until set, frame_count is the agent's average length of
the behaviour's clips and start_frame the scene's current frame. `behaviour` lists the selected agent's behaviours
(`behaviour_items`): its values are their ids, "POINT" and "WAVE" for those; `behaviour_name` keeps the id chosen,
so that an agent that lacks it still shows and names it.
"""
import zlib

import bpy

from ..core import behaviours, frame_rate
from ..core.behaviours import INTENSITY, KNOWN_KINDS, POINT, TARGET, WAVE
from ..core.errors import RLAnimateError
from . import preferences

#: Length used when the bundled agent cannot be read at start-up.
FALLBACK_LENGTH = 60


def _bundled_lengths():
    """{behaviour: the bundled agent's average length of its clips, in its frames}, {} when it cannot be read."""
    try:
        averages = preferences.load_agent(preferences.BUNDLED_AGENT).average_frames
    except (RLAnimateError, ImportError):
        return {}
    return {behaviour: int(round(frames)) for behaviour, frames in averages.items()}


#: The bundled agent's average lengths at its 30 fps, read once at start-up.
BUNDLED_LENGTHS = _bundled_lengths()


def learned_length(behaviour=POINT):
    """The bundled agent's average gesture length for the behaviour, in frames."""
    return BUNDLED_LENGTHS.get(behaviour, FALLBACK_LENGTH)


#: The bundled agent's average Point length at its 30 fps.
DEFAULT_LENGTH = learned_length()


def scene_fps(scene):
    """The scene's frame rate in frames per second (fps / fps_base: 29.97 for NTSC)."""
    return scene.render.fps / scene.render.fps_base


def _owning_scene(settings):
    """The scene whose rate a settings group's length follows: its own, or the current one for an
    armature's own settings (None in a context without one)."""
    owner = settings.id_data
    return owner if isinstance(owner, bpy.types.Scene) else bpy.context.scene


def _learned_length(behaviour):
    """The selected agent's average length of the behaviour's clips, in its frames (the bundled agent's when it
    cannot be read or lacks the behaviour)."""
    try:
        return int(round(preferences.selected_agent(bpy.context).average_frames[behaviour]))
    except (RLAnimateError, KeyError):
        return BUNDLED_LENGTHS.get(behaviour, DEFAULT_LENGTH)


def _get_frame_count(settings):
    """The length set, else the agent's average length of the chosen behaviour's clips, in seconds at the
    scene's rate (core/frame_rate.py)."""
    stored = settings.get("frame_count")
    if stored is not None:
        return int(stored)
    scene = _owning_scene(settings)
    learned = _learned_length(chosen_behaviour(settings, bpy.context))
    return learned if scene is None else frame_rate.scene_frames(learned, scene_fps(scene))


def _set_frame_count(settings, value):
    length = RLANIMATE_PG_settings.bl_rna.properties["frame_count"]
    settings["frame_count"] = min(max(int(value), length.hard_min), length.hard_max)


def _get_start_frame(settings):
    """The start frame set, else the scene's current frame (the playhead)."""
    stored = settings.get("start_frame")
    if stored is not None:
        return int(stored)
    scene = _owning_scene(settings)
    return 1 if scene is None else scene.frame_current


def _set_start_frame(settings, value):
    settings["start_frame"] = int(value)


def follow_playhead(settings):
    """Have the settings' Start Frame follow the scene's current frame again (it is unset)."""
    if "start_frame" in settings:
        del settings["start_frame"]


#: Tooltips of the paper's pair; another behaviour's says what its kind asks for.
_DESCRIPTIONS = {POINT: "Point the index finger at the target", WAVE: "Wave the hand; exaggeration sets its size"}
_KIND_DESCRIPTIONS = {TARGET: "{name}, toward the target", INTENSITY: "{name}; exaggeration sets how much"}
#: The enum numbers of the paper's pair; another behaviour's is a hash of its id, so that a stored choice
#: names the same behaviour whichever agent is selected (Blender stores an enum's number).
_NUMBERS = {POINT: 0, WAVE: 1}


def behaviour_number(behaviour):
    """The enum number of a behaviour id, the same in every agent: POINT 0, WAVE 1, another id a crc32 of it
    (two ids of one agent sharing one: about 1 in 10^9)."""
    return _NUMBERS.get(behaviour, 2 + zlib.crc32(behaviour.encode()) % (2 ** 30))


#: The enum's items by (declared behaviours and kinds, the one held that the agent lacks): see behaviour_items.
_items: dict[tuple[tuple[tuple[str, str], ...], str | None], list[tuple[str, str, str, int]]] = {}
#: The behaviour ids of the paper's pair by enum number.
_NAMED_NUMBERS = {number: name for name, number in _NUMBERS.items()}


def stored_behaviour(settings):
    """The id of the behaviour the settings hold, whichever agent is selected: the one remembered when it was
    chosen (`behaviour_name`) while the stored number is still its, else point or wave by number; None when the
    stored number is of a behaviour not remembered."""
    if settings is None:
        return None
    number = settings.get("behaviour", behaviour_number(POINT))
    name = settings.get("behaviour_name", "")
    return name if name and behaviour_number(name) == number else _NAMED_NUMBERS.get(number)


def _lacking_item(name):
    """The enum item of a behaviour the settings hold that the selected agent does not perform: shown, so that the
    choice is read without Blender's 'matches no enum' warning and Generate can name it."""
    title = behaviours.title(name)
    return (name, f"{title} (not in this agent)", f"The selected agent does not perform {title}: pick one of its "
            "behaviours, or choose an agent trained for it in Preferences", behaviour_number(name))


def behaviour_items(settings, context):
    """The `behaviour` enum's items: the selected agent's behaviours (point and wave when it cannot be
    loaded; the panel says why), and the one the settings hold when the agent lacks it (`_lacking_item`). The
    list is kept here, per set of behaviours: Blender reads the strings after this returns, and crashes or shows
    garbage if Python has freed them (the bpy.props.EnumProperty documentation's known bug with item callbacks)."""
    try:
        agent = preferences.selected_agent(context or bpy.context)
        declared = tuple((name, agent.kind(name)) for name in agent.behaviours)
    except RLAnimateError:
        declared = tuple(KNOWN_KINDS.items())
    held = stored_behaviour(settings)
    lacking = held if held is not None and held not in dict(declared) else None
    if (declared, lacking) not in _items:
        _items[declared, lacking] = [
            (name, behaviours.title(name),
             _DESCRIPTIONS.get(name) or _KIND_DESCRIPTIONS[kind].format(name=behaviours.title(name)),
             behaviour_number(name)) for name, kind in declared] + ([_lacking_item(lacking)] if lacking else [])
    return _items[declared, lacking]


def _remember_behaviour(settings, context):
    """The enum's update: keep the chosen behaviour's id (`behaviour_name`), so that another agent that lacks it
    still names it."""
    settings["behaviour_name"] = settings.behaviour


def chosen_behaviour(settings, context):
    """The id of the settings' behaviour (one the selected agent lacks included, `behaviour_items`), or "" when the
    stored choice is of a behaviour not remembered: read from the stored enum number, as `settings.behaviour`
    would, without the warning Blender prints for a value its items lack (the panel reads it on every redraw)."""
    number = settings.get("behaviour", behaviour_number(POINT))
    return next((item[0] for item in behaviour_items(settings, context) if item[3] == number), "")


def declared_behaviour(context: bpy.types.Context, behaviour: str) -> behaviours.Behaviour | None:
    """The declaration (behaviours.Behaviour: its kind and what it does) of `behaviour` in the selected agent;
    the paper's, or None, when the agent cannot be loaded or lacks it."""
    try:
        agent = preferences.selected_agent(context)
        if behaviour in agent.behaviours:
            return agent.space.behaviour(behaviour)
    except RLAnimateError:
        pass
    return behaviours.Behaviour(behaviour, KNOWN_KINDS[behaviour]) if behaviour in KNOWN_KINDS else None


class RLANIMATE_PG_settings(bpy.types.PropertyGroup):
    behaviour: bpy.props.EnumProperty(
        name="Behaviour", default=behaviour_number(POINT), items=behaviour_items, update=_remember_behaviour,
        description="The gesture: one of the selected agent's behaviours")
    behaviour_name: bpy.props.StringProperty(
        name="Behaviour Name", default="", options={"HIDDEN"},
        description="The id of the behaviour last chosen, kept so that an agent lacking it can name it")
    arm: bpy.props.EnumProperty(
        name="Arm", default="RIGHT",
        items=[("LEFT", "Left", "The character's left arm"), ("RIGHT", "Right", "The character's right arm")])
    target: bpy.props.PointerProperty(
        name="Target", type=bpy.types.Object,
        description="Object to point at; it is read at every frame, so an animated target is tracked")
    use_cursor: bpy.props.BoolProperty(
        name="Use 3D Cursor", default=False,
        description="Point at the 3D cursor when no target object is picked")
    exaggeration: bpy.props.FloatProperty(
        name="Exaggeration", min=0.0, max=1.0, default=0.5, subtype="FACTOR",
        description="How big and high the wave is, from a small wave (0) to a whole-arm wave (1)")
    tempo: bpy.props.FloatProperty(
        name="Tempo", min=0.0, max=10.0, soft_max=4.0, default=0.0, precision=2,
        description="Side-to-side swings per second (Hz) of a wave; 0 lets the agent choose, as the waves it "
                    "learned from of this exaggeration do")
    frame_count: bpy.props.IntProperty(
        name="Length", min=0, soft_min=2, max=100000, default=DEFAULT_LENGTH,
        get=_get_frame_count, set=_set_frame_count,
        description="Length of the gesture in frames; until set, the agent's average length of the behaviour's "
                    "clips in seconds, at the scene's frame rate")
    start_frame: bpy.props.IntProperty(
        name="Start Frame", default=1, get=_get_start_frame, set=_set_start_frame,
        description="First frame of the gesture; until set, the scene's current frame")
    target_bone: bpy.props.StringProperty(
        name="Target Bone", default="",
        description="When the target is an armature, point at this bone's head (another character's head); "
        "unused for other targets")
    exact_aim: bpy.props.BoolProperty(
        name="Exact Aim", default=True,
        description="Turn the arm so the index finger passes exactly through the target; "
                    "off keys the agent's own aim")
    blend_type: bpy.props.EnumProperty(
        name="Layer", default="REPLACE",
        items=[("REPLACE", "Replace", "Over existing animation, the gesture replaces the bones it drives "
                                      "(NLA Replace)"),
               ("COMBINE", "Combine", "Over existing animation, the gesture is added to the bones it drives "
                                      "(NLA Combine)")])
    editable_keys: bpy.props.BoolProperty(
        name="Editable Keys", default=False,
        description="Bake a few Bezier keys per bone, only where needed to stay within the tolerance, instead "
                    "of a key on every frame")
    key_tolerance: bpy.props.FloatProperty(
        name="Tolerance", default=0.5, min=0.01, max=10.0, precision=2,
        description="Largest rotation, in degrees, by which the editable keys may stray from the baked gesture")
    bone_map_file: bpy.props.StringProperty(
        name="Bone Map", default="", subtype="FILE_PATH",
        description="A bone-map file (JSON) naming the rig's bone for each role; empty detects the bones")
    keep_previous: bpy.props.BoolProperty(
        name="Keep Previous", default=False,
        description="Layer the new gesture over an earlier one on the same arm and frames, on a new NLA track, "
                    "instead of replacing it in place")
    follow_target: bpy.props.BoolProperty(
        name="Follow Target", default=False,
        description="While on, moving the target of an armature's last Point gesture re-bakes that gesture "
                    "(until its keys are edited by hand)")
    seed: bpy.props.IntProperty(
        name="Variation Seed", min=0, default=0,
        description="0 gives the agent's most likely gesture; other values give variations")
    replace_edited_keys: bpy.props.BoolProperty(
        name="Replace Edited Keys", default=False,
        description="Bake a gesture again, or take over from it, even where its keys were edited by hand, "
                    "overwriting the edits (off: Generate refuses, naming the bones and frames edited)")


class RLANIMATE_PG_object(bpy.types.PropertyGroup):
    """`Object.rlanimate`: an armature's own gesture settings, used instead of the scene's when switched on
    (so several selected characters can each get their own gesture in one Generate)."""
    use_own_settings: bpy.props.BoolProperty(
        name="Own Settings", default=False,
        description="Generate this armature's gesture from its own settings instead of the scene's")
    settings: bpy.props.PointerProperty(type=RLANIMATE_PG_settings)
    vrm_file: bpy.props.StringProperty(
        name="VRM File", default="", subtype="FILE_PATH",
        description="The VRM file this armature was imported from: its humanoid map names the bones "
                    "(set by Bone Map from VRM File)")
    gesture: bpy.props.StringProperty(
        name="Selected Gesture", default="",
        description="The gesture selected in the panel's list (its action's name), which Generate bakes again; "
                    "empty: Generate adds a gesture")


def settings_for(obj, shared):
    """The settings Generate uses for an armature: its own when switched on, else the shared scene's."""
    own = obj.rlanimate
    return own.settings if own.use_own_settings else shared


def armature_of(obj):
    """The armature an object stands for: itself, or the armature whose Armature modifier deforms a mesh; None
    for anything else."""
    if obj is not None and obj.type == "MESH":
        obj = next((m.object for m in obj.modifiers if m.type == "ARMATURE" and m.object is not None), None)
    return obj if obj is not None and obj.type == "ARMATURE" else None


def panel_settings(context):
    """The settings the panel edits: the active armature's own when switched on, else the scene's."""
    obj = armature_of(context.active_object)
    shared = context.scene.rlanimate
    return shared if obj is None else settings_for(obj, shared)
