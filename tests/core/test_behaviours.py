"""Behaviours as data: a name and a kind; ids for data and the panel, keys for command lines and reports;
the objective order; and the training sets ("all", "both", keys) in one place."""
import pytest

from rlanimate_addon.core import behaviours, spaces
from rlanimate_addon.core.behaviours import INTENSITY, TARGET, Behaviour
from rlanimate_addon.core.errors import RLAnimateError


def test_the_papers_pair_keeps_the_panels_ids_and_table_2s_type_codes():
    assert [(b.name, b.kind) for b in behaviours.PAPER] == [("POINT", TARGET), ("WAVE", INTENSITY)]
    assert spaces.PAPER_SPACE.names == ("POINT", "WAVE") == (behaviours.POINT, behaviours.WAVE)
    assert spaces.PAPER_SPACE.labels.tolist() == [[1.0], [2.0]]  # Table 2's type codes


def test_keys_and_parse_are_inverse_and_refuse_what_is_not_a_name():
    for name in ("POINT", "WAVE", "THIS_WAY", "B2"):
        assert behaviours.parse(behaviours.key(name)) == behaviours.parse(name) == name
    for bad in ("", "2hands", "this way", "x" * 33, None, "wave;rm"):
        with pytest.raises(RLAnimateError, match="is not a behaviour name"):
            behaviours.parse(bad)
    with pytest.raises(RLAnimateError, match="upper case"):
        Behaviour("beckon", TARGET)
    with pytest.raises(RLAnimateError, match="use target or intensity"):
        Behaviour("BECKON", "direction")


def test_objective_order_puts_the_papers_pair_first_then_the_others_by_name():
    declared = [Behaviour("RAISE_HAND", INTENSITY), Behaviour("WAVE", INTENSITY), Behaviour("BECKON", TARGET),
                Behaviour("POINT", TARGET), Behaviour("BECKON", TARGET)]
    assert [b.name for b in behaviours.ordered(declared)] == ["POINT", "WAVE", "BECKON", "RAISE_HAND"]
    assert [b.name for b in behaviours.ordered([Behaviour("WAVE", INTENSITY)])] == ["WAVE"]
    with pytest.raises(RLAnimateError, match="BECKON is given as both target and intensity"):
        behaviours.ordered([Behaviour("BECKON", TARGET), Behaviour("BECKON", INTENSITY)])


def test_training_sets_name_all_both_one_or_several_behaviours_in_the_librarys_order():
    library = ("POINT", "WAVE", "BECKON")
    assert behaviours.training_set("all", library) == library
    assert behaviours.training_set("both", library) == ("POINT", "WAVE")
    assert behaviours.training_set("wave", library) == ("WAVE",)
    assert behaviours.training_set("beckon, point", library) == ("POINT", "BECKON")
    with pytest.raises(RLAnimateError, match="no wave training clips.*point, beckon"):
        behaviours.training_set("both", ("POINT", "BECKON"))
    with pytest.raises(RLAnimateError, match="is not a behaviour name"):
        behaviours.training_set("point;wave", library)
