"""One spelling of a behaviour: ids for data and the panel, keys for command lines and reports, and the
training sets (what "both" trains) in one place."""
import pytest

from rlanimate_addon.core import behaviours, spaces
from rlanimate_addon.core.errors import RLAnimateError


def test_the_ids_are_the_panels_and_the_agent_files_values():
    assert behaviours.BEHAVIOURS == ("POINT", "WAVE") == (behaviours.POINT, behaviours.WAVE)
    assert [spaces.BEHAVIOUR_TYPE[b] for b in behaviours.BEHAVIOURS] == [1.0, 2.0]  # Table 2's type codes


def test_keys_and_parse_are_inverse_and_refuse_other_names():
    for behaviour in behaviours.BEHAVIOURS:
        assert behaviours.parse(behaviours.key(behaviour)) == behaviours.parse(behaviour) == behaviour
    with pytest.raises(RLAnimateError, match="Unknown behaviour 'jump': use POINT or WAVE"):
        behaviours.parse("jump")


def test_both_trains_every_behaviour_in_order_and_one_key_its_own():
    assert behaviours.TRAINING_SETS == {"point": ("POINT",), "wave": ("WAVE",), "both": ("POINT", "WAVE")}
    assert behaviours.training_set(behaviours.BOTH) == behaviours.BEHAVIOURS
    with pytest.raises(RLAnimateError, match="Unknown behaviour 'POINT' to train: use point, wave, both"):
        behaviours.training_set("POINT")
