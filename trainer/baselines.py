"""The baselines an animator would try before RLAnimate, producing clips the evaluator scores.

Both answer the agent's request (behaviour, arm, label attributes, frame count) with a clip of
local rotations (F, 15, 3) of skeleton.ACTION_JOINTS, like MotionClip.rotvecs:

NearestClip      retrieval, as motion matching does: the training clip of the same behaviour and arm
                 whose label is closest (angle between pointing directions; |difference| of
                 exaggerations), time-warped uniformly to the requested length (per-joint slerp).
ProceduralIK     Blender's IK constraint on the sample rig. Point: the index finger's IK chain (Index1,
                 Hand, ForeArm, Arm) reaches for a target 2.5 m along the requested direction, so the arm
                 and finger line up with it; the constraint's influence is keyed 0 -> 1 -> 0 with
                 minimum-jerk ease (stroke, hold, return), which is a per-joint slerp between the start
                 pose and the solved pose. Wave: the hand's IK chain (Hand, ForeArm, Arm) follows a
                 target that rises with minimum-jerk timing and swings side to side at 2.5 Hz; the
                 raise (70 + 90 e degrees from hanging) and the swing (0.05 + 0.35 e arm lengths each
                 way) scale with the exaggeration e, the same scale trainer/autolabel.py measures.
                 Each frame is one depsgraph evaluation of the constrained rig, and the constraint's
                 influence follows the raise, so the clip starts and ends in the neutral pose.

Both start from and return to `neutral` (15, 3), the pose the training clips start in.
AgentMethod (an exported .npz, numpy runtime) and TrainedAgentMethod (a trainer's torch agent) put
RLAnimate behind the same generate() interface, so all three are scored by one code path.
"""
from pathlib import Path

import numpy as np

from rlanimate_addon.core import metrics, rotations, skeleton, spaces
from rlanimate_addon.core.easing import minimum_jerk
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.gesture import slerp

from . import autolabel, bpy_support

FPS = 30.0
#: Where the IK target sits along the requested pointing direction, metres from the rest shoulder.
POINT_TARGET_DISTANCE = 2.5
#: Pointing timing as fractions of the clip: stroke from..to, hold until, return until.
POINT_TIMING = (0.12, 0.38, 0.72, 0.92)
#: Waving timing: raise from..to, lower from..to, as fractions of the clip; swing frequency in Hz.
WAVE_TIMING = (0.08, 0.3, 0.72, 0.94)
WAVE_FREQUENCY = 2.5
#: Wave shape: elevation of shoulder->hand from hanging (degrees) and side-to-side swing (arm lengths).
WAVE_ELEVATION = (70.0, 90.0)  # at e = 0, added at e = 1
WAVE_SWING = (0.05, 0.35)
WAVE_REACH = 0.8  # shoulder->hand distance at the raise, in arm lengths (the elbow stays bent)


def neutral_pose(clips):
    """(15, 3) start pose: the mean first frame of `clips` (they all start standing neutrally)."""
    if not clips:
        raise RLAnimateError("No training clips: a baseline needs at least one clip to start from.")
    quats = rotations.rotvec_to_quat(np.stack([np.asarray(c.rotvecs[0]) for c in clips]))  # (C, 15, 4)
    quats = np.where(np.sum(quats * quats[:1], axis=-1, keepdims=True) < 0.0, -quats, quats)
    mean = quats.mean(axis=0)
    return rotations.quat_to_rotvec(mean / np.linalg.norm(mean, axis=-1, keepdims=True))


def time_warp(rotvecs, frame_count):
    """(M, 15, 3) -> (frame_count, 15, 3), uniform time scaling with per-joint slerp, ends kept."""
    quats = rotations.rotvec_to_quat(np.asarray(rotvecs, dtype=np.float64))  # (M, 15, 4)
    position = np.linspace(0.0, len(quats) - 1, int(frame_count))
    low = np.floor(position).astype(int)
    high = np.minimum(low + 1, len(quats) - 1)
    weight = np.broadcast_to((position - low)[:, None], (len(position), quats.shape[1]))
    return rotations.quat_to_rotvec(slerp(quats[low], quats[high], weight))


