"""Write a trained agent as the data-only file the extension loads (rlanimate_addon/core/agent_file.py).

    python trainer/export.py [PATH]     writes an untrained default-config agent (for development)

`export_agent(agent, path, metadata)` writes every weight as float32 and the metadata as JSON text
in one `.npz`, to a temporary file that is then moved into place, so a reader never sees half a file.
"""
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
if str(REPO_ROOT) not in sys.path:
    sys.path.insert(0, str(REPO_ROOT))

import datetime  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import subprocess  # noqa: E402
from dataclasses import asdict, is_dataclass  # noqa: E402

import numpy as np  # noqa: E402

from rlanimate_addon.core import agent_file, skeleton, spaces  # noqa: E402

DEFAULT_PATH = REPO_ROOT / "rlanimate_addon" / "agents" / "default.npz"
#: Average gesture length in frames (30 fps) when the caller gives none: the UI's default length.
FALLBACK_AVERAGE_FRAMES = {"POINT": 90, "WAVE": 90}


def export_agent(agent, path, metadata=None):
    """Atomically write `agent` (an RLAnimateAgent) to `path` (.npz); returns the full metadata written.

    `metadata` may hold: "training" (provenance: clips, seed, epochs, ...; the git commit and date
    are added), "train_config" (a TrainConfig or dict), "average_frames" ({behaviour: n} for each
    behaviour trained, the mean length of its training clips), "action_bounds" ((45, 2), default the
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
        "training": {"git_commit": _git_commit(), "date": _now(), **extra.pop("training", {})},
        **extra,
    }
    arrays = {name: tensor.detach().cpu().numpy().astype(np.float32)
              for name, tensor in agent.state_dict().items()}
    arrays[agent_file.METADATA_KEY] = np.array(json.dumps(full, indent=1, sort_keys=True, default=_json_value))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(temporary, "wb") as handle:
            np.savez(handle, **arrays)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return full


def _json_value(value):
    """numpy scalars and arrays in the metadata, as JSON numbers and lists."""
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    raise TypeError(f"Agent metadata must be JSON data; got {type(value).__name__}")


def _spaces():
    return {"objective_size": spaces.OBJECTIVE_SIZE, "description_size": spaces.DESCRIPTION_SIZE,
            "action_size": spaces.ACTION_SIZE, "behaviours": list(spaces.BEHAVIOURS),
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


def main(argv=None):
    """Export an untrained default-config RLAnimate agent (seed 0) to argv[0] or DEFAULT_PATH."""
    import torch

    from trainer.config import load_preset
    from trainer.models import RLAnimateAgent

    argv = sys.argv[1:] if argv is None else argv
    path = Path(argv[0]) if argv else DEFAULT_PATH
    torch.set_num_threads(1)
    torch.manual_seed(0)
    agent_config, train_config = load_preset("default")
    export_agent(RLAnimateAgent(agent_config), path,
                 {"train_config": train_config, "training": {"untrained": True, "seed": 0, "epochs": 0}})
    print(f"wrote an untrained agent to {path}")


if __name__ == "__main__":
    main()
