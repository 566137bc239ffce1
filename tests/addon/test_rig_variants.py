"""Generate Gesture on rig variants built from the sample character (tests/addon/rig_variants.py): accepted,
pointing on target with exact aim, waves with their strokes, and nothing it does not own changed."""
import bpy
import numpy as np
import pytest

import addon_helpers as helpers
import rig_variants
from rlanimate_addon.blender import action_adapter, gestures
from rlanimate_addon.core import behaviour_metrics, gesture, rig_roles
from test_generate import random_target

RNG = np.random.default_rng(11)
POINT_STARTS = (20, 220, 420)
MEDIAN_DEG, WORST_DEG = 3.0, 8.0


@pytest.fixture(scope="module")
def variant_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("variants")
    return {name: rig_variants.build(name, folder) for name in rig_variants.BUILDERS}


def _roles(rig):
    return rig_roles.detect([b.name for b in rig.data.bones])[1]


def _world(rig, point):
    return np.array(rig.matrix_world, dtype=np.float64) @ np.append(point, 1.0)


def finger_angle(rig, arm, target, frames):
    """(F,) degrees between the rig's finger line (gesture.finger_line_bones: joint heads, or a hand's tail) and
    its base-to-target line, and (F, 3) world positions of the finger base."""
    line = gesture.finger_line_bones(_roles(rig), arm)
    angles, bases = [], []
    for frame in frames:
        bpy.context.scene.frame_set(int(frame))
        base = _world(rig, rig.pose.bones[line.start].head)[:3]
        tip = _world(rig, getattr(rig.pose.bones[line.end], "tail" if line.to_tail else "head"))[:3]
        finger, to_target = tip - base, np.asarray(target) - base
        cos = finger @ to_target / np.linalg.norm(finger) / np.linalg.norm(to_target)
        angles.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
        bases.append(base)
    return np.array(angles), np.array(bases)


def hold_miss(rig, angles, bases):
    """Median of a Point gesture's finger angles (F,) over its pointing hold (behaviour_metrics.hold_frames
    of the finger base's world positions (F, 3), as docs/METRICS.md measures the agent's own aim); the
    angle at the apex, where the base is farthest from its start, for a gesture without a hold."""
    roles = _roles(rig)
    width = np.linalg.norm(np.subtract(*(_world(rig, rig.data.bones[roles[side + "Arm"]].head_local)[:3]
                                         for side in ("Left", "Right"))))
    render = bpy.context.scene.render
    hold = behaviour_metrics.hold_frames(bases, width, render.fps / render.fps_base)
    if hold is None:
        return float(angles[int(np.argmax(np.linalg.norm(bases - bases[0], axis=1)))])
    return float(np.median(angles[hold[0]:hold[1] + 1]))


def _eye_misses(rig, target, frame):
    """Degrees by which each eye the rig has looks off the target at the frame; an eye looks along the
    character's forward at rest."""
    roles = _roles(rig)
    heads = {r: np.array(rig.data.bones[b].head_local) for r, b in roles.items()}
    forward = gesture.character_frame(heads).T @ np.array([0.0, -1.0, 0.0])
    bpy.context.scene.frame_set(frame)
    out = []
    for eye in ("LeftEye", "RightEye"):
        if eye not in roles:
            continue
        bone = rig.pose.bones[roles[eye]]
        posed = np.array(bone.matrix.to_3x3().normalized()) @ np.array(
            bone.bone.matrix_local.to_3x3().normalized()).T @ forward
        world = np.array(rig.matrix_world.to_3x3()) @ posed
        to_target = np.asarray(target) - _world(rig, bone.head)[:3]
        cos = world @ to_target / np.linalg.norm(world) / np.linalg.norm(to_target)
        out.append(float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))))
    return out


def _sample_world_target(rig, arm, rng=None):
    """A random unseen target (drawn with rng, else the module's RNG), placed relative to the rig as
    random_target places it relative to the canonical character (the rig's own world transform and size
    applied)."""
    heads = {role: rig.data.bones[bone].head_local for role, bone in _roles(rig).items()}
    frame = gesture.character_frame({r: np.array(h) for r, h in heads.items()})  # armature -> character
    size = np.linalg.norm(np.subtract(heads["Head"], heads[("Right" if arm == "RIGHT" else "Left") + "Arm"]))
    canonical_size = np.linalg.norm(np.subtract(*(gesture.canonical_rig().rest_heads[n] for n in ("Head", "RightArm"))))
    local = frame.T @ (random_target(arm, RNG if rng is None else rng) * size / canonical_size)
    return _world(rig, local)[:3]