def _blend(start, end, weights):
    """Per-joint slerp from pose `start` (15, 3) to pose(s) `end` ((15, 3) or (F, 15, 3)) by (F,) weights."""
    end = np.broadcast_to(end, (len(weights),) + np.shape(start))
    q0 = np.broadcast_to(rotations.rotvec_to_quat(start), end.shape[:-1] + (4,))
    w = np.broadcast_to(np.asarray(weights)[:, None], end.shape[:-1])
    return rotations.quat_to_rotvec(slerp(q0, rotations.rotvec_to_quat(end), w))


def envelope(frame_count, rise_start, rise_end, fall_start, fall_end):
    """(F,) 0 -> 1 -> 0 with minimum-jerk rise and fall; the arguments are fractions of the clip."""
    s = np.linspace(0.0, 1.0, int(frame_count))
    rise = minimum_jerk((s - rise_start) / (rise_end - rise_start))
    fall = minimum_jerk((s - fall_start) / (fall_end - fall_start))
    return rise * (1.0 - fall)


def _check_request(behaviour, arm, frame_count):
    if behaviour not in spaces.BEHAVIOURS:
        raise RLAnimateError(f"Unknown behaviour {behaviour!r}: use POINT or WAVE.")
    if arm not in skeleton.ARMS:
        raise RLAnimateError(f"Unknown arm {arm!r}: use LEFT or RIGHT.")
    if int(frame_count) < 2:
        raise RLAnimateError(f"A gesture needs at least 2 frames, got {frame_count}.")


class NearestClip:
    """Motion-matching retrieval over labelled training clips (MotionClip-like: behaviour, arm,
    attributes, rotvecs)."""

    def __init__(self, clips):
        self.clips = list(clips)

    def nearest(self, behaviour, arm, attributes):
        """The training clip of `behaviour` and `arm` whose label is closest to `attributes`."""
        candidates = [c for c in self.clips if c.behaviour.upper() == behaviour and c.arm.upper() == arm]
        if not candidates:
            raise RLAnimateError(f"No {behaviour.lower()} training clip uses the {arm.lower()} arm: "
                                 "add one to the library to use the nearest-clip baseline.")
        return min(candidates, key=lambda c: self.label_distance(behaviour, c.attributes, attributes))

    @staticmethod
    def label_distance(behaviour, a, b):
        """Angle (rad) between pointing directions, or |difference| of exaggerations."""
        if behaviour == "POINT":
            a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
            cos = a @ b / (np.linalg.norm(a) * np.linalg.norm(b))
            return float(np.arccos(np.clip(cos, -1.0, 1.0)))
        return abs(float(np.ravel(a)[0]) - float(np.ravel(b)[0]))

    def generate(self, behaviour, arm, attributes, frame_count):
        _check_request(behaviour, arm, frame_count)
        return time_warp(self.nearest(behaviour, arm, attributes).rotvecs, frame_count)


