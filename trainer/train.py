"""Train an RLAnimate agent (Algorithm 1) and write the agent, its report and plots.

    python trainer/train.py [ARGS]
    blender -b -P trainer/train.py -- [ARGS]      (Blender's Python finds torch through a venv of
                                                   the same minor version on PYTHONPATH; see README)

With no arguments it trains the both-behaviour RLAnimate agent on the sample clip library into
runs/default/. `--install` also copies the agent to rlanimate_addon/agents/default.npz and its
report to docs/results/. Outputs in --output: agent.npz, checkpoint.pt (every --checkpoint-every
epochs, atomically), metrics.jsonl, report.json, report.md, training_curves.png, and tensorboard/
when TensorBoard is installed. `--resume` continues the run in --output from its checkpoint; the
continuation equals the uninterrupted run.
"""
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
if str(REPO_ROOT) not in sys.path:
    sys.path.insert(0, str(REPO_ROOT))

import argparse  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import random  # noqa: E402
import shutil  # noqa: E402

import numpy as np  # noqa: E402
import torch  # noqa: E402
from tqdm import tqdm  # noqa: E402

from rlanimate_addon.core import spaces  # noqa: E402
from rlanimate_addon.core.errors import RLAnimateError  # noqa: E402
from trainer import checkpoint, evaluate, plots  # noqa: E402
from trainer.algorithm import BEHAVIOUR_CHOICES, ClipReferences, Trainer  # noqa: E402
from trainer.bpy_support import SAMPLE_RIG_BLEND, script_args  # noqa: E402

DEFAULT_MANIFEST = REPO_ROOT / "sample_rigs" / "clips" / "manifest.json"
DEFAULT_OUTPUT = REPO_ROOT / "runs" / "default"
INSTALLED_AGENT = REPO_ROOT / "rlanimate_addon" / "agents" / "default.npz"
RESULTS_DIR = REPO_ROOT / "docs" / "results"
VARIANTS = ("rlanimate", "single_state", "single_dynamics", "supervised")
#: The paper's training lengths (Figure 3): 50 epochs for one behaviour, 100 for both.
PAPER_EPOCHS = {"point": 50, "wave": 50, "both": 100}
#: Run settings a resumed run takes from its checkpoint, so it continues the same experiment.
RESUMED_SETTINGS = ("behaviour", "clips", "preset", "variant", "seed", "eval_every")


def build_parser():
    parser = argparse.ArgumentParser(prog="trainer/train.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--behaviour", choices=BEHAVIOUR_CHOICES, default="both")
    parser.add_argument("--clips", default=str(DEFAULT_MANIFEST),
                        help="clip library: a manifest.json or the folder that holds one")
    parser.add_argument("--epochs", type=int, default=None,
                        help="iterations of Algorithm 1 (default: the preset's, the paper's 50 for one behaviour "
                             "and 100 for both; on --resume, the run's own)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--output", default=str(DEFAULT_OUTPUT))
    parser.add_argument("--preset", default="default", help="config preset: debug, default or paper")
    parser.add_argument("--variant", choices=VARIANTS, default="rlanimate", help="ablation variant (Table 4)")
    parser.add_argument("--resume", action="store_true", help="continue the run in --output from its checkpoint")
    parser.add_argument("--install", action="store_true",
                        help="install the agent as the add-on's default and its report into docs/results/")
    parser.add_argument("--eval-every", type=int, default=10,
                        help="evaluate on seen and unseen clips every N epochs (0: only at the end)")
    parser.add_argument("--checkpoint-every", type=int, default=1)
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    return parser


def manifest_path(clips):
    path = Path(clips)
    return path / "manifest.json" if path.is_dir() else path


def default_epochs(train_config, behaviour):
    return train_config.epochs_both if behaviour == "both" else train_config.epochs_single


def seed_everything(seed):
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)


