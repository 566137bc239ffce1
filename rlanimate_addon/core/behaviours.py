"""The behaviours an agent performs: data, named by the clips and declared by the agent file.

A behaviour is a name, a kind and what it does. Its kind is what it is conditioned on:
    target     a direction to a target (point, "this way"): the objective's attributes are the unit
               vector from the arm's rest shoulder to the target;
    intensity  an exaggeration in [0, 1] (wave, raise a hand): the attributes are the exaggeration (and,
               for an oscillating behaviour, its rhythm; core/rhythm.py).
What it does (`does`, ACTIONS) gives it the add-on's help: "point" aims (Exact Aim and the pointing hand),
"wave" oscillates (a rhythm and a tempo), "present" presents (a target behaviour's open hand), "raise"
raises. The shipped names do what SHIPPED says; a taught behaviour does what its clips' manifest and its
agent file declare ("does": "point"), else nothing of these (it plays as the agent learned it).
Its id is its name in upper case ("POINT", "THIS_WAY"): the clip manifest's `behaviour`,
MotionClip.behaviour, GestureRequest, the agent file's declaration and Scene.rlanimate.behaviour hold
it. Command lines, run folders and report keys use its `key`, the id in lower case ("point").

PAPER is the paper's pair (Table 2): what a clip library or an agent file that declares nothing holds.
A training run's `--behaviour` names a training set (`training_set`): "all" (every behaviour of the
library), "both" (point and wave), one behaviour's key, or keys joined by commas ("point,beckon").
"""
import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from .errors import RLAnimateError

TARGET = "target"
INTENSITY = "intensity"
KINDS = (TARGET, INTENSITY)

#: What a behaviour does, each with the kind it needs.
AIMS, OSCILLATES, PRESENTS, RAISES = "point", "wave", "present", "raise"
ACTIONS = {AIMS: TARGET, OSCILLATES: INTENSITY, PRESENTS: TARGET, RAISES: INTENSITY}

POINT = "POINT"
WAVE = "WAVE"
GUIDE = "GUIDE"
RAISE_HAND = "RAISE_HAND"
#: The one table from the shipped behaviours' names to what they do.
SHIPPED = {POINT: AIMS, WAVE: OSCILLATES, GUIDE: PRESENTS, RAISE_HAND: RAISES}

#: An id: a letter, then letters, digits or underscores, 32 characters at most.
_ID = re.compile(r"[A-Z][A-Z0-9_]{0,31}")
#: The most behaviours one agent declares (the objective's one-hot label has one entry each).
MAX_BEHAVIOURS = 64


def key(behaviour: str) -> str:
    """The behaviour's lower-case key ("point") for command lines, folder names and report keys."""
    return behaviour.lower()


def title(behaviour: str) -> str:
    """The behaviour's name as the panel and the gesture's track show it ("THIS_WAY" -> "This Way")."""
    return behaviour.replace("_", " ").title()


def parse(name: str) -> str:
    """The id of a behaviour name written in either case ("this_way" -> "THIS_WAY"); RLAnimateError for a
    name that is not a letter followed by letters, digits or underscores (32 at most)."""
    behaviour = str(name).upper()
    if not isinstance(name, str) or not _ID.fullmatch(behaviour):
        raise RLAnimateError(f"{name!r} is not a behaviour name: use a letter followed by letters, digits or "
                             f"underscores, 32 at most (such as POINT, WAVE or THIS_WAY).")
    return behaviour


def shipped_action(name: str, kind: str) -> str | None:
    """What the behaviour `name` of `kind` does when it declares nothing: SHIPPED's action for a shipped name
    of the kind that action needs, else None."""
    action = SHIPPED.get(name)
    return action if action is not None and ACTIONS[action] == kind else None


