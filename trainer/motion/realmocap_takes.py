"""The Bandai Namco real motion capture as data: file names, styles and takes, and splits (numpy; the clips are
read in place from ../shared/realmocap/, CC BY-NC; a capture without fingers gets trainer/motion/hands.py's hand)."""
import re
from pathlib import Path

import numpy as np

from rlanimate_addon.core import behaviours
from rlanimate_addon.core.errors import RLAnimateError
from trainer.paths import REALMOCAP_DIR

STYLES = ("active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful")
#: Takes 021-036 (they exist for some styles and arms only; README there).
LATER_TAKES = tuple(f"{k:03d}" for k in range(21, 37))
#: Takes 001-008 and the later takes.
TRAIN_TAKES = tuple(f"{k:03d}" for k in range(1, 9)) + LATER_TAKES
TEST_TAKES = ("009", "010")
#: Takes 011-020 are held out for evaluation outside the project: never read, even where present.
WITHHELD_TAKES = tuple(f"{k:03d}" for k in range(11, 21))
#: The takes every style and arm has: the unseen styles are tested on these (40 clips, as before 021-036).
FIRST_TAKES = tuple(f"{k:03d}" for k in range(1, 11))
#: Styles the hold-out agent never sees: the two whose labels fall between the trained ones
#: (exaggeration ~0.3 and ~0.55 against 0.1 feminine and 0.75-1 for the rest), as the paper's unseen
#: waves are exaggerations between the training ones.
HOLDOUT_STYLES = ("elderly", "exhausted")
#: Validation for choices made before the tests (trainer/experiments/realmocap_length.py), from the training
#: takes only: takes 007-008 stand for takes 009-010 (of the 5 styles whose takes 001-010 are not the unseen
#: styles' test), and normal stands for the unseen styles:
#: without it, its labels (0.62 ± 0.10) fall beside another style's that swings at another rate (masculine,
#: 0.67), as exhausted's (0.53) fall beside normal's.
VALIDATION_TAKES = ("007", "008")
VALIDATION_STYLE = "normal"
#: The groups of takes the report compares a style's label and tempo over, {name: takes}: the training takes
#: before the validation ones, the validation takes, the test takes and the later takes.
TAKE_GROUPS = {"001-006": tuple(f"{k:03d}" for k in range(1, 7)), "007-008": VALIDATION_TAKES,
               "009-010": TEST_TAKES, "021-036": LATER_TAKES}
#: The 14 styles of dataset 1's guide and bye takes (one take, 001, each; licenses/dataset-1_style_label.txt
#: but "not-confident", which has neither).
GESTURE_STYLES = ("active", "angry", "childish", "chimpira", "feminine", "giant", "happy", "masculinity", "musical",
                  "normal", "old", "proud", "sad", "tired")
#: The guide and bye styles the gesture experiment tests on and never trains on: the same 4 for both, drawn
#: with this seed before any agent was trained (gesture_test_styles()).
GESTURE_SPLIT_SEED = 27
GESTURE_TEST_COUNT = 4
#: What each folder's takes perform, {folder: Behaviour}: as the paper's pair (the wave experiments: goodbye
#: waves tested as waves, guide takes as pointing), and as behaviours of their own beside the waves (the
#: gesture experiment): "this way" a target behaviour like point (the direction the arm is held in), a
#: goodbye wave an intensity one like wave (the exaggeration autolabel reads from the motion).
PAPER_LABELS = {"wave": behaviours.PAPER[1], "bye": behaviours.PAPER[1], "guide": behaviours.PAPER[0]}
GESTURE_LABELS = {"wave": behaviours.PAPER[1], "bye": behaviours.Behaviour("BYE", behaviours.INTENSITY),
                  "guide": behaviours.Behaviour("GUIDE", behaviours.TARGET)}
#: How far ahead along the held direction a guide take's target is put, metres (the sample library's
#: guiding targets are 1.5-5 m away): the guide metrics read its heading from the shoulder.
GUIDE_TARGET_DISTANCE = 3.0

_NAME = re.compile(r"dataset-(?P<dataset>\d)_(?P<content>[a-z]+)(?:-(?P<side>left|right)-hand)?"
                   r"_(?P<style>[a-z-]+)_(?P<take>\d{3})$")