class Session:
    """What a run needs besides the trainer: the FK environment and the clip library, loaded once
    and shared by the runs of an experiment."""

    def __init__(self, manifest, rig_path=SAMPLE_RIG_BLEND):
        from trainer.clip_import import load_clip_set
        from trainer.fk_env import FKEnvironment
        self.manifest = Path(manifest)
        self.clip_set = load_clip_set(self.manifest)
        self.env = FKEnvironment(rig_path)
        self.references = ClipReferences(self.env)

    @property
    def train_clips(self):
        return self.clip_set.train

    @property
    def test_clips(self):
        return self.clip_set.test


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


def evaluate_seen_unseen(trainer, session):
    """Held-out (unseen) and 10 training (seen) clips of the trainer's behaviour(s)."""
    unseen = evaluate.select_clips(session.test_clips, trainer.behaviour)
    seen = evaluate.select_clips(session.train_clips, trainer.behaviour, evaluate.SEEN_CLIP_COUNT)
    return {"unseen": evaluate.evaluate_clips(trainer.agent, session.env, unseen, session.references, trainer.bounds),
            "seen": evaluate.evaluate_clips(trainer.agent, session.env, seen, session.references, trainer.bounds)}


def run(args, session=None):
    """Train (or resume) one run as `args` says; returns (report dict, Trainer). Writes everything to args.output."""
    from trainer.config import load_preset
    from trainer.export import export_agent
    from trainer.models import RLAnimateAgent

    torch.set_num_threads(1)
    output = Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    saved = None
    if args.resume:
        saved = checkpoint.load(output / checkpoint.FILENAME)
        for name in RESUMED_SETTINGS:
            setattr(args, name, saved["arguments"][name])
        args.epochs = args.epochs or saved["arguments"]["epochs"]
    agent_config, train_config = load_preset(args.preset)
    session = session or Session(manifest_path(args.clips))
    epochs = args.epochs or default_epochs(train_config, args.behaviour)

    seed_everything(args.seed)
    agent = RLAnimateAgent(agent_config, args.variant)
    trainer = Trainer(agent, session.env, session.train_clips, train_config, args.behaviour, args.seed,
                      references=session.references, epochs=epochs)
    if saved is not None:
        trainer.load_state_dict(saved["trainer"])
    arguments = {**{name: getattr(args, name) for name in RESUMED_SETTINGS}, "epochs": epochs}
    log = MetricsLog(output, trainer.history)
    bar = tqdm(range(trainer.epoch, epochs), initial=trainer.epoch, total=epochs, disable=args.quiet,
               desc=f"{args.variant} {args.behaviour}", unit="epoch", dynamic_ncols=True)
    final = None
    for _ in bar:
        entry = trainer.run_epoch()
        if trainer.epoch == epochs or (args.eval_every and trainer.epoch % args.eval_every == 0):
            final = evaluate_seen_unseen(trainer, session)
            entry.update(_flatten(final))
        log.write(entry)
        bar.set_postfix({name[5:]: f"{value:.4g}" for name, value in entry.items() if name.startswith("loss/")})
        if trainer.epoch % args.checkpoint_every == 0 or trainer.epoch == epochs:
            checkpoint.save(output / checkpoint.FILENAME, trainer.state_dict(), arguments)
    bar.close()
    if final is None:  # resumed a run that had already finished
        final = evaluate_seen_unseen(trainer, session)
    log.close()
    report = _report(args, trainer, final, epochs)
    export_agent(agent, output / "agent.npz", _agent_metadata(report, trainer))
    _write_report(report, output)
    plots.training_curves(trainer.history, output / "training_curves.png", title=f"{args.variant}, {args.behaviour}")
    if args.install:
        install(output)
    return report, trainer


def install(output):
    """Copy a run's agent into the add-on (atomically) and its report and curves into docs/results/."""
    output = Path(output)
    INSTALLED_AGENT.parent.mkdir(parents=True, exist_ok=True)
    temporary = INSTALLED_AGENT.with_name(f".{INSTALLED_AGENT.name}.{os.getpid()}.tmp")
    shutil.copyfile(output / "agent.npz", temporary)
    os.replace(temporary, INSTALLED_AGENT)
    RESULTS_DIR.mkdir(parents=True, exist_ok=True)
    for source, target in (("report.json", "default_agent.json"), ("report.md", "default_agent.md"),
                           ("training_curves.png", "default_agent_curves.png")):
        shutil.copyfile(output / source, RESULTS_DIR / target)


