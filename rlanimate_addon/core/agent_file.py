"""The exported agent file: one `.npz` of float weight arrays plus JSON metadata, read without pickle.

Layout (format FORMAT_NAME, version FORMAT_VERSION):
    "__metadata__"   0-d numpy unicode array holding JSON text (see docs/AGENT.md for its fields)
    "<module>.<parameter>"   one float32 array per torch parameter, named as in the torch state_dict:
        portrayal.layers.K.{weight,bias}        o_t -> self-description d_t     (absent in single_state)
        task_rnn.{weight,bias}_{ih,hh}_l0       GRU h_t = f1(h_{t-1}, o_t)      (absent in single_dynamics)
        behaviour_cell.{weight,bias}_{ih,hh}    GRUCell e_t = f2(e_{t-1}; x_t)
        prior.layers.K.*, posterior.layers.K.*  Gaussian p(z_t | e_t), q(z_t | e_t, d_t)
        animation.layers.K.*, decoder.layers.K.*  Beta over a_t, and p(d_t | h_t, b_t)
`expected_weight_shapes` is the single statement of which arrays an agent of a given config and
variant has; the torch model, the exporter and the numpy runtime all agree with it.
"""
import json
import zipfile
from pathlib import Path

import numpy as np

from . import spaces
from .errors import RLAnimateError

FORMAT_NAME = "rlanimate-agent"
FORMAT_VERSION = 1
METADATA_KEY = "__metadata__"
VARIANTS = ("rlanimate", "single_state", "single_dynamics", "supervised")
#: a_0, the previous action of a sequence's first frame (the middle of every channel's range): part
#: of the agent's definition, shared by the torch model and the numpy runtime.
INITIAL_ACTION = 0.5
#: Metadata fields every agent file has.
REQUIRED_METADATA = ("format", "format_version", "variant", "agent_config", "action_bounds", "average_frames")
_AGENT_SIZES = ("task_size", "behaviour_size", "stochastic_size", "hidden_size", "portrayal_hidden_size",
                "hidden_layers")
_AGENT_SCALARS = ("min_std", "concentration_floor", "concentration_scale")


def uses_portrayal(variant):
    """Whether the variant self-describes with a portrayal model (all but single_state)."""
    return variant != "single_state"


def uses_task_state(variant):
    """Whether the variant keeps a separate task state h_t (all but single_dynamics)."""
    return variant != "single_dynamics"


def mlp_shapes(name, inputs, hidden, layers, outputs):
    """Shapes of an MLP's arrays: `layers` hidden Linear(+tanh) layers of width `hidden`, then a Linear."""
    widths = [inputs] + [hidden] * layers + [outputs]
    shapes = {}
    for k, (n_in, n_out) in enumerate(zip(widths[:-1], widths[1:])):
        shapes[f"{name}.layers.{k}.weight"] = (n_out, n_in)
        shapes[f"{name}.layers.{k}.bias"] = (n_out,)
    return shapes


def gru_shapes(name, inputs, size, suffix=""):
    """Shapes of a torch GRU / GRUCell's arrays (gates r, z, n stacked along the first axis)."""
    return {f"{name}.weight_ih{suffix}": (3 * size, inputs), f"{name}.weight_hh{suffix}": (3 * size, size),
            f"{name}.bias_ih{suffix}": (3 * size,), f"{name}.bias_hh{suffix}": (3 * size,)}


def expected_weight_shapes(agent_config, variant):
    """{array name: shape} of an agent with `agent_config` (a dict of AgentConfig fields) and `variant`."""
    if variant not in VARIANTS:
        raise RLAnimateError(f"Unknown agent variant {variant!r}: the file must name one of "
                             f"{', '.join(VARIANTS)}.")
    c = agent_config
    O, D, A = spaces.OBJECTIVE_SIZE, spaces.DESCRIPTION_SIZE, spaces.ACTION_SIZE
    E, Z, hid, n = c["behaviour_size"], c["stochastic_size"], c["hidden_size"], c["hidden_layers"]
    task = c["task_size"] if uses_task_state(variant) else O  # what f2 and the heads see of the task
    head_inputs = (c["task_size"] if uses_task_state(variant) else 0) + E + Z
    shapes = {}
    if uses_portrayal(variant):
        shapes.update(mlp_shapes("portrayal", O, c["portrayal_hidden_size"], n, D))
    if uses_task_state(variant):
        shapes.update(gru_shapes("task_rnn", O, c["task_size"], suffix="_l0"))
    shapes.update(gru_shapes("behaviour_cell", task + Z + A, E))
    shapes.update(mlp_shapes("prior", E, hid, n, 2 * Z))
    shapes.update(mlp_shapes("posterior", E + D, hid, n, 2 * Z))
    shapes.update(mlp_shapes("animation", head_inputs, hid, n, 2 * A))
    shapes.update(mlp_shapes("decoder", head_inputs, hid, n, D))
    return shapes


def load_agent_file(path):
    """(weights {name: float array}, metadata dict) from the agent file at `path`, fully validated."""
    path = Path(path)
    if not path.is_file():
        raise RLAnimateError(f"No agent file at {path}: choose an existing .npz agent in the add-on preferences.")
    arrays = _read_arrays(path)
    metadata = _parse_metadata(path, arrays.pop(METADATA_KEY, None))
    _check_weights(path, arrays, metadata)
    _check_metadata_values(path, metadata)
    return arrays, metadata