class ProceduralIK:
    """IK-constraint gestures on the sample rig, loaded into the current bpy session beside anything
    already there (such as the FK environment's rigs)."""

    def __init__(self, neutral, rig_path=bpy_support.SAMPLE_RIG_BLEND):
        self.neutral = np.asarray(neutral, dtype=np.float64)  # (15, 3)
        self._bpy = bpy_support.import_bpy()
        self.rig = bpy_support.load_rig(rig_path)
        self.rig.animation_data_clear()
        self.rig.name = "RLAnimate_ProceduralIK"
        self.target = self._bpy.data.objects.new("RLAnimate_ProceduralIK_target", None)
        self._bpy.context.scene.collection.objects.link(self.target)
        self._bpy.context.view_layer.update()
        self.scale = float(np.mean(self.rig.matrix_world.to_scale()))  # object units -> metres
        self._pose_bones = {skeleton.strip_prefix(b.name): b for b in self.rig.pose.bones}
        bones = {skeleton.strip_prefix(b.name): b for b in self.rig.data.bones}
        self._rest = {n: np.asarray(b.matrix_local, dtype=np.float64)[:3, :3] for n, b in bones.items()}
        self._parent = {n: (skeleton.strip_prefix(b.parent.name) if b.parent else None) for n, b in bones.items()}
        self._constraint = None

    def _constrain(self, bone, chain_count):
        if self._constraint is not None:
            self._constraint[0].constraints.remove(self._constraint[1])
        pose_bone = self._pose_bones[bone]
        constraint = pose_bone.constraints.new("IK")
        constraint.target = self.target
        constraint.chain_count = chain_count
        constraint.use_tail = True
        constraint.use_stretch = False
        self._constraint = (pose_bone, constraint)

    def _set_pose(self, rotvecs):
        for joint, rotvec in zip(skeleton.ACTION_JOINTS, rotvecs):
            bone = self._pose_bones[joint]
            bone.rotation_mode = "QUATERNION"
            bone.rotation_quaternion = rotations.rotvec_to_quat(rotvec)

    def _solve(self, target_position):
        """(15, 3) local rotations of the constrained pose with the IK target at `target_position` (3,),
        character frame in metres, starting from the neutral pose."""
        local = np.append(np.asarray(target_position) / self.scale, 1.0)  # object space, homogeneous
        world = np.asarray(self.rig.matrix_world, dtype=np.float64) @ local
        self.target.location = world[:3]
        self._bpy.context.view_layer.update()
        pose = {n: np.asarray(b.matrix, dtype=np.float64)[:3, :3] for n, b in self._pose_bones.items()}
        local = []
        for joint in skeleton.ACTION_JOINTS:
            parent = self._parent[joint]
            bind = pose[parent] @ self._rest[parent].T @ self._rest[joint]
            local.append(rotations.matrix_to_rotvec(bind.T @ pose[joint]))
        return np.stack(local)

    def generate(self, behaviour, arm, attributes, frame_count):
        _check_request(behaviour, arm, frame_count)
        self._set_pose(self.neutral)
        side = skeleton.ARM_PREFIX[arm]
        if behaviour == "POINT":
            direction = np.asarray(attributes, dtype=np.float64)
            direction = direction / np.linalg.norm(direction)
            self._constrain(side + "HandIndex1", 4)
            solved = self._solve(skeleton.shoulder_rest_position(arm) + POINT_TARGET_DISTANCE * direction)
            return _blend(self.neutral, solved, envelope(frame_count, *POINT_TIMING))
        exaggeration = float(np.ravel(attributes)[0])
        self._constrain(side + "Hand", 3)
        solved = np.stack([self._solve(p) for p in self.wave_targets(arm, exaggeration, frame_count)])
        return _blend(self.neutral, solved, envelope(frame_count, *WAVE_TIMING))

    def wave_targets(self, arm, exaggeration, frame_count):
        """(F, 3) hand targets of a wave, character frame in metres."""
        side = skeleton.ARM_PREFIX[arm]
        sign = 1.0 if arm == "LEFT" else -1.0
        shoulder = skeleton.shoulder_rest_position(arm)
        length = autolabel.arm_length(side)
        raised = envelope(frame_count, *WAVE_TIMING)  # (F,)
        hang = shoulder + np.array([0.05 * sign, -0.05, -0.9 * length])
        elevation = np.radians(WAVE_ELEVATION[0] + WAVE_ELEVATION[1] * exaggeration)
        up = shoulder + WAVE_REACH * length * np.array([sign * np.sin(elevation) * 0.7,
                                                        -np.sin(elevation) * 0.7, -np.cos(elevation)])
        t = np.arange(frame_count) / FPS
        swing = (WAVE_SWING[0] + WAVE_SWING[1] * exaggeration) * length * np.sin(2 * np.pi * WAVE_FREQUENCY * t)
        positions = hang + raised[:, None] * (up - hang)  # (F, 3)
        positions[:, 0] += raised**2 * swing  # side to side, only once the arm is up
        return positions


