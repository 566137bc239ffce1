"""How the gestures on one character compose, in plain data: which gesture a Generate bakes again, which
earlier gesture a new one takes over from (a handover), and which gestures must be baked again once one
changed.

Each gesture is a Span: its arm, its frames as it was made (and the frame a later one took over at: a trim
does not change them), whether it is of a target behaviour (its aim and gaze are solved on the pose it plays
over), whether it was made on a still rig (it holds the standing pose and keys the other arm), whether it was
layered with Keep Previous (it takes no part in handovers) and its place in the layer stack. A gesture owns
its arm; two gestures on one arm hand over: the later-starting takes over at its start frame, and the earlier
one is trimmed there.
"""
from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class Span:
    id: str
    arm: str
    start: int
    end: int
    target: bool = False
    still: bool = False
    layered: bool = False
    level: int = 0
    cut: int | None = None  # the frame where a later gesture on its arm takes over from it

    @property
    def until(self) -> int:
        """The last frame it plays before any later gesture takes over."""
        return self.end if self.cut is None else min(self.end, self.cut)

    def overlaps(self, other: "Span") -> bool:
        return self.start <= other.end and other.start <= self.end


def regenerated(spans: list[Span], arm: str, start: int, selected: str = "",
                keep_previous: bool = False) -> Span | None:
    """The gesture a Generate bakes again in place: the selected one (its id), else, with Keep Previous off,
    the topmost on the same arm that starts on the same frame; None for a new gesture."""
    if selected:
        return next((s for s in spans if s.id == selected), None)
    if keep_previous:
        return None
    same = [s for s in spans if s.arm == arm and s.start == start]
    return max(same, key=lambda s: s.level, default=None)


def _handing_over(spans: list[Span], exclude: Iterable[str]) -> list[Span]:
    excluded = set(exclude)
    return [s for s in spans if not s.layered and s.id not in excluded]


def taken_over(spans: list[Span], arm: str, start: int, exclude: Iterable[str] = ()) -> Span | None:
    """The gesture that a gesture on `arm` from frame `start` takes over from: of those on that arm still
    playing at `start` (started before it), the latest-starting; None when there is none."""
    playing = [s for s in _handing_over(spans, exclude) if s.arm == arm and s.start < start <= s.until]
    return max(playing, key=lambda s: (s.start, s.level), default=None)


def taking_over(spans: list[Span], arm: str, start: int, end: int, exclude: Iterable[str] = ()) -> Span | None:
    """The gesture that takes over from a gesture on `arm` over frames start-end: of those on that arm that
    start after `start` and by `end`, the earliest-starting; None when there is none."""
    later = [s for s in _handing_over(spans, exclude) if s.arm == arm and start < s.start <= end]
    return min(later, key=lambda s: (s.start, -s.level), default=None)


def dependants(spans: list[Span], before: Span | None, after: Span | None) -> list[Span]:
    """The gestures to bake again, bottom first, once a gesture changed from `before` (None: it is new) to
    `after` (None: it was deleted): the one taking over from it, whose start is its pose; the one it took
    over from, when the frame of that handover changed (it is trimmed there, or played whole again); those of
    a target behaviour over its frames, whose aim and gaze are solved on the spine and head it turns; and,
    for a gesture made on a still rig, those on its other arm over its frames, which start from its keys."""
    changed = [s for s in (before, after) if s is not None]
    ids = {s.id for s in changed}
    others = [s for s in spans if s.id not in ids]
    found = {}
    moved = before is None or after is None or before.start != after.start
    for span in changed:
        for other in others:
            if not other.overlaps(span):
                continue
            took_over = other.arm == span.arm and other.start < span.start and not (other.layered or span.layered)
            if (other.target or other.arm == span.arm and not took_over or took_over and moved
                    or span.still and other.arm != span.arm):
                found[other.id] = other
    return sorted(found.values(), key=lambda s: s.level)
