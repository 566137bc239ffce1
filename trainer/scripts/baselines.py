"""Score RLAnimate and the baselines on the sample library's held-out clips: the sample-library section of
docs/results/baselines.json and .md.

    nice -n 10 python -m trainer.scripts.baselines [--agent PATH] [--clips MANIFEST] [--results DIR]
"""
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from rlanimate_addon.core import behaviours
from trainer.blender_io.clip_session import LibrarySession
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.blender_io.rig_session import new_empty_scene
from trainer.evaluation.baselines import AgentMethod, NearestClip, generate_for, mean_start_pose
from trainer.evaluation.scoring import score_motions, select_clips
from trainer.motion import autolabel
from trainer.motion.fk import ClipReferences
from trainer.paths import DEFAULT_MANIFEST, INSTALLED_AGENT, RESULTS_DIR, shown
from trainer.reporting.baselines_report import write_baselines_results
from trainer.scripts import cli
from trainer.scripts.cli import run_main


@dataclass(frozen=True)
class BaselinesSettings:
    """What the sample-library comparison scores, and where it writes."""
    agent: str = str(INSTALLED_AGENT)  # exported RLAnimate agent (.npz)
    clips: str = str(DEFAULT_MANIFEST)  # clip library: a manifest.json or the folder that holds one
    results: str = str(RESULTS_DIR)  # where baselines.json and .md go


def parse_settings(argv: Sequence[str] | None = None) -> BaselinesSettings:
    """BaselinesSettings from the command line."""
    return cli.parse_settings(BaselinesSettings, argv, prog="python -m trainer.scripts.baselines", doc=__doc__)


def sample_library_comparison(agent_path, manifest):
    """{set: {method: {score, smoothness[, label_error]}}} on the sample library's held-out clips, per
    behaviour; for waves the label error compares the auto-labels of the generated and the real clip
    (the library's own exaggeration scale is the generator's, not autolabel's)."""
    session = LibrarySession(manifest)
    train_clips = session.train_clips
    methods = {"rlanimate": AgentMethod(agent_path), "nearest_clip": NearestClip(train_clips),
               "procedural_ik": ProceduralIK(mean_start_pose(train_clips))}
    references = ClipReferences(session.env)
    sets = {}
    for behaviour in ("point", "wave"):
        clips = select_clips(session.test_clips, (behaviours.parse(behaviour),))
        rows = {}
        for name, method in methods.items():
            motions = generate_for(method, clips)
            result = score_motions(session.env, motions, clips, references)
            rows[name] = {key: result[key] for key in ("score", "smoothness")}
            if behaviour == "wave":
                rows[name]["label_error"] = float(np.mean([
                    abs(autolabel.label_wave(m).exaggeration - autolabel.label_wave(c.rotvecs).exaggeration)
                    for m, c in zip(motions, clips, strict=True)]))
        sets[f"{behaviour}, held-out clips ({len(clips)})"] = rows
    return sets, methods["rlanimate"].agent.metadata.get("training", {})


def main(argv=None):
    settings = parse_settings(argv)
    torch.set_num_threads(1)
    new_empty_scene()
    sets, training = sample_library_comparison(settings.agent, settings.clips)
    agent = shown(settings.agent)
    provenance = "untrained" if training.get("untrained") else ", ".join(
        f"{k} {training[k]}" for k in ("behaviour", "variant", "preset", "epochs", "episodes") if k in training)
    write_baselines_results(settings.results, "sample library",
                  f"The 10 held-out clips of sample_rigs/clips (targets and exaggerations no training clip has). "
                  f"RLAnimate: `{agent}` ({provenance}). "
                  f"Regenerate: `nice -n 10 python -m trainer.scripts.baselines --agent {agent}`.", sets)
    print((Path(settings.results) / "baselines.md").read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main))
