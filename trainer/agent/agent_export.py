"""Write a trained agent as the data-only file the extension loads (rlanimate_addon/core/agent_file.py).

`export_agent(agent, path, metadata)` writes every weight as float32 and the metadata as JSON text
in one `.npz`, atomically (trainer/files.py). (rlanimate_addon/blender/export.py is the other export:
it writes an FBX.)
"""
import datetime
import json
import subprocess
from dataclasses import asdict, is_dataclass

import numpy as np

from rlanimate_addon.core import agent_file, behaviours, skeleton, spaces
from trainer.files import atomic_open
from trainer.paths import REPO_ROOT

#: Average gesture length in frames (30 fps) when the caller gives none: the UI's default length.
FALLBACK_AVERAGE_FRAMES = dict.fromkeys(behaviours.BEHAVIOURS, 90)


def export_agent(agent, path, metadata=None):
    """Atomically write `agent` (an RLAnimateAgent) to `path` (.npz); returns the full metadata written.

    `metadata` may hold: "training" (provenance: clips, seed, epochs, ...; the git commit and date
    are added), "train_config" (a TrainConfig or dict), "average_frames" ({behaviour: n} for each
    behaviour trained, the mean length of its training clips), "wave_rhythm" (a
    core.rhythm.RhythmModel's dict, or None: the paper's wave objective), "action_bounds" ((45, 2), default the
    spaces' bounds), and any other JSON-serialisable entries (kept as given).
    """
    extra = dict(metadata or {})
    bounds = np.asarray(extra.pop("action_bounds", spaces.DEFAULT_ACTION_BOUNDS), dtype=np.float64)
    train_config = extra.pop("train_config", None)
    full = {
        "format": agent_file.FORMAT_NAME,
        "format_version": agent_file.FORMAT_VERSION,
        "variant": agent.variant,
        "agent_config": agent.config.to_dict(),
        "train_config": asdict(train_config) if is_dataclass(train_config) else train_config,
        "spaces": _spaces(),
        "action_bounds": bounds.tolist(),
        "rig": {"convention": "mixamo", "bone_prefix": skeleton.PREFIX,
                "required_bones": list(skeleton.REQUIRED_BONES)},
        "average_frames": {k: float(v) for k, v in extra.pop("average_frames", FALLBACK_AVERAGE_FRAMES).items()},
        "wave_rhythm": extra.pop("wave_rhythm", None),
        "training": {"git_commit": _git_commit(), "date": _now(), **extra.pop("training", {})},
        **extra,
    }
    arrays = {name: tensor.detach().cpu().numpy().astype(np.float32)
              for name, tensor in agent.state_dict().items()}
    arrays[agent_file.METADATA_KEY] = np.array(json.dumps(full, indent=1, sort_keys=True, default=_json_value))
    with atomic_open(path) as handle:
        np.savez(handle, **arrays)
    return full


def _json_value(value):
    """numpy scalars and arrays in the metadata, as JSON numbers and lists."""
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    raise TypeError(f"Agent metadata must be JSON data; got {type(value).__name__}")


def _spaces():
    return {"objective_size": spaces.OBJECTIVE_SIZE, "description_size": spaces.DESCRIPTION_SIZE,
            "action_size": spaces.ACTION_SIZE, "behaviours": list(behaviours.BEHAVIOURS),
            "behaviour_type": dict(spaces.BEHAVIOUR_TYPE), "action_joints": list(skeleton.ACTION_JOINTS),
            "action_encoding": "rotation vector relative to rest, (r - low) / (high - low)",
            "description_joints": [list(j) for j in skeleton.DESCRIPTION_JOINTS],
            "effectors": [list(e) for e in skeleton.EFFECTORS]}


def _git_commit():
    try:
        result = subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO_ROOT, capture_output=True, text=True,
                                timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if result.returncode != 0:
        return None
    return result.stdout.strip() or None


def _now():
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
