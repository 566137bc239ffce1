"""How long a gesture of your own takes to train until it is usable: the "hello" a new user makes from six clips.

Run: `nice -n 10 python benchmarks/taught_gesture_benchmark.py [--epochs 10 20 40]`. As docs/TRAINING.md ("Teach it
a new gesture") says, a user copies six raise-hand clips of the sample library into a folder, renames them hello,
keeps four point and wave clips beside them and writes a manifest (one hello clip held out); this trains that
library with the default preset (`trainer/train.py`, seed 2) for each length from the start, and measures each agent
as the add-on plays it (its exported agent.npz, the numpy runtime):
    held-out error     the held-out hello clip's hand height error (arm lengths; the kind's measure)
    rises              whether the hand's peak height rises with the exaggeration (Spearman over 0, 0.25 ... 1, both
                       arms; above 0.8) and by how much (arm lengths from 0 to 1, the smaller arm's; the clips'
                       own rise is about 0.45)
    free arm           the agent's own free-arm rise on those requests (arm lengths), and whether the file declares
                       HELLO's free arm still, so that Generate holds it where it was
A taught gesture is usable when the held-out error is at most 0.1 arm lengths (the raise measure's bound), its
height rises with the exaggeration on both arms by at least USABLE_SPAN, and its free arm is held. The section
"Taught gesture" of docs/BENCHMARKS.md is replaced with the table and the training CPU time of each length.
"""
import argparse
import json
import os
import platform
import shutil
import sys
import tempfile
from datetime import UTC, datetime
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO_ROOT))

import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)
from scipy.stats import spearmanr  # noqa: E402

from rlanimate_addon.core import behaviour_metrics, kinematics, runtime, spaces  # noqa: E402
from trainer.evaluation.baselines import agent_motion  # noqa: E402
from trainer.paths import CLIP_DIR, DEFAULT_MANIFEST  # noqa: E402
from trainer.scripts import train  # noqa: E402

HEADING = "## Taught gesture"
COMMAND = "nice -n 10 python benchmarks/taught_gesture_benchmark.py"
#: The sample raise-hand clips renamed hello (three per arm over the exaggeration's range), the last held out.
HELLO = ("raise_hand_left_000.fbx", "raise_hand_left_012.fbx", "raise_hand_left_023.fbx",
         "raise_hand_right_000.fbx", "raise_hand_right_023.fbx", "raise_hand_right_012.fbx")
KEPT = ("point_left_000.fbx", "point_right_001.fbx", "wave_left_000.fbx", "wave_right_001.fbx")
EXAGGERATIONS = (0.0, 0.25, 0.5, 0.75, 1.0)
USABLE_HEIGHT_ERROR = behaviour_metrics.RAISE_HEIGHT_ERROR
#: Arm lengths: the least rise of the hand's peak height from exaggeration 0 to 1 of a usable gesture.
USABLE_SPAN = 0.1
LOAD_AT_START = os.getloadavg()[0]


def write_library(folder: Path) -> None:
    """HELLO renamed hello_*.fbx and KEPT, with a manifest naming them (the last hello clip held out)."""
    sample = {entry["file"]: entry for entry in json.loads(DEFAULT_MANIFEST.read_text())["clips"]}
    entries = []
    for k, name in enumerate(HELLO):
        renamed = name.replace("raise_hand", "hello")
        shutil.copy(CLIP_DIR / name, folder / renamed)
        entries.append({**sample[name], "file": renamed, "behaviour": "hello",
                        "split": "test" if k == len(HELLO) - 1 else "train"})
    for name in KEPT:
        shutil.copy(CLIP_DIR / name, folder / name)
        entries.append({**sample[name], "split": "train"})
    (folder / "manifest.json").write_text(json.dumps({"fps": 30, "clips": entries}, indent=1))