def _pose_snapshot(rig, frames):
    """{bone: (F, 4, 4)} every bone's matrix_basis at each frame."""
    out = {b.name: [] for b in rig.pose.bones}
    for frame in frames:
        bpy.context.scene.frame_set(int(frame))
        for bone in rig.pose.bones:
            out[bone.name].append(np.array(bone.matrix_basis))
    return {k: np.array(v) for k, v in out.items()}


def _gesture_bones(actions, rig):
    """The bones an action, or a list of actions, keys."""
    bones = set()
    for action in actions if isinstance(actions, list) else [actions]:
        target = action_adapter.ActionTarget(action, action.slots[0] if action_adapter.LAYERED else None)
        bones |= {f.data_path.split('"')[1] for f in target.fcurves()}
    return bones


def _all_keys():
    keys = {}
    for action in bpy.data.actions:
        target = action_adapter.ActionTarget(action, action.slots[0] if action_adapter.LAYERED and len(action.slots)
                                             else None)
        for f in target.fcurves():
            keys[(action.name, f.data_path, f.array_index)] = [tuple(p.co) for p in f.keyframe_points]
    return keys


@pytest.mark.parametrize("variant", list(rig_variants.BUILDERS))
def test_point_with_exact_aim_hits_and_changes_nothing_it_does_not_own(settings, variant_files, variant):
    rig = rig_variants.load(variant_files[variant])
    frames = np.arange(1, 640, 7)
    before, keys_before = _pose_snapshot(rig, frames), _all_keys()
    owned, misses, gaze = set(), [], []
    for k, start in enumerate(POINT_STARTS):
        arm = ("RIGHT", "LEFT")[k % 2]
        location = _sample_world_target(rig, arm)
        target = helpers.add_empty(f"Target{k}", location)
        assert helpers.generate(rig, settings, behaviour="POINT", arm=arm, target=target, start_frame=start,
                                frame_count=120, exact_aim=True) == {"FINISHED"}, variant
        angles, bases = finger_angle(rig, arm, location, np.arange(start, start + 120))
        apex = int(np.argmax(np.linalg.norm(bases - bases[0], axis=1)))
        misses.append(angles[apex])
        gaze.extend(_eye_misses(rig, location, start + apex))
        owned |= {(b, start) for b in _gesture_bones(_newest_gesture(), rig)}
    print(f"{variant}: apex misses {np.round(misses, 2)} deg, eyes {np.round(gaze, 2)} deg")
    assert all(g < 0.5 for g in gaze), f"{variant}: the eyes look {gaze} deg off the target at the apex"
    assert np.median(misses) <= MEDIAN_DEG and max(misses) <= WORST_DEG, f"{variant}: misses {misses}"
    _assert_unowned_unchanged(rig, before, keys_before, frames, owned)


def _newest_gesture():
    """The actions of the gesture made last: its main action and its torso action."""
    main = max((a for a in bpy.data.actions if gestures.RECORD in a), key=lambda a: a.session_uid)
    return [main] + [a for a in bpy.data.actions if a.get(gestures.TORSO_OF) == main[gestures.RECORD]["id"]]


def _assert_unowned_unchanged(rig, before, keys_before, frames, owned, length=120):
    """Bones the gestures do not key, and keyed bones outside the gestures' frames, play as before. On a
    rig with no animation of its own, a keyed bone holds the standing pose outside the gestures."""
    after = _pose_snapshot(rig, frames)
    still = not keys_before
    for bone, matrices in before.items():
        inside = np.zeros(len(frames), dtype=bool)
        for owner, start in owned:
            if owner == bone:
                inside |= still | ((frames >= start) & (frames < start + length))
        assert np.allclose(after[bone][~inside], matrices[~inside], atol=1e-5), (
            f"{bone} changed where the gesture does not drive it"
        )
    keys_after = _all_keys()
    assert {k: v for k, v in keys_after.items() if k in keys_before} == keys_before, "existing keys changed"


def _lateral_wrist(rig, frames):
    """(F,) the waving wrist's side-to-side position relative to its shoulder, in arm lengths (shoulder to
    elbow to wrist at rest)."""
    roles = _roles(rig)
    heads = {r: np.array(rig.data.bones[b].head_local) for r, b in roles.items()}
    frame = gesture.character_frame(heads)
    size = np.linalg.norm(heads["RightForeArm"] - heads["RightArm"]) + np.linalg.norm(
        heads["RightHand"] - heads["RightForeArm"]
    )
    out = []
    for f in frames:
        bpy.context.scene.frame_set(int(f))
        wrist, shoulder = (np.array(rig.pose.bones[roles[n]].head) for n in ("RightHand", "RightArm"))
        out.append((frame @ (wrist - shoulder))[0] / size)
    return np.array(out)


