"""Point aim before and after aim correction, on random unseen targets, with numpy FK on the canonical skeleton.

For targets 1.5-4 m from the shoulder (azimuth -30..70 degrees towards the arm's side, elevation
-25..45), prints the angle between the index finger and the line from its base to the target at
the apex (the frame where the finger base is farthest from its start), and the smoothness of the
description joints, for the raw agent and after `core.aim.aim_at`, as docs/EXTENSION.md reports.

Run: `nice -n 10 python benchmarks/aim_benchmark.py [--targets 80] [--frames 120] [--seed 7] [--agent FILE]`
"""
import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rlanimate_addon.core import aim, gesture, kinematics, metrics, runtime, skeleton  # noqa: E402


def random_target(arm, rng):
    side = 1.0 if arm == "LEFT" else -1.0
    azimuth = math.radians(rng.uniform(-30.0, 70.0)) * side
    elevation = math.radians(rng.uniform(-25.0, 45.0))
    direction = np.array([math.sin(azimuth) * math.cos(elevation), -math.cos(azimuth) * math.cos(elevation),
                          math.sin(elevation)])
    return skeleton.shoulder_rest_position(arm) + rng.uniform(1.5, 4.0) * direction


def apex_angle(rotvecs, arm, target):
    """Degrees between the finger line and the target at the apex frame."""
    _, base, finger, _ = aim.finger_lines(rotvecs, arm)
    peak = int(np.argmax(np.linalg.norm(base - base[0], axis=1)))
    to_target = (target - base[peak]) / np.linalg.norm(target - base[peak])
    return math.degrees(math.acos(np.clip(finger[peak] @ to_target, -1.0, 1.0)))


def smoothness(rotvecs):
    pose = kinematics.pose_matrices({j: rotvecs[:, i] for i, j in enumerate(skeleton.ACTION_JOINTS)})
    joints = [kinematics.bone_index(bone) for _, bone in skeleton.DESCRIPTION_JOINTS]
    return metrics.smoothness(kinematics.head_positions(pose)[:, joints])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--targets", type=int, default=80)
    parser.add_argument("--frames", type=int, default=120)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--agent", default=str(ROOT / "rlanimate_addon" / "agents" / "default.npz"))
    args = parser.parse_args()
    agent = runtime.load_agent(args.agent)
    rest_heads = gesture.canonical_rig().rest_heads
    rng = np.random.default_rng(args.seed)
    rows = []  # (raw angle, aimed angle, raw smoothness, aimed smoothness)
    for k in range(args.targets):
        arm = skeleton.ARMS[k % 2]
        target = random_target(arm, rng)
        objectives = gesture.build_objectives(
            agent.space, "POINT", arm, args.frames, targets=np.tile(target, (args.frames, 1)), rest_heads=rest_heads
        )
        raw = gesture.run_agent(agent, "POINT", objectives)  # (N, 15, 3)
        aimed = aim.aim_at(raw, arm, target)
        rows.append((apex_angle(raw, arm, target), apex_angle(aimed, arm, target), smoothness(raw), smoothness(aimed)))
    rows = np.array(rows)
    print(f"{args.targets} targets, {args.frames} frames, seed {args.seed}")
    for name, column in (("raw agent", 0), ("aim-corrected", 1)):
        angles = rows[:, column]
        print(f"{name:14s} apex angle deg: median {np.median(angles):.2f}  p90 {np.percentile(angles, 90):.2f}  "
              f"max {angles.max():.2f}  share <= 5 deg {np.mean(angles <= 5.0):.0%}")
    drop = rows[:, 2] - rows[:, 3]
    print(f"smoothness: raw min {rows[:, 2].min():.2f} mean {rows[:, 2].mean():.2f}; aimed min {rows[:, 3].min():.2f} "
          f"mean {rows[:, 3].mean():.2f}; largest drop {drop.max():.2f}")


if __name__ == "__main__":
    main()