class TrainedAgentMethod:
    """A torch RLAnimate agent behind the baselines' generate() interface: the deterministic rollout
    that trainer.evaluate scores, decoded to rotations with the trainer's bounds."""

    def __init__(self, trainer, path):
        self.agent, self.bounds, self.path = trainer.agent, trainer.bounds, Path(path)

    def generate(self, behaviour, arm, attributes, frame_count):
        from .algorithm import rollout_actions
        self.agent.eval()
        actions = rollout_actions(self.agent, spaces.make_objective(behaviour, arm, attributes, frame_count))
        return spaces.decode_action(actions, self.bounds)


class AgentMethod:
    """An exported RLAnimate agent (.npz) behind the baselines' generate() interface: the deterministic
    numpy rollout on the request's objectives, decoded to rotations."""

    def __init__(self, path):
        from rlanimate_addon.core import runtime
        self.path = Path(path)
        self.agent = runtime.load_agent(self.path)

    def generate(self, behaviour, arm, attributes, frame_count):
        objectives = spaces.make_objective(behaviour, arm, attributes, frame_count)
        return spaces.decode_action(self.agent.rollout(objectives), np.asarray(self.agent.action_bounds))


def evaluate_motions(env, motions, clips, references):
    """{'score', 'smoothness', 'clips': [{name, behaviour, score, smoothness}]} of generated
    (F_i, 15, 3) `motions` against `clips` (references: algorithm.ClipReferences), as evaluate.evaluate_clips."""
    ends = np.cumsum([len(m) for m in motions])[:-1]
    positions = np.split(np.asarray(env.evaluate(np.concatenate(motions)).joint_positions), ends)
    rows = []
    for clip, generated in zip(clips, positions):
        _, reference = references.get(clip)
        rows.append({"name": getattr(clip, "name", ""), "behaviour": clip.behaviour.lower(),
                     "score": float(metrics.score(generated, reference)),
                     "smoothness": float(metrics.smoothness(generated))})
    return {"score": float(np.mean([r["score"] for r in rows])),
            "smoothness": float(np.mean([r["smoothness"] for r in rows])), "clips": rows}


def generate_for(baseline, clips):
    """The baseline's answer to each clip's own request (label and length): list of (F_i, 15, 3)."""
    return [baseline.generate(c.behaviour.upper(), c.arm.upper(), c.attributes, len(c.rotvecs)) for c in clips]


METHOD_LABELS = {"rlanimate": "RLAnimate", "nearest_clip": "Nearest clip", "procedural_ik": "Procedural IK"}
METRIC_LABELS = {"score": "score", "smoothness": "smoothness", "label_error": "label error (autolabel)",
                 "forearm_angle_deg": "forearm angle at hold (deg)"}