def _read_arrays(path):
    try:
        archive = np.load(path, allow_pickle=False)
        if not hasattr(archive, "files"):  # a bare .npy array, not an archive
            raise _not_an_agent(path)
        with archive:
            return {name: archive[name] for name in archive.files}
    except ValueError as error:
        if "Object arrays cannot be loaded" in str(error):
            raise RLAnimateError(f"The agent file {path} carries a pickled Python object, which is refused "
                                 f"because loading it could run code: use an agent exported by "
                                 f"trainer/agent/agent_export.py.") from error
        if "pickled data" in str(error):  # neither .npz nor .npy: numpy would have to unpickle it
            raise RLAnimateError(f"{path} is not an RLAnimate agent file (not a numpy archive; pickled "
                                 f"data is refused): choose a .npz written by trainer/agent/agent_export.py.") from error
        raise _damaged(path, error) from error
    except (OSError, EOFError, zipfile.BadZipFile, KeyError) as error:
        raise _damaged(path, error) from error


def _damaged(path, error):
    return RLAnimateError(f"The agent file {path} is truncated or damaged ({error}): export or copy it again.")


def _not_an_agent(path):
    return RLAnimateError(f"{path} is not an RLAnimate agent file (no {METADATA_KEY} entry): choose a .npz "
                          f"written by trainer/agent/agent_export.py.")


def _parse_metadata(path, entry):
    if entry is None or entry.dtype.kind != "U" or entry.shape != ():
        raise _not_an_agent(path)
    try:
        metadata = json.loads(str(entry))
    except json.JSONDecodeError as error:
        raise _damaged(path, error) from error
    if not isinstance(metadata, dict) or metadata.get("format") != FORMAT_NAME:
        raise _not_an_agent(path)
    if metadata.get("format_version") != FORMAT_VERSION:
        raise RLAnimateError(f"The agent file {path} is format version {metadata.get('format_version')!r}, but "
                             f"this add-on reads version {FORMAT_VERSION}: update the add-on, or re-export "
                             f"the agent with this version's trainer.")
    missing = [key for key in REQUIRED_METADATA if key not in metadata]
    if missing:
        raise RLAnimateError(f"The agent file {path} lacks metadata {', '.join(missing)}: re-export it with "
                             f"trainer/agent/agent_export.py.")
    return metadata


def _check_weights(path, arrays, metadata):
    config = metadata["agent_config"]
    if not isinstance(config, dict) or any(not isinstance(config.get(k), int) or config[k] <= 0
                                           for k in _AGENT_SIZES) \
            or any(not isinstance(config.get(k), (int, float)) or not config[k] > 0 for k in _AGENT_SCALARS):
        raise RLAnimateError(f"The agent file {path} has an invalid agent_config: re-export it with "
                             f"trainer/agent/agent_export.py.")
    expected = expected_weight_shapes(config, metadata["variant"])
    missing = sorted(set(expected) - set(arrays))
    extra = sorted(set(arrays) - set(expected))
    wrong = [f"{name} {arrays[name].shape} (expected {expected[name]})"
             for name in sorted(set(expected) & set(arrays)) if arrays[name].shape != tuple(expected[name])]
    if missing or extra or wrong:
        problems = ([f"missing {', '.join(missing)}"] if missing else []) + \
                   ([f"unexpected {', '.join(extra)}"] if extra else []) + \
                   ([f"wrong shape {'; '.join(wrong)}"] if wrong else [])
        raise RLAnimateError(f"The agent file {path} does not match its own config: {'; '.join(problems)}. "
                             f"Re-export the agent with trainer/agent/agent_export.py.")
    for name, array in arrays.items():
        if array.dtype.kind != "f":
            raise RLAnimateError(f"The agent file {path} holds {name} as {array.dtype}, not floats: re-export it.")
        if not np.all(np.isfinite(array)):
            raise RLAnimateError(f"The agent file {path} has NaN or infinite values in {name}: its training "
                                 f"diverged; train it again (a lower learning rate or gradient clip helps).")


def _check_metadata_values(path, metadata):
    bounds = np.asarray(metadata["action_bounds"], dtype=np.float64)
    if bounds.shape != (spaces.ACTION_SIZE, 2) or not np.all(np.isfinite(bounds)) \
            or not np.all(bounds[:, 0] < bounds[:, 1]):
        raise RLAnimateError(f"The agent file {path} has invalid action_bounds (need ({spaces.ACTION_SIZE}, 2) "
                             f"finite [low, high] pairs): re-export it with trainer/agent/agent_export.py.")
    frames = metadata["average_frames"]
    if not isinstance(frames, dict) or not frames or any(
            b not in spaces.BEHAVIOURS or not isinstance(n, (int, float)) or not n >= 2 for b, n in frames.items()):
        raise RLAnimateError(f"The agent file {path} has invalid average_frames (need a length of at least 2 "
                             f"frames for each behaviour it was trained for, among "
                             f"{', '.join(spaces.BEHAVIOURS)}): re-export it.")
