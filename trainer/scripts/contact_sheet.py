"""Contact sheets: the clip library's key frames (docs/contact_sheet.png), or, with --generated, the add-on's
Generate Gesture on the sample character rendered by Blender (Cycles, CPU) into
docs/results/generated_frames.png (point and wave), or, with --generated --further, the guide and
raise-hand gestures into docs/results/generated_guide_raise_frames.png, or, with --generated --overview, one
gesture of each behaviour (point, wave, guide, raise hand) into docs/results/four_behaviours_frames.png (the
README's picture), or, with --composing, gestures composed on one character (both arms at once, a handover) into
docs/results/composing_frames.png.

    python -m trainer.scripts.contact_sheet [--out docs/contact_sheet.png] [--seed S]
    nice -n 10 python -m trainer.scripts.contact_sheet --generated [--further | --overview] [--agent PATH] [--out PNG]
    nice -n 10 python -m trainer.scripts.contact_sheet --composing [--agent PATH] [--out PNG]
"""
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from trainer.motion.library_plan import DEFAULT_SEED
from trainer.paths import CONTACT_SHEET, RESULTS_DIR, shown
from trainer.reporting.contact_sheet import generated_sheet, render
from trainer.scripts import cli
from trainer.scripts.cli import run_main

GENERATED_SHEET = RESULTS_DIR / "generated_frames.png"
FURTHER_SHEET = RESULTS_DIR / "generated_guide_raise_frames.png"
COMPOSING_SHEET = RESULTS_DIR / "composing_frames.png"
OVERVIEW_SHEET = RESULTS_DIR / "four_behaviours_frames.png"
TARGET_HIGH = (-0.9, -2.0, 1.7)  # ahead, up and to the character's right
TARGET_ACROSS = (-0.9, -1.8, 0.9)  # low, across the body for the left arm
TARGET_DOOR = (-2.2, -1.6, 0.9)  # a doorway ahead and out to the character's right, at waist height
TARGET_FLOOR = (0.6, -2.2, 0.05)  # on the floor ahead, a little to the left
TARGET_ASIDE = (-1.0, -1.8, 0.9)  # at waist height ahead and to the character's right, in the camera's view


@dataclass(frozen=True)
class SheetSettings:
    """Which contact sheet to make, and where."""
    out: Path | None = None  # the PNG to write (None: the sheet's own under docs/)
    seed: int = DEFAULT_SEED  # library plan seed (library sheet)
    generated: bool = False  # render Generate Gesture's output with Blender
    further: bool = False  # with --generated: the guide and raise-hand gestures
    overview: bool = False  # with --generated: one gesture of each behaviour (the README's picture)
    composing: bool = False  # render gestures composed on one character (both arms, a handover) with Blender
    agent: Path | None = None  # agent file for the add-on (None: the bundled agent)


def parse_settings(argv: Sequence[str] | None = None) -> SheetSettings:
    """SheetSettings from the command line."""
    return cli.parse_settings(SheetSettings, argv, prog="python -m trainer.scripts.contact_sheet", doc=__doc__)


def generated_requests():
    """The requests of the generated sheet: points with and without exact aim, waves small to big, a seed."""
    from trainer.blender_io.gesture_render import RenderRequest
    return [
        RenderRequest("point right, exact aim", {"behaviour": "POINT", "arm": "RIGHT", "exact_aim": True, "seed": 0},
                      target=TARGET_HIGH),
        RenderRequest("point right, own aim", {"behaviour": "POINT", "arm": "RIGHT", "exact_aim": False, "seed": 0},
                      target=TARGET_HIGH),
        RenderRequest("point left across, own aim", {"behaviour": "POINT", "arm": "LEFT", "exact_aim": False,
                                                     "seed": 0}, target=TARGET_ACROSS),
        RenderRequest("wave right, e 0.2", {"behaviour": "WAVE", "arm": "RIGHT", "exaggeration": 0.2, "seed": 0}),
        RenderRequest("wave right, e 0.9", {"behaviour": "WAVE", "arm": "RIGHT", "exaggeration": 0.9, "seed": 0}),
        RenderRequest("wave left, e 0.6, seed 3", {"behaviour": "WAVE", "arm": "LEFT", "exaggeration": 0.6, "seed": 3}),
    ]


