"""A folder of a studio's own takes, without a manifest, as a labelled clip library (numpy; the takes are imported
by trainer/experiments/capture.py).

Each take is a .bvh or .fbx file in the folder or in a subfolder of it. Its labels come from its names and its
motion (trainer/motion/autolabel.py):
    behaviour     a known behaviour's word in the file name (wave, point, guide, raise_hand), else the name of the
                  folder that holds it; its kind is the known one, else intensity (a new gesture: edit the manifest
                  to "kind": "target" for one that aims at something)
    arm           the arm that moves more (the file name's left/right, where it disagrees, is noted)
    exaggeration  WAVE: autolabel.label_wave; another intensity behaviour: how high its arm goes, placed between
                  the lowest (0) and highest (1) of that behaviour's takes
    direction     a target behaviour: autolabel.label_point's held direction
    tempo         WAVE: the Hz its hand swings at (wave_rhythm.tempo_reading), the tempo a request for it names
A share of the takes is held out by take (`hold_out`): in each behaviour and arm, takes spread evenly over the
label's range. A wave too short to read its swing is held out (asked with its label alone), never trained on.
`manifest` writes the labels as a clip manifest (trainer/motion/manifest.py) the user can edit and pass back.
"""
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from rlanimate_addon.core import behaviours, frame_rate, skeleton
from trainer.motion import autolabel, realmocap_takes, wave_rhythm
from trainer.motion.clip import MotionClip

SUFFIXES = (".bvh", ".fbx")
#: The share of a behaviour and arm's takes held out for the comparison report, by default.
HOLD_OUT_SHARE = 0.2
#: Metres: how far along a target behaviour's held direction the manifest puts its target (the sample library's
#: are 1.5-4 m away), so that the report can measure the aim.
TARGET_DISTANCE = 3.0


@dataclass
class TakeLabel:
    """One take's labels, as the table shows them and the manifest writes them."""
    path: str
    behaviour: str
    kind: str
    arm: str
    frames: int
    fps: float
    exaggeration: float | None = None  # intensity behaviours
    direction: tuple[float, float, float] | None = None  # target behaviours: unit vector from the rest shoulder
    elevation: float | None = None  # degrees: how high the arm goes (an intensity behaviour other than WAVE)
    tempo: float | None = None  # Hz: a wave's swing, the tempo its request names
    split: str = "train"
    notes: list[str] = field(default_factory=list)

    @property
    def name(self) -> str:
        return Path(self.path).name

    @property
    def value(self) -> float:
        """The label the hold-out spreads over: the exaggeration, or the direction's azimuth (radians)."""
        if self.exaggeration is not None:
            return self.exaggeration
        assert self.direction is not None, "a take is labelled with an exaggeration or a direction"
        return float(np.arctan2(self.direction[0], -self.direction[1]))


def find_takes(folder) -> tuple[list[Path], list[str]]:
    """(the take files in `folder` and its subfolders, sorted; notes): files named as the capture dataset's
    withheld takes (realmocap_takes.is_withheld) are left out unopened, and said."""
    folder = Path(folder)
    paths = sorted(p for p in [*folder.iterdir(), *(q for d in folder.iterdir() if d.is_dir() for q in d.iterdir())]
                   if p.is_file() and p.suffix.lower() in SUFFIXES)
    withheld = {p for p in paths if realmocap_takes.is_withheld(p)}
    notes = [f"left out {len(withheld)} take(s) held out for evaluation elsewhere, unopened: "
             f"{', '.join(p.name for p in paths if p in withheld)}"] if withheld else []
    return [p for p in paths if p not in withheld], notes


def label_take(path, clip: MotionClip) -> TakeLabel:
    """The labels of one imported take (a MotionClip on the canonical rig) from its names and motion."""
    behaviour = autolabel.behaviour_from_name(path)
    kind = autolabel.NAMED_BEHAVIOURS.get(behaviour, behaviours.INTENSITY)
    label = TakeLabel(str(Path(path).resolve()), behaviour, kind, "", clip.frames, clip.fps)
    if behaviour not in autolabel.NAMED_BEHAVIOURS:
        label.notes.append(f"{behaviour}: a gesture of its own, labelled as an intensity one (how high the arm "
                           "goes); make it \"kind\": \"target\" in the manifest if it aims at something")
    if kind == behaviours.TARGET:
        read = autolabel.label_point(clip.rotvecs)
        x, y, z = (float(v) for v in read.direction)
        label.arm, label.direction = read.arm, (x, y, z)
    elif behaviours.SHIPPED.get(behaviour) == behaviours.OSCILLATES:
        read = autolabel.label_wave(clip.rotvecs, clip.fps)
        label.arm, label.exaggeration = read.arm, read.exaggeration
        label.tempo, why = wave_rhythm.tempo_reading(replace(clip, arm=read.arm))
        if wave_rhythm.too_short(clip):
            label.split = "test"
            label.notes.append(f"{why}: held out, asked with its label alone, never trained on")
        elif why:
            label.notes.append(why)
    else:
        label.arm, label.elevation = autolabel.arm_elevation(clip.rotvecs)
    named = autolabel.arm_from_name(path)
    if named is not None and named != label.arm:
        label.notes.append(f"the name says {named.lower()} arm, the motion moves the {label.arm.lower()} one more")
    return label


