"""Training checkpoints: one file holding everything a resumed run needs to continue bit for bit.

A checkpoint is a dict of plain data and tensors (no pickled classes), so it loads with
`torch.load(weights_only=True)`: the trainer's `state_dict()` (agent, optimiser, buffer, epoch,
history, and the python / numpy / torch RNG states) plus a format version and the run's arguments.
It is written atomically (trainer/files.py), so a run killed mid-write leaves the previous checkpoint intact.
`load` returns its dicts as _CheckedDicts (which name a missing key); `save` writes plain dicts whatever it is
given, so a run resumed any number of times writes a checkpoint that loads.
"""
import random
import re
from collections import Counter, OrderedDict
from pathlib import Path
from typing import Any

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
    payload = _plain({"format_version": FORMAT_VERSION, "arguments": run_arguments, "trainer": trainer_state})
    with atomic_open(path) as handle:
        torch.save(payload, handle)


def load(path):
    """The checkpoint at `path` as written by `save`; RLAnimateError if it is missing or damaged.

    Every dict in it names its place in the file: a key that a reader (the run's settings, the
    trainer's load_state_dict) needs and the file lacks raises an RLAnimateError naming the checkpoint
    and the key, not a KeyError.
    """
    path = Path(path)
    if not path.is_file():
        raise RLAnimateError(f"No checkpoint at {path}: start a new run without --resume, "
                             f"or point --output at the folder of the run to resume.")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as error:  # torch raises several types for damaged files
        payload = _written_after_a_resume(path, error)
    if not isinstance(payload, dict) or payload.get("format_version") != FORMAT_VERSION:
        raise RLAnimateError(f"The checkpoint {path} is not format version {FORMAT_VERSION}: "
                             f"it was written by another version of the trainer; start a new run.")
    return _checked(payload, path, "")


def _written_after_a_resume(path: Path, error: Exception) -> dict:
    """The checkpoint a run resumed by an earlier trainer wrote: it saved the dicts `load` had returned as
    _CheckedDicts (with their PosixPath), which weights_only refuses. Those load here as Counters (a dict
    type torch builds; the path as None) and come back as plain dicts. Any other file raises the
    RLAnimateError of a damaged checkpoint, with torch's reason (`error`)."""
    def ignored(*_):
        return None
    try:
        with torch.serialization.safe_globals([(Counter, f"{__name__}._CheckedDict"), (ignored, "pathlib.PosixPath")]):
            return _plain(torch.load(path, map_location="cpu", weights_only=True))
    except Exception:
        raise RLAnimateError(f"The checkpoint {path} is damaged ({_reason(error)}), so the run cannot continue "
                             f"from it: {_RESTART}") from error


#: What a run whose checkpoint cannot be read can do instead.
_RESTART = ("put back a copy of the run's folder if you have one, or train the run again: train.py with --overwrite "
            "(which replaces it) or another --output folder; an experiment after moving the run's folder away.")


def _plain(value: Any) -> Any:
    """`value` with every dict in it but torch's OrderedDict state_dicts a plain dict (a _CheckedDict that
    `load` returned and a resumed trainer kept), lists and tuples rebuilt around them."""
    if isinstance(value, dict) and not isinstance(value, OrderedDict):
        return {key: _plain(item) for key, item in value.items()}
    if type(value) in (list, tuple):
        return type(value)(_plain(item) for item in value)
    return value


def _reason(error):
    """What torch says is wrong with a file, without its advice to load with weights_only=False (which
    would unpickle, and could run, whatever the file holds) or its terminal colour codes: its first sentence,
    on one line."""
    text = re.sub(r"\x1b\[[0-9;]*m", "", str(error))
    if "WeightsUnpickler error:" in text:  # torch's advice comes first, the reason after this marker
        text = text.split("WeightsUnpickler error:", 1)[1]
    first = next((line.strip() for line in text.splitlines() if line.strip()), "")
    return first.split(". ", 1)[0].rstrip(".") or type(error).__name__


class _CheckedDict(dict):
    """A checkpoint's dict that names the checkpoint and the missing key when a reader needs one."""

    def __missing__(self, key):
        raise RLAnimateError(f"The checkpoint {self.path} lacks {self.place}{key}: it is incomplete, or was "
                             f"edited or written by another trainer; {_RESTART}")


def _checked(value, path, place):
    """`value` with every plain dict in it a _CheckedDict, lists and tuples rebuilt around them; anything
    else as it is (tensors, and torch's own OrderedDict state_dicts, which torch checks itself)."""
    if type(value) is dict:
        checked = _CheckedDict((key, _checked(item, path, f"{place}{key}.")) for key, item in value.items())
        checked.path, checked.place = path, place
        return checked
    if type(value) in (list, tuple):
        return type(value)(_checked(item, path, f"{place}{k}.") for k, item in enumerate(value))
    return value


def _python_state_to_data(state):
    version, internal, gauss = state
    return {"version": version, "internal": torch.tensor(internal, dtype=torch.int64), "gauss": gauss}


def _python_state_from_data(data):
    return data["version"], tuple(int(x) for x in data["internal"].tolist()), data["gauss"]
