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


def test_what_a_behaviour_does_comes_from_its_declaration_or_the_shipped_names_table():
    assert [(b.name, b.does) for b in behaviours.PAPER] == [("POINT", "point"), ("WAVE", "wave")]
    assert Behaviour("GUIDE", TARGET).does == "present" and Behaviour("RAISE_HAND", INTENSITY).does == "raise"
    assert Behaviour("BECKON", TARGET).does is None and not Behaviour("BECKON", TARGET).aims
    taught = Behaviour("AIM_AT", TARGET, "point")
    assert taught.aims and not taught.oscillates and taught.to_dict() == {"name": "AIM_AT", "kind": TARGET,
                                                                          "does": "point"}
    assert behaviours.from_dict(taught.to_dict()) == taught
    assert Behaviour("POINT", TARGET).to_dict() == {"name": "POINT", "kind": TARGET}  # as files already written
    assert Behaviour("WAVE", TARGET).does is None  # a shipped name of another kind does nothing of the table's
    with pytest.raises(RLAnimateError, match="BECKON of the kind intensity cannot do 'point'"):
        Behaviour("BECKON", INTENSITY, "point")
    with pytest.raises(RLAnimateError, match="given as both doing 'point' and None"):
        behaviours.ordered([taught, Behaviour("AIM_AT", TARGET)])
    space = spaces.ObjectiveSpace((Behaviour("POINT", TARGET), Behaviour("SHAKE", INTENSITY, "wave")))
    assert space.oscillating() == ("SHAKE",) and space.behaviour("SHAKE").oscillates
