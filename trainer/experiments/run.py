"""One training run: `train(RunSettings, session)` runs Algorithm 1 (or resumes it) and writes the agent,
its checkpoint, metrics, report and training curves into the run's output folder.

Outputs in `output`: agent.npz, checkpoint.pt (every `checkpoint_every` epochs, atomically),
metrics.jsonl, report.json, report.md, training_curves.png, and tensorboard/ when TensorBoard is
installed. A resumed run takes its settings from its checkpoint and continues bit for bit.
`train_runs` trains several runs of the sample-library kind as Ray tasks (trainer/cluster.py), each on its
own LibrarySession and pinned to one torch thread, so each is bit for bit the run `train` makes alone.
"""
import json
import os
import random
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import torch
import tyro
from tqdm import tqdm

from rlanimate_addon.core import behaviours
from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent import checkpoint
from trainer.agent.agent_export import export_agent
from trainer.agent.algorithm import Trainer
from trainer.agent.config import PRESETS, load_preset
from trainer.agent.models import VARIANTS, RLAnimateAgent
from trainer.blender_io.clip_session import LibrarySession
from trainer.cluster import connect, run_tasks
from trainer.evaluation.scoring import evaluate_seen_unseen, select_clips
from trainer.experiments.options import one_of
from trainer.motion.autolabel import still_free_arm
from trainer.motion.clip import trained_behaviours, training_space
from trainer.motion.library_checks import check_new_behaviours, left_out
from trainer.motion.manifest import manifest_path
from trainer.paths import DEFAULT_MANIFEST
from trainer.reporting import plots
from trainer.reporting.run_report import write_run_report

#: Settings a resumed run takes from its checkpoint, so that it continues the same experiment.
RESUMED_SETTINGS = ("behaviour", "clips", "preset", "variant", "seed", "eval_every")


@dataclass(frozen=True)
class RunSettings:
    """What a run is (train.py's command line). A setting left out (None) takes the default its help names,
    or on --resume the run's own value."""
    output: str  # the run's folder: its agent, checkpoint, metrics, report and plots
    # the behaviours to learn: all (every behaviour of the clip library), both (point and wave), one
    # behaviour (point), or several joined by commas (point,beckon) (None: all; on --resume, the run's own)
    behaviour: str | None = None
    # clip library: a manifest.json or the folder that holds one; or a folder of .bvh/.fbx takes without one, which
    # is labelled from the takes' names and motion into <output>/manifest.json (None: sample_rigs/clips)
    clips: str | None = None
    # iterations of Algorithm 1 (None: the preset's, the paper's 50 for one behaviour and 100 for both;
    # on --resume, the run's own)
    epochs: int | None = None
    seed: int | None = None  # the training seed (None: 2)
    preset: str | None = None  # config preset: debug, default or paper (None: default)
    variant: Annotated[str | None, one_of(VARIANTS)] = None  # ablation variant (Table 4; None: rlanimate)
    # evaluate on seen and unseen clips every N epochs (0: only at the end; None: 10)
    eval_every: int | None = None
    resume: bool = False  # continue the run in --output from its checkpoint, with the run's own settings
    overwrite: bool = False  # replace the run in --output (without it, a new run into a run's folder is refused)
    # with --behaviour all, also learn a behaviour other than point and wave that fewer than 3 clips name (without
    # it, such a behaviour is refused as a likely typo)
    allow_new_behaviour: bool = False
    checkpoint_every: int = 1  # write the run's checkpoint every N epochs
    progress: tyro.conf.Suppress[bool] = True  # show a progress bar (the command line's --quiet turns it off)


#: Seed 2: of seeds 0-3 of the default preset (T = 120 updates an epoch), the one whose agent meets issue
#: 10's bounds with the most room; the shipped agent is that run (docs/AGENT.md, "The budget and the shipped
#: seed").
NEW_RUN_DEFAULTS = {"behaviour": behaviours.ALL, "clips": str(DEFAULT_MANIFEST), "seed": 2, "preset": "default",
                    "variant": "rlanimate", "eval_every": 10}


def resolve(settings: RunSettings) -> RunSettings:
    """`settings` with every None filled: from the run's checkpoint when resuming (RLAnimateError when a
    given value conflicts with the run's own), else from NEW_RUN_DEFAULTS. `epochs` stays None when not
    given to a new run (the preset decides)."""
    check_settings(settings)
    saved = checkpoint.load(Path(settings.output) / checkpoint.FILENAME) if settings.resume else None
    return _resolved(settings, saved)


