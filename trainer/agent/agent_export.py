"""Write a trained agent as the data-only file the extension loads (rlanimate_addon/core/agent_file.py).

`export_agent(agent, path, metadata)` writes every weight as float32 and the metadata as JSON text
in one `.npz`, atomically (trainer/files.py). (rlanimate_addon/blender/export.py is the other export:
it writes an FBX.)
"""
import datetime
import json
import subprocess
from dataclasses import asdict, is_dataclass
from pathlib import Path

import numpy as np

from rlanimate_addon.core import agent_file, skeleton, spaces
from trainer import paths
from trainer.files import atomic_open

#: Entries of the metadata's "training" that are paths on the training machine.
TRAINING_PATHS = ("clips",)
#: Average gesture length in frames (30 fps) of each behaviour when the caller gives none: the UI's default.
FALLBACK_AVERAGE_FRAMES = 90


def export_agent(agent, path, metadata=None):
    """Atomically write `agent` (an RLAnimateAgent) to `path` (.npz); returns the full metadata written.

    `metadata` may hold: "training" (provenance: clips, seed, epochs, ...; the git commit and date
    are added, and the clips' path is recorded relative to the repository, or as its file name),
    "train_config" (a TrainConfig or dict), "average_frames" ({behaviour: n} for each behaviour
    trained, the mean length of its training clips), "wave_rhythm" (a core.rhythm.RhythmModel's dict,
    or None: the paper's wave objective), "action_bounds" ((45, 2), default the spaces' bounds), and
    any other JSON-serialisable entries (kept as given). The file declares the agent's behaviours
    (`agent.space`: name and kind each, in objective order).
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
        "behaviours": [b.to_dict() for b in agent.space.behaviours],
        "spaces": _spaces(agent.space),
        "action_bounds": bounds.tolist(),
        "rig": {"convention": "mixamo", "bone_prefix": skeleton.PREFIX,
                "required_bones": list(skeleton.REQUIRED_BONES)},
        "average_frames": {k: float(v) for k, v in extra.pop(
            "average_frames", dict.fromkeys(agent.space.names, FALLBACK_AVERAGE_FRAMES)).items()},
        "wave_rhythm": extra.pop("wave_rhythm", None),
        "training": _training(extra.pop("training", {})),
        **extra,
    }
    arrays = {name: tensor.detach().cpu().numpy().astype(np.float32)
              for name, tensor in agent.state_dict().items()}
    arrays[agent_file.METADATA_KEY] = np.array(json.dumps(full, indent=1, sort_keys=True, default=_json_value))
    with atomic_open(path) as handle:
        np.savez(handle, **arrays)
    return full


def _training(training):
    """The provenance entry: the git commit and date added, and the paths among `training` (TRAINING_PATHS)
    as recorded_path gives them."""
    recorded = {key: recorded_path(value) if key in TRAINING_PATHS and value is not None else value
                for key, value in training.items()}
    return {"git_commit": _git_commit(), "date": _now(), **recorded}


def recorded_path(path):
    """A training path as an agent file records it: relative to the repository when inside it, else the
    file's name alone, so that no agent carries the folders of the machine it was trained on."""
    shown = paths.shown(path)
    return (Path(shown.name) if shown.is_absolute() else shown).as_posix()


def _json_value(value):
    """numpy scalars and arrays in the metadata, as JSON numbers and lists."""
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    raise TypeError(f"Agent metadata must be JSON data; got {type(value).__name__}")


def _spaces(space):
    return {
        "objective_size": space.size,
        "description_size": spaces.DESCRIPTION_SIZE,
        "action_size": spaces.ACTION_SIZE,
        "behaviour_labels": dict(zip(space.names, space.labels.tolist(), strict=True)),
        "action_joints": list(skeleton.ACTION_JOINTS),
        "action_encoding": "rotation vector relative to rest, (r - low) / (high - low)",
        "description_joints": [list(j) for j in skeleton.DESCRIPTION_JOINTS],
        "effectors": [list(e) for e in skeleton.EFFECTORS],
    }


def _git_commit():
    try:
        result = subprocess.run(["git", "rev-parse", "HEAD"], cwd=paths.REPO_ROOT, capture_output=True, text=True,
                                timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if result.returncode != 0:
        return None
    return result.stdout.strip() or None


def _now():
    return datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
