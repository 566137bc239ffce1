"""A clip library's objective space: its behaviours with their kinds, in objective order."""
import numpy as np
import pytest

from rlanimate_addon.core import spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion.clip import MotionClip, library_space, training_space


def _clip(behaviour, kind=None):
    return MotionClip(behaviour.lower(), "", 30.0, np.zeros((3, 15, 3)), behaviour=behaviour, kind=kind)


def test_point_and_wave_alone_keep_the_papers_space_and_others_widen_it_to_a_one_hot():
    assert library_space([_clip("WAVE")]) == spaces.PAPER_SPACE, "a wave-only run labels waves 2, as the paper"
    assert library_space([_clip("WAVE"), _clip("POINT")]) == spaces.PAPER_SPACE
    space = library_space([_clip("WAVE"), _clip("RAISE_HAND", "intensity"), _clip("BECKON", "target"),
                           _clip("POINT")])
    assert space.names == ("POINT", "WAVE", "BECKON", "RAISE_HAND") and space.size == 10
    assert (space.kind("BECKON"), space.kind("RAISE_HAND")) == ("target", "intensity")
    only = library_space([_clip("RAISE_HAND", "intensity")])
    assert only.names == ("RAISE_HAND",) and only.labels.tolist() == [[1.0]] and only.size == 7
    with pytest.raises(RLAnimateError, match="BECKON is given as both target and intensity"):
        library_space([_clip("BECKON", "target"), _clip("BECKON", "intensity")])


def test_an_agent_declares_only_the_behaviours_it_trains():
    library = [_clip("WAVE"), _clip("GUIDE", "target"), _clip("RAISE_HAND", "intensity"), _clip("POINT")]
    assert training_space(library, "both") == spaces.PAPER_SPACE, "point and wave keep the shipped agent's space"
    assert training_space(library, "all").names == ("POINT", "WAVE", "GUIDE", "RAISE_HAND")
    assert training_space(library, "guide,wave").names == ("WAVE", "GUIDE")
    with pytest.raises(RLAnimateError, match="no beckon training clips"):
        training_space(library, "beckon")
