"""Train on a folder of your own takes with one command: `python trainer/train.py --clips FOLDER` on a folder of
.bvh or .fbx takes without a manifest.

`label_folder` imports every take (Blender's importers, trainer/blender_io/clip_import.py, into an import cache in
the run's folder), labels it from its names and motion (trainer/motion/capture_folder.py), holds out a share of the
takes, shows the labels as a table and writes them as <output>/manifest.json, which the user can edit and pass back
with --clips. After training, `compare_held_out` answers every held-out take's request with the agent (its exported
agent.npz, what the add-on plays) and with nearest-clip retrieval from the training takes, a wave's request both as
the paper asks it (its label) and naming its tempo; `write_report` writes <output>/capture_report.{json,md}
(trainer/reporting/capture_report.py).
"""
import json
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TypeGuard

import numpy as np
from tqdm import tqdm

from rlanimate_addon.core import behaviours, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io.clip_import import import_clip
from trainer.blender_io.rig_session import blender_output
from trainer.evaluation import baselines
from trainer.evaluation.behaviour import clip_target
from trainer.experiments.realmocap import REQUESTS, compare
from trainer.experiments.run import RunSettings
from trainer.files import atomic_write_text
from trainer.motion import capture_folder, clip_cache
from trainer.motion.hands import with_hand
from trainer.reporting.capture_report import capture_markdown, labels_markdown
from trainer.reporting.plots import gesture_hand_paths, wave_hand_paths

#: What a capture-folder run trains by default where the command line says nothing: the recipe chosen on real
#: capture's validation takes (docs/REALMOCAP.md).
CAPTURE_DEFAULTS: dict[str, Any] = {"preset": "end_chunks", "epochs": 100}
MANIFEST = "manifest.json"
REPORT = "capture_report"
PATHS_FIGURE = "capture_hand_paths.png"


def is_capture_folder(clips: str | None) -> TypeGuard[str]:
    """Whether --clips names a folder of takes without a manifest (what `label_folder` labels)."""
    return clips is not None and Path(clips).is_dir() and not (Path(clips) / MANIFEST).is_file()


@dataclass
class Labelled:
    """A labelled capture folder: its manifest (written), its takes' labels, and notes (takes left out)."""
    folder: str
    manifest: Path
    labels: list
    notes: list = field(default_factory=list)


def label_folder(folder: str, output: str, share: float = capture_folder.HOLD_OUT_SHARE,
                 verbose: bool = False) -> Labelled:
    """Import and label every take of `folder`, hold out `share` of them, print the labels table and write
    <output>/manifest.json; RLAnimateError when no take can be used."""
    paths, notes = capture_folder.find_takes(folder)
    if not paths:
        raise RLAnimateError(f"{folder} holds no .bvh or .fbx takes (in it or in a folder in it): put the takes "
                             "there, one gesture per file.")
    if not 0.0 <= share < 1.0:
        raise RLAnimateError(f"--hold-out {share:g}: hold out a share from 0 to below 1 of the takes, such as 0.2.")
    cache = Path(output) / clip_cache.CACHE_DIR_NAME
    labels = []
    with blender_output(verbose) as terminal:
        for path in tqdm(paths, desc="labelling", unit="take", file=terminal, leave=False, dynamic_ncols=True):
            try:
                labels.append(capture_folder.label_take(path, with_hand(import_clip(path, cache_dir=cache))))
            except RLAnimateError as error:
                notes.append(f"skipped: {error}")
    if not labels:
        raise RLAnimateError(f"None of the {len(paths)} takes of {folder} could be used: {'; '.join(notes[:3])}.")
    capture_folder.place_elevations(labels)
    capture_folder.hold_out(labels, share)
    manifest = Path(output) / MANIFEST
    atomic_write_text(manifest, json.dumps(capture_folder.manifest(labels, folder), indent=1) + "\n")
    labelled = Labelled(str(folder), manifest, labels, notes)
    print("\n".join(labels_markdown(labelled.labels)), flush=True)
    held = sum(label.split == "test" for label in labels)
    print(f"labels: {len(labels)} takes of {folder} ({held} held out), written to {manifest}; edit it and train on "
          f"it with --clips {manifest}", file=sys.stderr)
    for note in notes:
        print(f"  {note}", file=sys.stderr)
    return labelled


