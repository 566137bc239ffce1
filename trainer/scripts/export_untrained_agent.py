"""Write an untrained default-config RLAnimate agent (seed 0), for development.

    python -m trainer.scripts.export_untrained_agent [PATH]     (default: the add-on's default.npz)
"""
import sys
from pathlib import Path

import torch

from trainer.agent.agent_export import export_agent
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent
from trainer.paths import INSTALLED_AGENT


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    path = Path(argv[0]) if argv else INSTALLED_AGENT
    torch.set_num_threads(1)
    torch.manual_seed(0)
    agent_config, train_config = load_preset("default")
    export_agent(RLAnimateAgent(agent_config), path,
                 {"train_config": train_config, "training": {"untrained": True, "seed": 0, "epochs": 0}})
    print(f"wrote an untrained agent to {path}")


if __name__ == "__main__":
    main()