def _flatten(evaluation):
    return {f"{split}/{name}": evaluation[split][name] for split in ("seen", "unseen")
            for name in ("score", "smoothness")}


def _report(args, trainer, final, epochs):
    seconds = sum(e["collect_seconds"] + e["update_seconds"] for e in trainer.history)
    cpu_seconds = sum(e["cpu_seconds"] for e in trainer.history)
    return {
        "behaviour": args.behaviour, "variant": args.variant, "preset": args.preset, "seed": args.seed,
        "clips": str(manifest_path(args.clips)), "epochs": epochs, "episodes": len(trainer.buffer),
        "frames": trainer.buffer.frames, "train_seconds": seconds, "train_cpu_seconds": cpu_seconds,
        "torch_threads": torch.get_num_threads(),
        "held_out": final["unseen"], "training": final["seen"],
        "final_losses": {k[5:]: v for k, v in trainer.history[-1].items() if k.startswith("loss/")},
    }


def _agent_metadata(report, trainer):
    lengths = {}
    for group in trainer.clip_groups:
        for clip in group:
            lengths.setdefault(clip.behaviour.upper(), []).append(len(clip.rotvecs))
    return {"training": {key: report[key] for key in ("behaviour", "variant", "preset", "seed", "clips",
                                                       "epochs", "episodes", "train_seconds")},
            "train_config": trainer.train_config,
            "action_bounds": trainer.bounds,
            "average_frames": {name: float(np.mean(values)) for name, values in lengths.items()},
            "evaluation": {"held_out_score": report["held_out"]["score"],
                           "held_out_smoothness": report["held_out"]["smoothness"]}}


def _write_report(report, output):
    with open(output / "report.json", "w") as handle:
        json.dump(report, handle, indent=2)
    lines = [f"# RLAnimate agent: {report['variant']}, {report['behaviour']}", "",
             f"Preset `{report['preset']}`, seed {report['seed']}, {report['epochs']} epochs (iterations of "
             f"Algorithm 1), {report['episodes']} sample episodes ({report['frames']} frames), "
             f"{report['train_seconds'] / 60:.1f} min of training (wall clock; {report['train_cpu_seconds'] / 60:.1f} "
             f"min of CPU time) with {report['torch_threads']} torch thread(s) on a machine shared with other jobs. "
             f"Clips: `{Path(report['clips']).relative_to(REPO_ROOT) if Path(report['clips']).is_relative_to(REPO_ROOT) else report['clips']}`.",
             "", "| clip set | clips | score | smoothness |", "|---|---|---|---|"]
    for label, key in (("held-out (unseen)", "held_out"), ("training (seen)", "training")):
        lines.append(f"| {label} | {len(report[key]['clips'])} | {report[key]['score']:.2f} | "
                     f"{report[key]['smoothness']:.2f} |")
        for behaviour, entry in report[key]["by_behaviour"].items():
            count = sum(c["behaviour"] == behaviour for c in report[key]["clips"])
            lines.append(f"| {label}, {behaviour} | {count} | {entry['score']:.2f} | {entry['smoothness']:.2f} |")
    lines += ["", "Per held-out clip:", "", "| clip | behaviour | score | smoothness |", "|---|---|---|---|"]
    lines += [f"| {c['name']} | {c['behaviour']} | {c['score']:.2f} | {c['smoothness']:.2f} |"
              for c in report["held_out"]["clips"]]
    (output / "report.md").write_text("\n".join(lines) + "\n")


def main(argv=None):
    args = build_parser().parse_args(script_args(argv))
    try:
        report, _ = run(args)
    except RLAnimateError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(f"held-out score {report['held_out']['score']:.2f}, smoothness {report['held_out']['smoothness']:.2f}; "
          f"outputs in {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
