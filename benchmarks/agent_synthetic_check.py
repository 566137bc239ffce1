"""A quick learning check of the agent without Blender: Algorithm 1 on a synthetic clip library.

Run: `nice -n 10 python benchmarks/agent_synthetic_check.py [VARIANT] [EPOCHS] [--no-portrayal-loss]`

It trains the both-behaviour agent of the `default` preset with trainer/agent/algorithm.py, but plays
actions through the numpy FK environment (trainer/motion/fk.py) instead of the bpy one, on the synthetic library of
the trainer tests
(20 training clips per behaviour, one held-out clip per behaviour and arm). It prints held-out
and seen score / smoothness and the losses every 10 epochs. It is a check of the models and losses
in minutes, not the paper's experiment (that is trainer/train.py on the sample clip library).
"""
import argparse
import dataclasses
import sys
import time
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO_ROOT))
sys.path.insert(0, str(REPO_ROOT / "tests" / "trainer"))

import torch  # noqa: E402

import synthetic_library  # noqa: E402
from trainer.agent.algorithm import Trainer  # noqa: E402
from trainer.agent.config import load_preset  # noqa: E402
from trainer.agent.models import VARIANTS, RLAnimateAgent  # noqa: E402
from trainer.evaluation import scoring  # noqa: E402
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("variant", nargs="?", default="rlanimate", choices=VARIANTS)
    parser.add_argument("epochs", nargs="?", type=int, default=40)
    parser.add_argument("--no-portrayal-loss", action="store_true")
    args = parser.parse_args()
    torch.set_num_threads(1)
    torch.manual_seed(0)
    library = synthetic_library.make_library(seed=0, per_behaviour=20)
    agent_config, train_config = load_preset("default")
    train_config = dataclasses.replace(train_config, portrayal_direct_loss=not args.no_portrayal_loss)
    env = NumpyFKEnvironment()
    references = ClipReferences(env)
    agent = RLAnimateAgent(agent_config, args.variant)
    trainer = Trainer(agent, env, library.train, train_config, "both", 0, references=references)
    start = time.perf_counter()
    for epoch in range(1, args.epochs + 1):
        metrics = trainer.run_epoch()
        if epoch % 10 == 0 or epoch == args.epochs:
            unseen = scoring.evaluate_clips(agent, env, library.test, references)
            seen = scoring.evaluate_clips(agent, env, library.train[:10], references)
            losses = " ".join(f"{k[5:]} {v:.3g}" for k, v in metrics.items() if k.startswith("loss/"))
            print(f"epoch {epoch} ({time.perf_counter() - start:.0f} s): held-out {unseen['score']:.2f} / "
                  f"{unseen['smoothness']:.2f}, seen {seen['score']:.2f} / {seen['smoothness']:.2f}; {losses}",
                  flush=True)


if __name__ == "__main__":
    main()
