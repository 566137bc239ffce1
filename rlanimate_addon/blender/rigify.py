"""Rigify at the Blender edge: telling a generated rig, reading an arm's IK-FK switch and the pose its
arm plays, and the switch's keys (core/rigify.py says how an arm in IK is switched to FK)."""
from ..core import rigify
from ..core.errors import RLAnimateError
from . import action_adapter


def is_generated(obj):
    """Whether Rigify generated the armature: its rig_id on the armature data (which its UI script names),
    or, where that was lost, Rigify's own machinery: ORG- bones and an arm's IK-FK switch."""
    if "rig_id" in obj.data:
        return True
    switches = [obj.pose.bones.get(rigify.switch_bone(arm)) for arm in ("LEFT", "RIGHT")]
    return any(s is not None and rigify.SWITCH in s for s in switches) and any(
        b.name.startswith("ORG-") for b in obj.data.bones)


def _switch_path(arm):
    return f'pose.bones["{rigify.switch_bone(arm)}"]["{rigify.SWITCH}"]'


def ik_share(obj, arm):
    """The arm's IK_FK value when the arm can follow its IK controls (below 1.0, or animated), else None.
    RLAnimateError when a driver sets it: keys on it would not play."""
    switch = obj.pose.bones.get(rigify.switch_bone(arm))
    if switch is None or rigify.SWITCH not in switch:
        return None
    data, path = obj.animation_data, _switch_path(arm)
    if data is not None and data.drivers.find(path) is not None:
        raise RLAnimateError(
            f"A driver sets the {arm.lower()} arm's IK-FK switch ({rigify.SWITCH} on {switch.name}) of "
            f"{obj.name!r}, and the gesture keys it to FK over its frames: remove or mute the driver (Drivers "
            "editor), or set the arm to FK, and generate again.")
    targets = [action_adapter.active_target(obj)] + action_adapter.strip_targets(obj)
    animated = any(f.data_path == path for t in targets if t is not None for f in t.fcurves())
    return float(switch[rigify.SWITCH]) if animated or switch[rigify.SWITCH] < 1.0 else None


def arm_reads(arm):
    """(the ORG- bones the arm's FK controls stand for, [(switch bone, IK_FK)]): what `played_arm` reads, for
    armature_io.sample_rig to read in its own pass over the frames."""
    return [rigify.org_bone(c) for c in rigify.fk_controls(arm)], [(rigify.switch_bone(arm), rigify.SWITCH)]


def played_arm(arm, played):
    """({FK control: (N, 4, 4)} the armature-space pose of the ORG- bone each FK control of the arm stands
    for, (N,) the arm's IK_FK), as the rig plays: played is the playback.Played of `arm_reads`."""
    controls = rigify.fk_controls(arm)
    switch = played.properties[rigify.switch_bone(arm), rigify.SWITCH]
    return {control: played.pose[:, k] for k, control in enumerate(controls)}, switch


def switch_keys(obj, arm, under, blend_type, animated):
    """{data path: (N,) values} keying the arm's IK_FK to FK over the gesture (core.rigify.switch_values),
    under: (N,) its values underneath. RLAnimateError on an animated rig whose animation leaves a switch
    off its default: outside the gesture's NLA strip Blender would play the switch at its default."""
    switch = obj.pose.bones[rigify.switch_bone(arm)]
    default = float(switch.id_properties_ui(rigify.SWITCH).as_dict().get("default", 0.0))
    path = _switch_path(arm)
    targets = [action_adapter.active_target(obj)] + action_adapter.strip_targets(obj)
    keyed = any(f.data_path == path for t in targets if t is not None for f in t.fcurves())
    if animated and not keyed and abs(under[0] - default) > 1e-6:
        raise RLAnimateError(
            f"The {arm.lower()} arm of {obj.name!r} stands at IK-FK {under[0]:.2f} ({rigify.SWITCH} on "
            f"{switch.name}), unkeyed, and its animation goes to the NLA: outside the gesture Blender would "
            f"play the switch at its default, {default:.1f}. Key the switch in the animation (or set it to "
            f"{default:.1f} or 1.0) and generate again.")
    return {path: rigify.switch_values(under, len(under), blend_type, default)}


def switches(obj, properties):
    """[(pose bone, property name)] of the switches keyed by `properties` ({data path: values} or None)."""
    return [(obj.pose.bones[path.split('"')[1]], path.split('"')[3]) for path in (properties or {})]