def check_settings(settings: RunSettings) -> None:
    """RLAnimateError naming every setting no run can use: called before any work is done."""
    problems = []
    if settings.epochs is not None and not (_is_count(settings.epochs) and settings.epochs >= 1):
        problems.append(f"--epochs {settings.epochs}: train at least 1 epoch (leave --epochs out for the "
                        "preset's length, the paper's 50 for one behaviour and 100 for both)")
    if not (_is_count(settings.checkpoint_every) and settings.checkpoint_every >= 1):
        problems.append(f"--checkpoint-every {settings.checkpoint_every}: write a checkpoint every 1 or more "
                        "epochs (the default 1 writes one after every epoch)")
    if settings.eval_every is not None and not (_is_count(settings.eval_every) and settings.eval_every >= 0):
        problems.append(f"--eval-every {settings.eval_every}: evaluate every N >= 1 epochs, or 0 for only at the "
                        "end")
    if settings.seed is not None and not (_is_count(settings.seed) and 0 <= settings.seed < 2 ** 32):
        problems.append(f"--seed {settings.seed}: use a seed from 0 to {2 ** 32 - 1}")
    if settings.preset is not None and settings.preset not in PRESETS:
        problems.append(f"--preset {settings.preset}: unknown config preset; use one of {', '.join(PRESETS)}")
    problems += _output_problems(settings.output) or _existing_run_problems(settings)
    if problems:
        raise RLAnimateError("; ".join(problems) + ". Nothing was trained.")


def _output_problems(output):
    """[] when the run can write in `output` (or create it), else the one problem, found by creating and
    removing a temporary file in its nearest existing folder (permission bits alone do not tell for root or
    a read-only mount)."""
    path = Path(output)
    existing = next(p for p in (path, *path.parents) if p.exists())
    if not existing.is_dir():
        return [f"--output {output}: {existing} is a file, not a folder; choose a folder for the run's outputs"]
    try:
        tempfile.TemporaryFile(dir=existing).close()
    except OSError as error:
        return [f"--output {output}: cannot write in {existing} ({error.strerror}); choose a folder you can write to"]
    return []


#: What a run writes in its folder: --overwrite removes them (and nothing else) before the new run writes.
RUN_OUTPUTS = ("agent.npz", checkpoint.FILENAME, "metrics.jsonl", "report.json", "report.md", "training_curves.png",
               "tensorboard")


def _existing_run_problems(settings: RunSettings) -> list[str]:
    """[] when a run may start in `settings.output`, else the one problem: --resume with --overwrite, or a
    new run into the folder of another run (finished: its agent.npz; stopped: its checkpoint) without
    --overwrite."""
    output = Path(settings.output)
    if settings.resume and settings.overwrite:
        return [f"--resume and --overwrite: give one (--resume continues the run in {output}, --overwrite "
                "replaces it with a new one)"]
    if settings.resume or settings.overwrite:
        return []
    if (output / "agent.npz").is_file():
        return [f"--output {output} holds a finished run (its agent.npz): choose another --output, or add "
                "--overwrite to replace that run"]
    if (output / checkpoint.FILENAME).is_file():
        return [f"--output {output} holds a run that has not finished (its {checkpoint.FILENAME}): continue it "
                "with --resume, or add --overwrite to replace it"]
    return []


def _is_count(value):
    return isinstance(value, int) and not isinstance(value, bool)


def _resolved(settings, saved):
    """`settings` checked and completed from NEW_RUN_DEFAULTS, or from the checkpoint `saved` when resuming."""
    check_settings(settings)
    if saved is None:
        return replace(settings, **{name: value for name, value in NEW_RUN_DEFAULTS.items()
                                    if getattr(settings, name) is None})
    saved_arguments = saved["arguments"]
    conflicts = [f"--{name.replace('_', '-')} {getattr(settings, name)} (the run has {saved_arguments[name]})"
                 for name in RESUMED_SETTINGS
                 if getattr(settings, name) is not None and getattr(settings, name) != saved_arguments[name]]
    if conflicts:
        raise RLAnimateError(f"Cannot resume the run in {settings.output} with {', '.join(conflicts)}: a resumed "
                             "run keeps its own settings. Leave those options out, or start a new run elsewhere.")
    trained = saved["trainer"]["epoch"]
    if settings.epochs is not None and settings.epochs < trained:
        raise RLAnimateError(f"--epochs {settings.epochs}, but the run in {settings.output} has trained {trained} "
                             f"epochs already: give {trained} or more to finish or extend it, or leave --epochs out "
                             "to finish it as planned.")
    return replace(settings, **{name: saved_arguments[name] for name in RESUMED_SETTINGS},
                   epochs=settings.epochs or saved_arguments["epochs"])


def seed_everything(seed: int) -> None:
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)