def place_elevations(labels: list[TakeLabel]) -> None:
    """Give each intensity take labelled by its elevation its exaggeration: where its elevation lies between
    the lowest (0) and highest (1) of its behaviour's takes (0.5 when they are all alike)."""
    for behaviour in {label.behaviour for label in labels if label.elevation is not None}:
        group = [(label, label.elevation) for label in labels
                 if label.behaviour == behaviour and label.elevation is not None]
        low, high = min(e for _, e in group), max(e for _, e in group)
        for label, elevation in group:
            label.exaggeration = 0.5 if high - low < 1e-6 else (elevation - low) / (high - low)


def hold_out(labels: list[TakeLabel], share: float = HOLD_OUT_SHARE) -> None:
    """Mark a `share` of each behaviour and arm's takes "test", spread evenly over their labels' range (never the
    last training take of a group; a group of one keeps it)."""
    for key in sorted({(label.behaviour, label.arm) for label in labels}):
        group = sorted((label for label in labels if (label.behaviour, label.arm) == key and label.split == "train"),
                       key=lambda label: (label.value, label.name))
        count = min(len(group) - 1, max(1, round(share * len(group)))) if share > 0 else 0
        for position in ((np.arange(count) + 0.5) * len(group) / max(count, 1)).astype(int):
            group[position].split = "test"


def manifest(labels: list[TakeLabel], folder) -> dict:
    """The clip manifest of the labels (trainer/motion/manifest.py), files by absolute path, a target behaviour's
    direction and a target TARGET_DISTANCE along it; `tempo_hz` and `notes` are for the reader and ignored by the
    importer."""
    entries = []
    for label in labels:
        entry = {"file": label.path, "behaviour": label.behaviour, "kind": label.kind, "arm": label.arm,
                 "frames": label.frames, "fps": round(label.fps, 3), "split": label.split}
        if label.direction is not None:  # and a target along it, which the behaviour measures aim at
            entry["direction"] = [round(v, 5) for v in label.direction]
            target = skeleton.shoulder_rest_position(label.arm) + TARGET_DISTANCE * np.asarray(label.direction)
            entry["target"] = [round(float(v), 4) for v in target]
        elif label.exaggeration is not None:
            entry["exaggeration"] = round(label.exaggeration, 4)
        if label.tempo is not None:
            entry["tempo_hz"] = round(label.tempo, 3)
        if label.notes:
            entry["notes"] = label.notes
        entries.append(entry)
    return {"source": str(Path(folder).resolve()), "labelled_by": "trainer/motion/autolabel.py",
            "fps": int(frame_rate.AGENT_FPS),
            "clips": entries}


def table_rows(labels: list[TakeLabel]) -> list[list[str]]:
    """Rows of the labels table: take, behaviour (kind), arm, label, tempo, frames, split, notes."""
    rows = []
    for label in labels:
        if label.direction is not None:
            azimuth, elevation = _angles(label.direction, label.arm)
            value = f"azimuth {azimuth:.0f}, elevation {elevation:.0f} deg"
        else:
            value = f"exaggeration {label.exaggeration:.2f}"
        rows.append([label.name, f"{behaviours.key(label.behaviour)} ({label.kind})", label.arm.lower(), value,
                     "" if label.tempo is None else f"{label.tempo:.2f} Hz", str(label.frames), label.split,
                     "; ".join(label.notes)])
    return rows


def _angles(direction, arm) -> tuple[float, float]:
    """(azimuth, elevation) in degrees of a direction: azimuth out to the arm's side from straight ahead."""
    x, y, z = direction
    outward = x if arm == skeleton.ARMS[0] else -x
    return float(np.degrees(np.arctan2(outward, -y))), float(np.degrees(np.arcsin(np.clip(z, -1.0, 1.0))))