def further_requests():
    """The requests of the guide and raise-hand sheet: "this way" to two targets, raised hands small to big."""
    from trainer.blender_io.gesture_render import RenderRequest
    return [
        RenderRequest(
            "this way, right, to a door", {"behaviour": "GUIDE", "arm": "RIGHT", "seed": 0}, target=TARGET_DOOR
        ),
        RenderRequest(
            "this way, left, to the floor", {"behaviour": "GUIDE", "arm": "LEFT", "seed": 0}, target=TARGET_FLOOR
        ),
        RenderRequest(
            "raise hand right, e 0.1", {"behaviour": "RAISE_HAND", "arm": "RIGHT", "exaggeration": 0.1, "seed": 0}
        ),
        RenderRequest(
            "raise hand left, e 0.9", {"behaviour": "RAISE_HAND", "arm": "LEFT", "exaggeration": 0.9, "seed": 0}
        ),
    ]


def overview_requests() -> list:
    """The requests of the overview sheet: one gesture of each shipped behaviour, right arm."""
    from trainer.blender_io.gesture_render import RenderRequest
    return [
        RenderRequest("point", {"behaviour": "POINT", "arm": "RIGHT", "exact_aim": True, "seed": 0},
                      target=TARGET_HIGH),
        RenderRequest("wave, e 0.8", {"behaviour": "WAVE", "arm": "RIGHT", "exaggeration": 0.8, "seed": 0}),
        RenderRequest("guide (this way)", {"behaviour": "GUIDE", "arm": "RIGHT", "seed": 0}, target=TARGET_ASIDE),
        RenderRequest("raise hand, e 0.8", {"behaviour": "RAISE_HAND", "arm": "RIGHT", "exaggeration": 0.8,
                                            "seed": 0}),
    ]


def _generated(settings: SheetSettings) -> tuple[list, Path]:
    """Which requests --generated renders, and the sheet they go to."""
    if settings.overview:
        return overview_requests(), OVERVIEW_SHEET
    if settings.further:
        return further_requests(), FURTHER_SHEET
    return generated_requests(), GENERATED_SHEET


def compositions():
    """The compositions of the composing sheet: a point and a wave on overlapping frames, a point handing over
    to a wave on the same arm (docs/EXTENSION.md, "Composing gestures")."""
    from trainer.blender_io.gesture_render import Composition
    point = {"behaviour": "POINT", "arm": "RIGHT", "start_frame": 1, "frame_count": 93, "seed": 0}
    return [
        Composition("point right 1-93,\nwave left 40-132", [
            (point, TARGET_HIGH),
            ({"behaviour": "WAVE", "arm": "LEFT", "exaggeration": 0.8, "start_frame": 40, "frame_count": 93,
              "seed": 0}, None)], (20, 45, 60, 75, 90, 110, 125)),
        Composition("point right 1-93, wave\nright from 50 takes over", [
            (point, TARGET_HIGH),
            ({"behaviour": "WAVE", "arm": "RIGHT", "exaggeration": 0.8, "start_frame": 50, "frame_count": 93,
              "seed": 0}, None)], (20, 40, 50, 58, 66, 90, 130)),
    ]


def _composing(settings):
    from trainer.blender_io.gesture_render import render_compositions
    with tempfile.TemporaryDirectory() as frames:
        rendered = render_compositions(compositions(), frames, agent_path=settings.agent)
        agent = shown(settings.agent) if settings.agent else "the bundled agent"
        return generated_sheet([(c.title, c.frames) for c in rendered], settings.out or COMPOSING_SHEET,
                               f"Gestures composed on the sample character, {agent}, rendered by Blender (Cycles): "
                               "frame numbers above; red: the point's target", frame_labels=True)


def main(argv=None):
    settings = parse_settings(argv)
    if settings.composing:
        print(f"wrote {_composing(settings)}")
        return 0
    if not settings.generated:
        print(f"wrote {render(settings.out or CONTACT_SHEET, settings.seed)}")
        return 0
    from trainer.blender_io.gesture_render import render_requests
    with tempfile.TemporaryDirectory() as frames:
        chosen, sheet = _generated(settings)
        requests = render_requests(chosen, frames, agent_path=settings.agent)
        agent = shown(settings.agent) if settings.agent else "the bundled agent"
        out = generated_sheet([(r.title, r.frames) for r in requests], settings.out or sheet,
                              f"Generate Gesture on the sample character, {agent}, rendered by Blender (Cycles); "
                              f"red: the target")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main))
