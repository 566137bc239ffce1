"""Agent files that declare more behaviours than point and wave, written with numpy alone (Blender 4.2 has
no torch): the shipped agent's weights, its objective widened from Table 2's type code to a one-hot label.

A one-hot label e_i meets weights whose label columns are (i + 1) times the shipped type-code column, so
the widened agent answers POINT (i = 0) and WAVE (i = 1) as the shipped one does, and each added behaviour
as the shipped agent answers type code i + 1: a real, moving gesture for a behaviour it never saw.
"""
import json
from pathlib import Path

import numpy as np

from rlanimate_addon.core import agent_file, behaviours, spaces
from rlanimate_addon.core.behaviours import Behaviour

SHIPPED = Path(__file__).resolve().parents[2] / "rlanimate_addon" / "agents" / "default.npz"
#: The arrays whose inputs are the objective, in the shipped (rlanimate) variant.
_OBJECTIVE_INPUTS = ("portrayal.layers.0.weight", "task_rnn.weight_ih_l0")


def widened_agent(path, added, average_frames=75.0):
    """Write at `path` a format-4 agent of the shipped weights declaring point, wave and `added`
    ([(id, kind)]); returns its ObjectiveSpace."""
    weights, metadata = agent_file.load_agent_file(SHIPPED)
    space = spaces.ObjectiveSpace(behaviours.ordered([*behaviours.PAPER, *(Behaviour(n, k) for n, k in added)]))
    assert space.label_size > 1, "a one-hot label: more than two behaviours"
    widened = dict(weights)
    for name in _OBJECTIVE_INPUTS:
        old = weights[name]  # (out, 7): [type, arm (2), attributes (3), t/N]
        codes = np.arange(1, space.label_size + 1, dtype=old.dtype)  # (L,)
        widened[name] = np.concatenate([old[:, :1] * codes, old[:, 1:]], axis=1)  # (out, L + 6)
    metadata = {**metadata, "format_version": agent_file.FORMAT_VERSION,
                "spaces": {**metadata["spaces"], "objective_size": space.size},
                "behaviours": [b.to_dict() for b in space.behaviours],
                "average_frames": {**metadata["average_frames"], **dict.fromkeys(dict(added), average_frames)}}
    np.savez(path, **widened, **{agent_file.METADATA_KEY: np.array(json.dumps(metadata))})
    return space
