"""Agent files that declare more behaviours than the shipped agent, written with numpy alone (Blender 4.2 has
no torch): the shipped agent's weights, with label columns added to the arrays that read the objective.

With the shipped agent's one-hot label, each shipped behaviour keeps its column and each added one gets a
copy of the column of the shipped behaviour of its kind that comes first (point's or wave's), so the
widened agent answers an added target behaviour as it points and an added intensity behaviour as it waves.
A point-and-wave agent (Table 2's type code) is widened to a one-hot label e_i that meets (i + 1) times
the type-code column, so POINT (i = 0) and WAVE (i = 1) answer as before and each added behaviour as the
shipped agent answers type code i + 1. Either way: a real, moving gesture for a behaviour it never saw.
"""
import json
from pathlib import Path

import numpy as np

from rlanimate_addon.core import agent_file, behaviours, runtime, spaces
from rlanimate_addon.core.behaviours import Behaviour

SHIPPED = Path(__file__).resolve().parents[2] / "rlanimate_addon" / "agents" / "default.npz"
#: The arrays whose inputs are the objective, in the shipped (rlanimate) variant.
_OBJECTIVE_INPUTS = ("portrayal.layers.0.weight", "task_rnn.weight_ih_l0")


def shipped_behaviours():
    """The ids of the shipped agent's behaviours, in objective order."""
    return runtime.load_agent(SHIPPED).behaviours


def listed_titles(names):
    """The behaviours as the panel and the preferences list them: "Point, Wave, Raise Hand"."""
    return ", ".join(behaviours.title(name) for name in names)


def widened_agent(path, added, average_frames=75.0):
    """Write at `path` a format-4 agent of the shipped weights declaring the shipped behaviours and `added`
    ([(id, kind)] or [(id, kind, does)]: behaviours.Behaviour's fields); returns its ObjectiveSpace."""
    weights, metadata = agent_file.load_agent_file(SHIPPED)
    shipped = runtime.load_agent(SHIPPED).space
    space = spaces.ObjectiveSpace(behaviours.ordered([*shipped.behaviours, *(Behaviour(*spec) for spec in added)]))
    assert space.label_size > 1, "a one-hot label: more than two behaviours"
    widened = dict(weights)
    for name in _OBJECTIVE_INPUTS:
        old = weights[name]  # (out, L + 6): [label (L), arm (2), attributes (3), t/N]
        label = old[:, :shipped.label_size]
        if shipped.label_size == 1:  # Table 2's type code
            columns = label * np.arange(1, space.label_size + 1, dtype=old.dtype)  # (out, L')
        else:
            source = [name if name in shipped.names else shipped.of_kind(space.kind(name))[0] for name in space.names]
            columns = label[:, [shipped.names.index(name) for name in source]]  # (out, L')
        widened[name] = np.concatenate([columns, old[:, shipped.label_size:]], axis=1)  # (out, L' + 6)
    metadata = {**metadata, "format_version": agent_file.FORMAT_VERSION,
                "spaces": {**metadata["spaces"], "objective_size": space.size},
                "behaviours": [b.to_dict() for b in space.behaviours],
                "average_frames": {**metadata["average_frames"],
                                   **dict.fromkeys((spec[0] for spec in added), average_frames)}}
    np.savez(path, **widened, **{agent_file.METADATA_KEY: np.array(json.dumps(metadata))})
    return space