def write_results(results_dir, section, description, sets):
    """Merge one section into results_dir/baselines.json and rewrite baselines.md from the whole file.

    sets: {set name: {method: {metric: value, ...}}}; the other sections are kept as they are, so
    the sample-library and the real-data runs each update their own.
    """
    import json
    results_dir = Path(results_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    path = results_dir / "baselines.json"
    table = json.loads(path.read_text()) if path.is_file() else {}
    table[section] = {"description": description, "sets": sets}
    path.write_text(json.dumps(table, indent=2) + "\n")
    lines = ["# RLAnimate against the baselines an animator would try first", "",
             "Nearest clip: the training clip with the closest label, time-warped to the requested length. "
             "Procedural IK: Blender's IK constraint with minimum-jerk timing (trainer/baselines.py). "
             "Each method answers the held-out clip's own request (label and length); score and smoothness "
             "as in docs/METRICS.md. Discussion: docs/REALMOCAP.md.", ""]
    for name, entry in table.items():
        lines += [f"## {name}", "", entry["description"], ""]
        for set_name, methods in entry["sets"].items():
            metric_names = [m for m in METRIC_LABELS if any(m in row for row in methods.values())]
            lines += [f"**{set_name}**", "", "| method | " + " | ".join(METRIC_LABELS[m] for m in metric_names) + " |",
                      "|---|" + "---|" * len(metric_names)]
            for method, row in methods.items():
                lines.append(f"| {METHOD_LABELS.get(method, method)} | "
                             + " | ".join(f"{row[m]:.3g}" if m == "label_error" else f"{row[m]:.2f}"
                                          for m in metric_names) + " |")
            lines.append("")
    (results_dir / "baselines.md").write_text("\n".join(lines))


def sample_library_comparison(agent_path, manifest):
    """{set: {method: {score, smoothness[, label_error]}}} on the sample library's held-out clips, per
    behaviour; for waves the label error compares the auto-labels of the generated and the real clip
    (the library's own exaggeration scale is the generator's, not autolabel's)."""
    from .algorithm import ClipReferences
    from .evaluate import select_clips
    from .train import Session
    session = Session(manifest)
    train_clips = session.train_clips
    methods = {"rlanimate": AgentMethod(agent_path), "nearest_clip": NearestClip(train_clips),
               "procedural_ik": ProceduralIK(neutral_pose(train_clips))}
    references = ClipReferences(session.env)
    sets = {}
    for behaviour in ("point", "wave"):
        clips = select_clips(session.test_clips, behaviour)
        rows = {}
        for name, method in methods.items():
            motions = generate_for(method, clips)
            result = evaluate_motions(session.env, motions, clips, references)
            rows[name] = {key: result[key] for key in ("score", "smoothness")}
            if behaviour == "wave":
                rows[name]["label_error"] = float(np.mean([
                    abs(autolabel.label_wave(m).exaggeration - autolabel.label_wave(c.rotvecs).exaggeration)
                    for m, c in zip(motions, clips)]))
        sets[f"{behaviour}, held-out clips ({len(clips)})"] = rows
    return sets, methods["rlanimate"].agent.metadata.get("training", {})


def main(argv=None):
    """python -m trainer.baselines [--agent PATH] [--clips MANIFEST] [--results DIR]: the sample-library
    section of docs/results/baselines.json and .md."""
    import argparse
    import sys

    import torch

    from .bpy_support import new_empty_scene, script_args
    from .train import DEFAULT_MANIFEST, INSTALLED_AGENT, REPO_ROOT, RESULTS_DIR
    parser = argparse.ArgumentParser(prog="python -m trainer.baselines", description=main.__doc__.split(":")[0])
    parser.add_argument("--agent", default=str(INSTALLED_AGENT), help="exported RLAnimate agent (.npz)")
    parser.add_argument("--clips", default=str(DEFAULT_MANIFEST))
    parser.add_argument("--results", default=str(RESULTS_DIR))
    options = parser.parse_args(script_args(argv))
    torch.set_num_threads(1)
    new_empty_scene()
    try:
        sets, training = sample_library_comparison(options.agent, options.clips)
    except RLAnimateError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    agent = Path(options.agent).resolve()
    shown = agent.relative_to(REPO_ROOT) if agent.is_relative_to(REPO_ROOT) else agent  # no machine paths in docs
    provenance = "untrained" if training.get("untrained") else ", ".join(
        f"{k} {training[k]}" for k in ("behaviour", "variant", "preset", "epochs", "episodes") if k in training)
    write_results(options.results, "sample library",
                  f"The 10 held-out clips of sample_rigs/clips (targets and exaggerations no training clip has). "
                  f"RLAnimate: `{shown}` ({provenance}). "
                  f"Regenerate: `nice -n 10 python -m trainer.baselines --agent {shown}`.", sets)
    print(open(Path(options.results) / "baselines.md").read())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
