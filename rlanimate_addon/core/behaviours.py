"""The behaviours an agent performs, spelt one way from the clip manifest to the panel.

A behaviour is named by its id, POINT or WAVE: the clip manifest's `behaviour`, MotionClip.behaviour,
GestureRequest, the agent file's per-behaviour data and the panel's Scene.rlanimate.behaviour all hold
it. Command lines, run folders and report keys use its `key`, the id in lower case ("point"). A training
run's `--behaviour` names a training set: one behaviour's key, or "both" (every behaviour, drawn in turn).

The set is fixed today. To let an agent file declare its behaviours, BEHAVIOURS becomes the file's list
(each id with its kind: a target to point at, or an intensity such as the wave's exaggeration); `parse`,
`key` and `training_set` keep their meaning.
"""
from .errors import RLAnimateError

POINT = "POINT"
WAVE = "WAVE"
#: Every behaviour, in the order of its objective type code (Table 2: point 1, wave 2).
BEHAVIOURS = (POINT, WAVE)

#: The training set of every behaviour.
BOTH = "both"


def key(behaviour: str) -> str:
    """The behaviour's lower-case key ("point") for command lines, folder names and report keys."""
    return behaviour.lower()


#: A training run's --behaviour choices: {key: the behaviours it trains, in BEHAVIOURS order}.
TRAINING_SETS = {**{key(behaviour): (behaviour,) for behaviour in BEHAVIOURS}, BOTH: BEHAVIOURS}


def parse(name: str) -> str:
    """The id of a behaviour written either way ("point" or "POINT"), as a manifest or a user gives it;
    RLAnimateError naming the choices for anything else."""
    behaviour = str(name).upper()
    if behaviour not in BEHAVIOURS:
        raise RLAnimateError(f"Unknown behaviour {name!r}: use {' or '.join(BEHAVIOURS)}.")
    return behaviour


def training_set(name: str) -> tuple[str, ...]:
    """The behaviours the training set `name` ("point", "wave" or "both") trains; RLAnimateError otherwise."""
    if name not in TRAINING_SETS:
        raise RLAnimateError(f"Unknown behaviour {name!r} to train: use {', '.join(TRAINING_SETS)}.")
    return TRAINING_SETS[name]
