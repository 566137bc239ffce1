"""The motion-clip type: one clip on the canonical rig with its declared labels, and a labelled clip set."""
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from rlanimate_addon.core import behaviours, spaces


@dataclass
class MotionClip:
    """One imported clip on the canonical rig, with its labels when a manifest gives them."""
    name: str
    source: str
    fps: float
    rotvecs: np.ndarray  # (F, 15, 3) local rotation vectors of skeleton.ACTION_JOINTS
    fingers: dict = field(default_factory=dict)  # {canonical finger bone: (F, 3)}; empty without fingers
    behaviour: str | None = None  # the behaviour's id: "POINT", "WAVE", or a user's own ("BECKON")
    kind: str | None = None  # behaviours.TARGET or INTENSITY; None for POINT and WAVE is their known kind
    does: str | None = None  # one of behaviours.ACTIONS ("point"); None: the shipped name's, or nothing
    arm: str | None = None  # "LEFT" or "RIGHT"
    attributes: object = None  # target kind: unit vector (3,) from the arm's shoulder; intensity: exaggeration
    target: tuple[float, ...] | None = None
    exaggeration: float | None = None
    split: str | None = None  # "train" or "test"
    label: object = None  # autolabel's WaveLabel or PointLabel, when labelled from the motion
    content: str | None = None  # real mocap: what the take shows ("wave", "bye", "guide")
    style: str | None = None  # real mocap: the actor's style ("normal", "elderly", ...)
    take: str | None = None  # real mocap: the take number ("001")
    named_arm: str | None = None  # real mocap: the arm the file name gives ("LEFT", "RIGHT" or None)

    @property
    def frames(self):
        return len(self.rotvecs)

    @property
    def behaviour_kind(self):
        """The clip's behaviours.TARGET or INTENSITY: its own, else its shipped name's."""
        return self.kind or behaviours.ACTIONS[behaviours.SHIPPED[self.behaviour]]

    @property
    def declared(self) -> behaviours.Behaviour:
        """The clip's behaviour: its name, kind and what it does (a labelled clip's)."""
        return behaviours.Behaviour(str(self.behaviour), self.behaviour_kind, self.does)


def library_space(clips):
    """The ObjectiveSpace of every behaviour among labelled `clips` (an agent trained on them declares it):
    the paper's (point and wave, Table 2's codes) for clips of point or wave alone, so that a one-behaviour
    run labels its behaviour as the paper does and its agent plays beside the others."""
    declared = behaviours.ordered(c.declared for c in clips)
    return spaces.PAPER_SPACE if set(declared) <= set(behaviours.PAPER) else spaces.ObjectiveSpace(declared)


def trained_behaviours(clips: Sequence[MotionClip], training_set: str,
                       order: Sequence[str] | None = None) -> tuple[str, ...]:
    """The ids of the behaviours a run with the training set `training_set` ("all", "both", keys:
    behaviours.training_set) trains on the training clips `clips`, in the objective order `order` (default
    library_space(clips)'s): "all" is the behaviours the clips have, so a library of points alone, or one
    whose waves are all held out, trains point although the paper's space it declares has wave too."""
    names = library_space(clips).names if order is None else order
    return behaviours.training_set(training_set, [name for name in names if any(c.behaviour == name for c in clips)])


def training_space(clips, training_set):
    """The ObjectiveSpace an agent trained on `clips` with the training set `training_set` declares: its own
    behaviours only, so point and wave taken from a library with more behaviours keep the paper's
    objective, as the shipped agent has it."""
    trained = trained_behaviours(clips, training_set)
    return library_space([clip for clip in clips if clip.behaviour in trained])


@dataclass
class ClipSet:
    """Labelled clips of a manifest, and the problems of the files that could not be used."""
    clips: list
    problems: list

    @property
    def train(self):
        return [c for c in self.clips if c.split == "train"]

    @property
    def test(self):
        return [c for c in self.clips if c.split == "test"]
