"""What a run with the training set "all" says about its clip library's behaviours before it trains: the
behaviours it leaves out and why (`left_out`), and a new behaviour that too few clips name, more likely a
typo in the manifest than a gesture to learn (`check_new_behaviours`)."""
from collections.abc import Sequence
from pathlib import Path

from rlanimate_addon.core import behaviours
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion.clip import MotionClip, library_space

#: The fewest clips (training and held out) that name a behaviour other than point and wave for "all" to
#: train it without --allow-new-behaviour.
MIN_NEW_BEHAVIOUR_CLIPS = 3


def left_out(train_clips: Sequence[MotionClip], test_clips: Sequence[MotionClip], trained: Sequence[str]) -> str:
    """A note naming each behaviour of the library (the behaviours its clips name, and the paper's pair for
    a library of point or wave alone) that the run does not train, and why; "" when it trains them all."""
    reasons = []
    for name in library_space([*train_clips, *test_clips]).names:
        if name in trained:
            continue
        held_out = sum(clip.behaviour == name for clip in test_clips)
        if held_out:
            reasons.append(f"{behaviours.key(name)}'s {held_out} clip{'s are all' if held_out > 1 else ' is'} "
                           f"held out (split \"test\"): mark some \"train\" to learn it")
        else:
            reasons.append(f"the library has no {behaviours.key(name)} clips")
    if not reasons:
        return ""
    return f"note: training {' and '.join(behaviours.key(name) for name in trained)} only: {'; '.join(reasons)}."


def check_new_behaviours(clips: Sequence[MotionClip], trained: Sequence[str]) -> None:
    """RLAnimateError naming each behaviour of `trained` other than point and wave that fewer than
    MIN_NEW_BEHAVIOUR_CLIPS of the library's `clips` name, with those clips' files."""
    rare = {name: [Path(clip.source).name for clip in clips if clip.behaviour == name]
            for name in trained if name not in behaviours.KNOWN_KINDS}
    rare = {name: files for name, files in rare.items() if len(files) < MIN_NEW_BEHAVIOUR_CLIPS}
    if rare:
        named = "; ".join(f"{name} by {len(files)} clip{'s' if len(files) > 1 else ''} ({', '.join(files)})"
                          for name, files in rare.items())
        raise RLAnimateError(f"The clip library names a new behaviour in fewer than {MIN_NEW_BEHAVIOUR_CLIPS} "
                             f"clips: {named}. If it is a typo, correct the clips' \"behaviour\" in the manifest; "
                             "to learn it from these clips, add --allow-new-behaviour (or name it in --behaviour). "
                             "Nothing was trained.")