class MetricsLog:
    """metrics.jsonl, rewritten from the checkpoint's history on resume, and TensorBoard when installed."""

    def __init__(self, output, history):
        self.path = Path(output) / "metrics.jsonl"
        with open(self.path, "w") as handle:
            handle.writelines(json.dumps(entry) + "\n" for entry in history)
        try:
            from torch.utils.tensorboard import SummaryWriter
            self.tensorboard = SummaryWriter(str(Path(output) / "tensorboard"))
        except ImportError:
            self.tensorboard = None

    def write(self, entry):
        with open(self.path, "a") as handle:
            handle.write(json.dumps(entry) + "\n")
        if self.tensorboard is not None:
            for name, value in entry.items():
                if name != "epoch":
                    self.tensorboard.add_scalar(name, value, entry["epoch"])
            self.tensorboard.flush()

    def close(self):
        if self.tensorboard is not None:
            self.tensorboard.close()


def train(settings: RunSettings, session: Any) -> tuple[dict, Trainer]:
    """Train (or resume) the run `settings` describes on `session` (env, references, train_clips, test_clips,
    problems: trainer.blender_io.clip_session.LibrarySession of `resolve(settings).clips`, or the real-mocap
    one); returns (report dict, Trainer). report.json lists the clips the session skipped."""
    torch.set_num_threads(1)
    output = Path(settings.output)
    saved = checkpoint.load(output / checkpoint.FILENAME) if settings.resume else None
    settings = _resolved(settings, saved)
    trainer, epochs = _trainer(settings, session, saved)
    _prepare_output(settings)
    arguments = {**{name: getattr(settings, name) for name in RESUMED_SETTINGS}, "epochs": epochs}
    log = MetricsLog(output, trainer.history)
    bar = tqdm(range(trainer.epoch, epochs), initial=trainer.epoch, total=epochs, disable=not settings.progress,
               desc=f"{settings.variant} {settings.behaviour}", unit="epoch", dynamic_ncols=True)
    final = None
    for _ in bar:
        entry = trainer.run_epoch()
        if trainer.epoch == epochs or (settings.eval_every and trainer.epoch % settings.eval_every == 0):
            final = evaluate_seen_unseen(trainer, session)
            entry.update(_flatten(final))
        log.write(entry)
        bar.set_postfix({name[5:]: f"{value:.4g}" for name, value in entry.items() if name.startswith("loss/")})
        if trainer.epoch % settings.checkpoint_every == 0 or trainer.epoch == epochs:
            checkpoint.save(output / checkpoint.FILENAME, trainer.state_dict(), arguments)
    bar.close()
    if final is None:  # resumed a run that had already finished
        final = evaluate_seen_unseen(trainer, session)
    log.close()
    report = _report(settings, trainer, final, epochs, session.problems, session.test_clips)
    export_agent(trainer.played_agent, output / "agent.npz", _agent_metadata(report, trainer))
    write_run_report(report, output)
    plots.training_curves(trainer.history, output / "training_curves.png",
                          title=f"{settings.variant}, {settings.behaviour}")
    return report, trainer


def _trainer(settings: RunSettings, session: Any, saved: dict | None) -> tuple[Trainer, int]:
    """(Trainer, planned epochs) of the resolved `settings` on `session`, from the checkpoint `saved` when
    resuming; a new run with "all" first says which of the library's behaviours it leaves out, and refuses
    a new behaviour that fewer than 3 clips name (library_checks)."""
    assert settings.behaviour is not None and settings.seed is not None, "resolved settings (resolve) fill both"
    agent_config, train_config = load_preset(settings.preset)
    trained = trained_behaviours(session.train_clips, settings.behaviour)
    if settings.behaviour == behaviours.ALL:
        if saved is None and not settings.allow_new_behaviour:
            check_new_behaviours([*session.train_clips, *session.test_clips], trained)
        note = left_out(session.train_clips, session.test_clips, trained)
        if note:
            print(note, file=sys.stderr)
    epochs = settings.epochs or (train_config.epochs_both if len(trained) > 1 else train_config.epochs_single)
    seed_everything(settings.seed)
    agent = RLAnimateAgent(agent_config, settings.variant, training_space(session.train_clips, settings.behaviour))
    trainer = Trainer(agent, session.env, session.train_clips, train_config, settings.behaviour, settings.seed,
                      references=session.references, epochs=epochs)
    if not select_clips(session.test_clips, trainer.trained):
        held_out = " or ".join(behaviours.key(b) for b in trainer.trained)
        print(f"note: the library has no held-out {held_out} clips (split \"test\"): the run is scored on "
              "training clips only. Mark some clips \"split\": \"test\" in the manifest to measure unseen requests.",
              file=sys.stderr)
    if saved is not None:
        trainer.load_state_dict(saved["trainer"])
    return trainer, epochs


