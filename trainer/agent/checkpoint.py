"""Training checkpoints: one file holding everything a resumed run needs to continue bit for bit.

A checkpoint is a dict of plain data and tensors (no pickled classes), so it loads with
`torch.load(weights_only=True)`: the trainer's `state_dict()` (agent, optimiser, buffer, epoch,
history, and the python / numpy / torch RNG states) plus a format version and the run's arguments.
It is written atomically (trainer/files.py), so a run killed mid-write leaves the previous checkpoint intact.
"""
import random
from pathlib import Path

import torch

from rlanimate_addon.core.errors import RLAnimateError
from trainer.files import atomic_open

#: 2: episodes hold the pointing term's "hold" frames (trainer/agent/buffer.py).
FORMAT_VERSION = 2
FILENAME = "checkpoint.pt"


def capture_rng_states(numpy_generator, torch_generator):
    """The global python and torch RNGs and the trainer's own generators, as checkpointable data."""
    return {
        "python": _python_state_to_data(random.getstate()),
        "numpy": numpy_generator.bit_generator.state,
        "torch": torch.get_rng_state(),
        "torch_generator": torch_generator.get_state(),
    }


def restore_rng_states(states, numpy_generator, torch_generator):
    random.setstate(_python_state_from_data(states["python"]))
    numpy_generator.bit_generator.state = states["numpy"]
    torch.set_rng_state(states["torch"])
    torch_generator.set_state(states["torch_generator"])


def save(path, trainer_state, run_arguments):
    """Atomically write `trainer_state` (from Trainer.state_dict) and the run's arguments to `path`."""
    payload = {"format_version": FORMAT_VERSION, "arguments": dict(run_arguments), "trainer": trainer_state}
    with atomic_open(path) as handle:
        torch.save(payload, handle)


def load(path):
    """The checkpoint at `path` as written by `save`; RLAnimateError if it is missing or damaged."""
    path = Path(path)
    if not path.is_file():
        raise RLAnimateError(f"No checkpoint at {path}: start a new run without --resume, "
                             f"or point --output at the folder of the run to resume.")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as error:  # torch raises several types for damaged files
        raise RLAnimateError(f"The checkpoint {path} is damaged ({error}): delete it and start again.") from error
    if not isinstance(payload, dict) or payload.get("format_version") != FORMAT_VERSION:
        raise RLAnimateError(f"The checkpoint {path} is not format version {FORMAT_VERSION}: "
                             f"it was written by another version of the trainer; start a new run.")
    return payload


def _python_state_to_data(state):
    version, internal, gauss = state
    return {"version": version, "internal": torch.tensor(internal, dtype=torch.int64), "gauss": gauss}


def _python_state_from_data(data):
    return data["version"], tuple(int(x) for x in data["internal"].tolist()), data["gauss"]