def _strokes(lateral):
    """Turns of the side-to-side motion bigger than 10% of its range, while the gesture is at full weight
    (not blending from or to the pose underneath: the middle 60% of the frames)."""
    ramp = int(round(gesture.BLEND_FRACTION * (len(lateral) - 1)))
    lateral = lateral[ramp:-ramp]
    turns, direction, extreme = 0, 0, lateral[0]
    threshold = 0.1 * np.ptp(lateral)
    for value in lateral[1:]:
        if direction >= 0 and value < extreme - threshold or direction <= 0 and value > extreme + threshold:
            turns += direction != 0
            direction = -1 if value < extreme else 1
            extreme = value
        elif direction * (value - extreme) > 0:
            extreme = value
    return turns


@pytest.fixture(scope="module")
def sample_wave(variant_files):
    helpers.enable_addon()
    rig = helpers.load_sample_rig()
    settings = bpy.context.scene.rlanimate
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT", exaggeration=0.8, start_frame=20,
                            frame_count=150) == {"FINISHED"}
    lateral = _lateral_wrist(rig, np.arange(20, 170))
    helpers.disable_addon()
    return lateral


@pytest.mark.parametrize("variant", list(rig_variants.BUILDERS))
def test_waves_keep_their_strokes_and_change_nothing_they_do_not_own(settings, variant_files, sample_wave, variant):
    rig = rig_variants.load(variant_files[variant])
    frames = np.arange(1, 400, 5)
    before, keys_before = _pose_snapshot(rig, frames), _all_keys()
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT", exaggeration=0.8, start_frame=20,
                            frame_count=150) == {"FINISHED"}
    lateral = _lateral_wrist(rig, np.arange(20, 170))
    expected = _strokes(sample_wave)
    print(f"{variant}: {_strokes(lateral)} strokes (sample {expected}), size {np.ptp(lateral[30:-30]):.3f} "
          f"(sample {np.ptp(sample_wave[30:-30]):.3f})")
    assert expected >= 3 and _strokes(lateral) == expected
    middle = slice(30, -30)
    assert 0.8 < np.ptp(lateral[middle]) / np.ptp(sample_wave[middle]) < 1.25
    owned = {(b, 20) for b in _gesture_bones(_newest_gesture(), rig)}
    _assert_unowned_unchanged(rig, before, keys_before, frames, owned, length=150)


def point_misses(rig, settings, count, exact_aim, rng, frames=120):
    """Misses at the hold (degrees, `hold_miss`) of `count` Point gestures of `frames` frames, 200 frames
    apart, both arms alternating, at random targets drawn with rng (the same character-relative targets
    on any rig for the same generator state)."""
    misses = []
    for k in range(count):
        arm, start = ("RIGHT", "LEFT")[k % 2], 1 + 200 * k
        location = _sample_world_target(rig, arm, rng)
        target = helpers.add_empty(f"Target{k}", location)
        assert helpers.generate(rig, settings, behaviour="POINT", arm=arm, target=target, start_frame=start,
                                frame_count=frames, exact_aim=exact_aim) == {"FINISHED"}
        misses.append(hold_miss(rig, *finger_angle(rig, arm, location, np.arange(start, start + frames))))
    return np.array(misses)


def _own_aim_misses(rig, settings):
    """Six own-aim misses (Exact Aim off) at the same targets on any rig."""
    return point_misses(rig, settings, 6, False, np.random.default_rng(5))


@pytest.fixture(scope="module")
def sample_own_aim(variant_files):
    settings = helpers.enable_addon()
    misses = _own_aim_misses(helpers.load_sample_rig(), settings)
    helpers.disable_addon()
    return misses


@pytest.mark.parametrize("variant", ["blender_human_metarig", "rigify_generated", "idle_animation"])
def test_the_agents_own_aim_on_a_rig_unlike_the_sample_misses_by_what_it_misses_on_the_sample(
        settings, variant_files, sample_own_aim, variant):
    """Exact Aim off, at the same character-relative targets as on the sample character. Blender's human
    metarig rests its index finger curled and Rigify's rig keeps that rest (the pointing index is keyed
    straight and its last bone swung by its own tail); the idle sways and turns the hips underneath (the
    agent is asked for the direction the body sees). Each missed by 4 to 8 degrees more before."""
    misses = _own_aim_misses(rig_variants.load(variant_files[variant]), settings)
    print(f"{variant}: own aim {np.round(misses, 1)} deg, sample {np.round(sample_own_aim, 1)} deg")
    assert np.median(misses - sample_own_aim) <= 1.5 and np.median(misses) <= np.median(sample_own_aim) + 1.5
