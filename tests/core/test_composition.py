"""How gestures on one character compose: what a Generate bakes again, handovers, and what depends on a change."""
from rlanimate_addon.core import composition
from rlanimate_addon.core.composition import Span

POINT_RIGHT = Span("point", "RIGHT", 1, 93, target=True, still=True, level=0)
WAVE_LEFT = Span("wave left", "LEFT", 40, 132, level=1)
WAVE_RIGHT = Span("wave right", "RIGHT", 50, 142, level=2)


def test_generate_bakes_again_the_selected_gesture_else_the_one_on_its_arm_and_start_frame():
    spans = [POINT_RIGHT, WAVE_LEFT]
    assert composition.regenerated(spans, "LEFT", 1, selected="point") == POINT_RIGHT, "the selection wins"
    assert composition.regenerated(spans, "RIGHT", 1) == POINT_RIGHT
    assert composition.regenerated(spans, "RIGHT", 1, keep_previous=True) is None, "Keep Previous layers"
    assert composition.regenerated(spans, "RIGHT", 2) is None, "a later start on the same arm is a new gesture"
    assert composition.regenerated(spans, "LEFT", 1) is None


def test_a_gesture_started_while_another_on_its_arm_plays_takes_over_from_it():
    spans = [POINT_RIGHT, WAVE_LEFT]
    assert composition.taken_over(spans, "RIGHT", 50) == POINT_RIGHT
    assert composition.taken_over(spans, "RIGHT", 94) is None, "right after it: nothing plays there to take over"
    assert composition.taken_over(spans, "RIGHT", 1) is None, "one that starts with it is baked again instead"
    assert composition.taken_over(spans, "LEFT", 50) == WAVE_LEFT
    layered = Span("layered", "RIGHT", 1, 93, layered=True)
    assert composition.taken_over([layered], "RIGHT", 50) is None, "Keep Previous gestures take no part"
    # Once trimmed where a later one took over, it no longer plays after that frame: the later one does.
    trimmed = Span("point", "RIGHT", 1, 93, cut=50)
    assert composition.taken_over([trimmed, WAVE_RIGHT], "RIGHT", 70) == WAVE_RIGHT
    assert composition.taken_over([trimmed], "RIGHT", 70) is None


def test_a_gesture_placed_before_a_later_one_on_its_arm_is_taken_over_by_it():
    spans = [WAVE_RIGHT]
    assert composition.taking_over(spans, "RIGHT", 1, 93) == WAVE_RIGHT
    assert composition.taking_over(spans, "RIGHT", 1, 49) is None
    assert composition.taking_over(spans, "LEFT", 1, 93) is None
    assert composition.taking_over([Span("a", "RIGHT", 80, 100), WAVE_RIGHT], "RIGHT", 1, 93) == WAVE_RIGHT, \
        "the earliest-starting one"


def test_dependants_are_what_depends_on_a_changed_gesture_bottom_first():
    spans = [POINT_RIGHT, WAVE_LEFT, WAVE_RIGHT, Span("far", "LEFT", 300, 400, target=True, level=3)]
    # The still base changed: the wave on its other arm starts from its keys, the wave taking over from it too.
    assert [s.id for s in composition.dependants(spans, POINT_RIGHT, POINT_RIGHT)] == ["wave left", "wave right"]
    # A wave on the left arm changed: the point over its frames is aimed again; the right wave does not care.
    assert [s.id for s in composition.dependants(spans, WAVE_LEFT, WAVE_LEFT)] == ["point"]
    # The right wave moved to other frames: the point it took over from is played whole again.
    moved = Span("wave right", "RIGHT", 60, 152, level=2)
    assert [s.id for s in composition.dependants(spans, WAVE_RIGHT, moved)] == ["point"]
    # Deleted: the same.
    assert [s.id for s in composition.dependants(spans, WAVE_RIGHT, None)] == ["point"]
    # A new gesture far from every other: nothing.
    assert composition.dependants(spans, None, Span("new", "RIGHT", 500, 600, level=4)) == []