def _prepare_output(settings: RunSettings) -> None:
    """Make the run's folder, once every check has passed (so a refused run leaves none); with --overwrite,
    first remove the files of the run it replaces (RUN_OUTPUTS)."""
    output = Path(settings.output)
    if settings.overwrite:
        for path in (output / name for name in RUN_OUTPUTS):
            if path.is_dir():
                shutil.rmtree(path)
            elif path.exists():
                path.unlink()
    output.mkdir(parents=True, exist_ok=True)


def _flatten(evaluation):
    return {f"{split}/{name}": evaluation[split][name] for split in ("seen", "unseen") if split in evaluation
            for name in ("score", "smoothness")}


def _not_scored(trainer, held_out_clips):
    """[{name, behaviour, why}] of the held-out clips the run does not score: those of behaviours it did not train."""
    trained = ", ".join(behaviours.key(b) for b in trainer.trained)
    return [{"name": getattr(clip, "name", ""), "behaviour": behaviours.key(clip.behaviour),
             "why": f"the agent was not trained on {behaviours.key(clip.behaviour)} (--behaviour {trained})"}
            for clip in held_out_clips if clip.behaviour not in trainer.trained]


def _report(settings, trainer, final, epochs, skipped, held_out_clips=()):
    seconds = sum(e["collect_seconds"] + e["update_seconds"] for e in trainer.history)
    cpu_seconds = sum(e["cpu_seconds"] for e in trainer.history)
    return {
        "behaviour": settings.behaviour, "variant": settings.variant, "preset": settings.preset,
        "seed": settings.seed, "clips": str(manifest_path(settings.clips)), "epochs": epochs,
        "episodes": len(trainer.buffer),
        "frames": trainer.buffer.frames, "train_seconds": seconds, "train_cpu_seconds": cpu_seconds,
        "torch_threads": torch.get_num_threads(),
        "held_out": final.get("unseen"), "training": final["seen"],  # held_out None: no held-out clips
        "final_losses": {k[5:]: v for k, v in trainer.history[-1].items() if k.startswith("loss/")},
        "skipped_clips": list(skipped),
        "training_clips": {behaviours.key(group[0].behaviour): len(group) for group in trainer.clip_groups},
        "not_scored": _not_scored(trainer, held_out_clips),
    }


def _agent_metadata(report, trainer):
    lengths = {}
    for group in trainer.clip_groups:
        for clip in group:
            lengths.setdefault(clip.behaviour, []).append(len(clip.rotvecs))
    return {"training": {key: report[key] for key in ("behaviour", "variant", "preset", "seed", "clips",
                                                       "epochs", "episodes", "train_seconds")},
            "train_config": trainer.train_config,
            "action_bounds": trainer.bounds,
            "average_frames": {name: float(np.mean(values)) for name, values in lengths.items()},
            "wave_rhythm": None if trainer.rhythm_model is None else trainer.rhythm_model.to_dict(),
            "still_free_arm": still_free_arm([clip for group in trainer.clip_groups for clip in group]),
            "evaluation": {} if report["held_out"] is None else {  # {}: no held-out clips
                "held_out_score": report["held_out"]["score"], "held_out_smoothness": report["held_out"]["smoothness"]}}


def train_logged(settings: RunSettings, make_session: Callable[[], Any] | None = None) -> dict:
    """`train` on make_session() (None: a LibrarySession of `settings.clips`), everything both print
    (Blender's too) going to train.log in the run's folder; returns the report. What a Ray task of
    `train_runs` (or of the real-capture experiment) runs."""
    output = Path(settings.output)
    output.mkdir(parents=True, exist_ok=True)
    with _output_to(output / "train.log"):
        session = LibrarySession(settings.clips) if make_session is None else make_session()
        return train(settings, session)[0]


def is_finished(folder: Path, epochs: int) -> bool:
    """Whether the run in `folder` has trained its `epochs` and written its report."""
    report = Path(folder) / "report.json"
    return report.is_file() and json.loads(report.read_text())["epochs"] == epochs


def train_runs(runs: Iterable[RunSettings], address: str | None = None,
               workers: int | None = None) -> Iterator[tuple[RunSettings, dict]]:
    """(settings, report) of each run, trained as Ray tasks on a local Ray of `workers` CPUs or on the
    cluster at `address` (trainer/cluster.py), in the order they finish."""
    runs = list(runs)
    if runs:
        connect(address, workers)
        yield from run_tasks(train_logged, runs, name=lambda run: f"The run in {run.output}")


@contextmanager
def _output_to(path):
    """File descriptors 1 and 2 (Python's prints and Blender's) into `path` for the duration."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with open(path, "w") as log:
        os.dup2(log.fileno(), 1)
        os.dup2(log.fileno(), 2)
        try:
            yield
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            for descriptor, copy in zip((1, 2), saved, strict=True):
                os.dup2(copy, descriptor)
                os.close(copy)