@dataclass(frozen=True)
class Behaviour:
    """A behaviour: `name` its id (upper case), `kind` TARGET or INTENSITY, `does` one of ACTIONS or None
    (None given: `shipped_action`)."""
    name: str
    kind: str
    does: str | None = None

    def __post_init__(self) -> None:
        if parse(self.name) != self.name:
            raise RLAnimateError(f"Behaviour {self.name!r} must be named in upper case: {parse(self.name)}.")
        if self.kind not in KINDS:
            raise RLAnimateError(f"Behaviour {self.name} has the kind {self.kind!r}: use {' or '.join(KINDS)}.")
        if self.does is None:
            object.__setattr__(self, "does", shipped_action(self.name, self.kind))
        elif ACTIONS.get(self.does) != self.kind:
            choices = ", ".join(f"{action!r} ({kind})" for action, kind in ACTIONS.items())
            raise RLAnimateError(f"Behaviour {self.name} of the kind {self.kind} cannot do {self.does!r}: use one "
                                 f"of {choices} that fits its kind, or leave it out.")

    @property
    def key(self) -> str:
        return key(self.name)

    @property
    def aims(self) -> bool:
        """Whether it points: Exact Aim solves its finger onto the target, and it holds the pointing hand."""
        return self.does == AIMS

    @property
    def oscillates(self) -> bool:
        """Whether it waves: its objective carries a rhythm (core/rhythm.py) and a request may ask a tempo."""
        return self.does == OSCILLATES

    def to_dict(self) -> dict[str, str]:
        """The agent file's declaration: its name and kind, and what it does where the name does not say."""
        declared = {"name": self.name, "kind": self.kind}
        if self.does is not None and self.does != shipped_action(self.name, self.kind):
            declared["does"] = self.does
        return declared


def from_dict(declared: dict[str, Any]) -> Behaviour:
    """The Behaviour of an agent file's declaration (`Behaviour.to_dict`)."""
    return Behaviour(declared["name"], declared["kind"], declared.get("does"))


#: The paper's pair, in the order of Table 2's type codes (point 1, wave 2).
PAPER = (Behaviour(POINT, TARGET), Behaviour(WAVE, INTENSITY))
#: The kind of each behaviour whose kind a manifest need not give.
KNOWN_KINDS = {b.name: b.kind for b in PAPER}

#: Training sets: every behaviour of the library, and the paper's pair.
ALL = "all"
BOTH = "both"


def ordered(declared: Iterable[Behaviour]) -> tuple[Behaviour, ...]:
    """Behaviours in their objective order: the paper's pair first, in Table 2's order, then the others by
    name; RLAnimateError when one name has two kinds or there are more than MAX_BEHAVIOURS."""
    named: dict[str, Behaviour] = {}
    for behaviour in declared:
        first = named.setdefault(behaviour.name, behaviour)
        if first != behaviour:
            said = (f"{first.kind} and {behaviour.kind}" if first.kind != behaviour.kind
                    else f"doing {first.does!r} and {behaviour.does!r}")
            raise RLAnimateError(f"Behaviour {behaviour.name} is given as both {said}: give every clip of one "
                                 f"behaviour the same kind and action.")
    if len(named) > MAX_BEHAVIOURS:
        raise RLAnimateError(f"{len(named)} behaviours, more than an agent learns ({MAX_BEHAVIOURS}): "
                             f"train fewer at once.")
    paper = [b.name for b in PAPER if b.name in named]
    return tuple(named[name] for name in paper + sorted(set(named) - set(paper)))


def training_set(name: str, library: Iterable[str]) -> tuple[str, ...]:
    """The ids a training set `name` trains ("all", "both", a key or keys joined by commas), in the
    library's order (`library`: the ids the clip library has, in objective order); RLAnimateError
    naming the choices for a set the library cannot train."""
    library = tuple(library)
    if name == ALL:
        return library
    wanted = {POINT, WAVE} if name == BOTH else {parse(part.strip()) for part in str(name).split(",")}
    missing = sorted(wanted - set(library))
    if missing:
        raise RLAnimateError(f"The clip library has no {', '.join(key(b) for b in missing)} training clips: add "
                             f"some, or train with --behaviour set to all, or to some of "
                             f"{', '.join(key(b) for b in library) or 'its behaviours'}.")
    return tuple(b for b in library if b in wanted)