def capture_settings(settings: RunSettings, labelled: Labelled) -> RunSettings:
    """The run of a labelled capture folder: its manifest, CAPTURE_DEFAULTS where `settings` has no value, and, when
    no --behaviour is given, the behaviours its training takes have (a folder of waves alone trains a wave agent)."""
    trained = ",".join(dict.fromkeys(behaviours.key(label.behaviour) for label in labelled.labels
                                     if label.split == "train"))
    return replace(settings, clips=str(labelled.manifest), behaviour=settings.behaviour or trained,
                   **{name: value for name, value in CAPTURE_DEFAULTS.items() if getattr(settings, name) is None})


def compare_held_out(agent: baselines.AgentMethod, retrieval: baselines.NearestClip, session: Any) -> dict:
    """{behaviour key: {request: realmocap.compare's {method: result}}} on the session's held-out takes of each
    behaviour the agent performs: RLAnimate (`agent`, its agent.npz) against `retrieval` from the training takes; a
    wave's requests asked the paper's way ("paper") and naming its tempo ("tempo")."""
    methods = {"rlanimate": agent, "nearest_clip": retrieval}
    results = {}
    for behaviour in agent.agent.behaviours:
        held = [clip for clip in session.test_clips if clip.behaviour == behaviour]
        if not held:
            continue
        requests = REQUESTS if agent.agent.space.behaviour(behaviour).oscillates else {"": False}
        results[behaviours.key(behaviour)] = {suffix[1:] or "paper": compare(methods, held, session.env,
                                                                             session.references, with_tempo)
                                              for suffix, with_tempo in requests.items()}
    return results


#: The hand-path figure beside the page: up to this many held-out takes of each behaviour, over its labels, each
#: titled by the end of its name.
PATH_TAKES = 3
TITLE_CHARACTERS = 24


def hand_paths(agent: baselines.AgentMethod, retrieval: baselines.NearestClip, session: Any, path: Path) -> list[str]:
    """Plot the hand paths of up to PATH_TAKES held-out takes of each behaviour the agent performs, lowest to highest
    label: the take, the agent and retrieval (a wave asked its tempo) into `path`, the waves' side to side where there
    are waves, else the other gestures' held reach; the takes drawn."""
    methods: dict[str, Any] = {"RLAnimate": agent, "retrieval": retrieval}
    waves: list[Any] = []
    held: list[Any] = []
    for behaviour in agent.agent.behaviours:
        takes = sorted((c for c in session.test_clips if c.behaviour == behaviour),
                       key=lambda c: float(np.ravel(c.attributes)[0]))
        for clip in [takes[k] for k in sorted({round(x) for x in np.linspace(0, len(takes) - 1, PATH_TAKES)})] \
                if takes else []:
            tempo = baselines.request_tempo(clip, clip.declared.oscillates)
            played = {"the take": clip.rotvecs, **{name: method.generate(clip.behaviour, clip.arm, clip.attributes,
                                                                          clip.frames, tempo=tempo)
                                                   for name, method in methods.items()}}
            positions = {name: spaces.description_joint_positions(session.describe(r)) for name, r in played.items()}
            title = f"{clip.name[-TITLE_CHARACTERS:]} ({'tempo asked' if tempo else 'label only'})"
            (waves if clip.declared.oscillates else held).append((title, clip.arm, positions, clip_target(clip)))
    if waves:
        wave_hand_paths([panel[:3] for panel in waves], path)
    elif held:
        gesture_hand_paths(held, path)
    return [panel[0] for panel in waves or held]


def write_report(labelled: Labelled, report: dict, session: Any, output: str, command: str) -> Path:
    """<output>/capture_report.json and .md: the comparison on the held-out takes, with the labels table, and
    capture_hand_paths.png; returns the page's path."""
    agent, retrieval = baselines.AgentMethod(Path(output) / "agent.npz"), baselines.NearestClip(session.train_clips)
    results = {"folder": labelled.folder, "command": command, "manifest": str(labelled.manifest),
               "labels": capture_folder.table_rows(labelled.labels), "notes": labelled.notes,
               "training_takes": len(session.train_clips), "held_out_takes": len(session.test_clips),
               "run": {key: report[key] for key in ("preset", "epochs", "seed", "train_cpu_seconds")},
               "behaviours": compare_held_out(agent, retrieval, session),
               "hand_paths": hand_paths(agent, retrieval, session, Path(output) / PATHS_FIGURE)}
    atomic_write_text(Path(output) / f"{REPORT}.json", json.dumps(results, indent=1) + "\n")
    page = Path(output) / f"{REPORT}.md"
    atomic_write_text(page, capture_markdown(results))
    return page