def measure(run: Path) -> dict:
    """The usability measures of a finished run (see the module docstring)."""
    result = json.loads((run / "report.json").read_text())
    held_out = next(c for c in result["held_out"]["clips"] if c["behaviour"] == "hello")
    agent = runtime.load_agent(run / "agent.npz")
    frames = int(round(agent.average_frames["HELLO"]))
    rises, spans, free = [], [], []
    for arm in ("LEFT", "RIGHT"):
        heights = []
        for exaggeration in EXAGGERATIONS:
            positions = spaces.description_joint_positions(kinematics.describe(
                agent_motion(agent, "HELLO", arm, exaggeration, frames)))
            heights.append(behaviour_metrics.peak_hand_height(positions, arm))
            free.append(behaviour_metrics.free_arm_rise(positions, arm))
        rises.append(float(spearmanr(EXAGGERATIONS, heights).correlation) if np.ptp(heights) > 0 else float("nan"))
        spans.append(heights[-1] - heights[0])
    held = "HELLO" in agent.still_free_arm
    usable = (held_out["hand_height_error"] <= USABLE_HEIGHT_ERROR and min(rises) > 0.8 and min(spans) >= USABLE_SPAN
              and held)
    return {"epochs": result["epochs"], "cpu_minutes": result["train_cpu_seconds"] / 60,
            "held_out_error": held_out["hand_height_error"], "held_out_score": held_out["score"],
            "spearman": rises, "span": min(spans), "free_arm_rise_max": max(free), "free_arm_held": held,
            "usable": bool(usable)}


def section(rows: list[dict], epochs: list[int], load: str) -> str:
    """The docs/BENCHMARKS.md section of `rows` (measure's, for `epochs`), the machine's `load` said."""
    now = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    lines = [HEADING, "",
             "How long a user's own gesture takes to train until it is usable: six raise-hand clips of the sample "
             "library renamed hello (one held out) beside four point and wave clips, the default preset, each "
             "length trained from the start (docs/TRAINING.md, \"Teach it a new gesture\"). Usable: the held-out "
             f"clip's hand height error at most {USABLE_HEIGHT_ERROR} arm lengths, the height rising with the "
             f"exaggeration on both arms (Spearman above 0.8) by at least {USABLE_SPAN} arm lengths from 0 to 1 (the "
             "clips' own rise about 0.45), and the free arm held by the add-on.", "",
             f"Regenerate: `{COMMAND} --epochs {' '.join(map(str, epochs))}`", "",
             f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs (load average "
             f"{load}), Python {platform.python_version()}. Date: {now}.", "",
             "| epochs | training CPU min | held-out hand height error (arm lengths) | held-out score | "
             "height rises, Spearman left / right | rise from 0 to 1 (arm lengths) | agent's own free-arm rise (max) | "
             "free arm held | usable |",
             "|---:|---:|---:|---:|---|---:|---:|---|---|"]
    lines += [f"| {r['epochs']} | {r['cpu_minutes']:.1f} | {r['held_out_error']:.3f} | {r['held_out_score']:.1f} | "
              f"{r['spearman'][0]:.2f} / {r['spearman'][1]:.2f} | {r['span']:.2f} | {r['free_arm_rise_max']:.2f} | "
              f"{'yes' if r['free_arm_held'] else 'no'} | {'**yes**' if r['usable'] else 'no'} |" for r in rows]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--epochs", type=int, nargs="+", default=[10, 20, 40])
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch) / "hello_library"
        folder.mkdir()
        write_library(folder)
        for epochs in args.epochs:
            run = Path(scratch) / f"run_{epochs}"
            train.main(["train.py", "--clips", str(folder), "--output", str(run), "--epochs", str(epochs),
                        "--eval-every", "0", "--quiet"])
            rows.append(measure(run))
            print(json.dumps(rows[-1]), flush=True)
    text = section(rows, args.epochs, f"{LOAD_AT_START:.1f} at start, {os.getloadavg()[0]:.1f} at the end")
    report.write_section(HEADING, text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