def require_realmocap(root=REALMOCAP_DIR):
    """The real-mocap folder, or RLAnimateError saying where it is expected."""
    root = Path(root)
    if not (root / "wave").is_dir():
        raise RLAnimateError(f"The real motion capture is not at {root}: put the Bandai Namco clips "
                             "(wave/, bye/, guide/) there, as ../shared/realmocap/README.md describes.")
    return root


def take_paths(folder):
    """The .bvh takes in `folder`, sorted by name, without the withheld ones (WITHHELD_TAKES), which are
    never opened."""
    return [path for path in sorted(Path(folder).glob("*.bvh")) if parse_name(path)["take"] not in WITHHELD_TAKES]


def is_withheld(path) -> bool:
    """Whether `path` is named as one of the dataset's withheld takes (WITHHELD_TAKES): any file whose name reads
    as a Bandai Namco take of those numbers, wherever it lies; decided from the name alone."""
    match = _NAME.match(Path(path).stem)
    return match is not None and match["take"] in WITHHELD_TAKES


def parse_name(path):
    """{'content', 'arm' (LEFT/RIGHT or None), 'style', 'take'} of a real-mocap file name."""
    match = _NAME.match(Path(path).stem)
    if match is None:
        raise RLAnimateError(f"{path}: not a Bandai Namco file name (dataset-N_content_style_take.bvh).")
    side = match["side"]
    return {"content": match["content"], "arm": side.upper() if side else None,
            "style": match["style"], "take": match["take"]}


def take_group(take):
    """The name of the TAKE_GROUPS group that holds `take` ('001'), or None."""
    return next((name for name, takes in TAKE_GROUPS.items() if take in takes), None)


def wave_split(clips):
    """(train, test): takes 001-008 and 021-036, and takes 009-010, of the one-arm waves."""
    return [c for c in clips if c.take in TRAIN_TAKES], [c for c in clips if c.take in TEST_TAKES]


def style_holdout_split(clips, held_out=HOLDOUT_STYLES):
    """(train, test): every take of the other styles (but the withheld ones), and takes 001-010 of the
    held-out ones."""
    return ([c for c in clips if c.style not in held_out and c.take in TRAIN_TAKES + TEST_TAKES],
            [c for c in clips if c.style in held_out and c.take in FIRST_TAKES])


def take_validation_split(clips):
    """(train, validation): wave_split's training takes but the validation ones, and those: VALIDATION_TAKES of
    the styles whose takes 001-010 no test holds (not HOLDOUT_STYLES)."""
    train, _ = wave_split(clips)
    validation = [c for c in train if c.take in VALIDATION_TAKES and c.style not in HOLDOUT_STYLES]
    return [c for c in train if c not in validation], validation


def style_validation_split(clips, held_out=VALIDATION_STYLE):
    """(train, validation): style_holdout_split's training styles but `held_out`, their training takes, and
    `held_out`'s training takes of FIRST_TAKES (no test take of either experiment)."""
    train = [c for c in clips if c.style not in HOLDOUT_STYLES and c.take in TRAIN_TAKES]
    return ([c for c in train if c.style != held_out],
            [c for c in train if c.style == held_out and c.take in FIRST_TAKES])


def gesture_test_styles(seed=GESTURE_SPLIT_SEED, count=GESTURE_TEST_COUNT):
    """The guide and bye styles held out of training, sorted: `count` of GESTURE_STYLES drawn with `seed`
    (27, 4: active, childish, feminine, musical)."""
    return tuple(sorted(np.random.default_rng(seed).choice(GESTURE_STYLES, count, replace=False).tolist()))


def gesture_split(clips, test_styles=None):
    """(train, test) of the guide and bye takes among `clips` (other takes are in neither list): the takes of
    the styles not in `test_styles` (default gesture_test_styles()), and those of the styles in it."""
    test_styles = gesture_test_styles() if test_styles is None else tuple(test_styles)
    gestures = [c for c in clips if c.content in ("guide", "bye")]
    return ([c for c in gestures if c.style not in test_styles], [c for c in gestures if c.style in test_styles])
