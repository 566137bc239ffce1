"""Write an untrained default-config RLAnimate agent (seed 0), for development.

    python -m trainer.scripts.export_untrained_agent [PATH]     (default: the add-on's default.npz)
"""
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import torch
import tyro

from trainer.agent.agent_export import export_agent
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent
from trainer.paths import INSTALLED_AGENT
from trainer.scripts import cli


@dataclass(frozen=True)
class ExportSettings:
    """Where the untrained agent goes."""
    path: tyro.conf.Positional[Path] = INSTALLED_AGENT  # the agent file to write


def parse_settings(argv: Sequence[str] | None = None) -> ExportSettings:
    """ExportSettings from the command line."""
    return cli.parse_settings(ExportSettings, argv, prog="python -m trainer.scripts.export_untrained_agent",
                              doc=__doc__)


def main(argv: Sequence[str] | None = None) -> None:
    path = parse_settings(argv).path
    torch.set_num_threads(1)
    torch.manual_seed(0)
    agent_config, train_config = load_preset("default")
    export_agent(RLAnimateAgent(agent_config), path,
                 {"train_config": train_config, "training": {"untrained": True, "seed": 0, "epochs": 0}})
    print(f"wrote an untrained agent to {path}")


if __name__ == "__main__":
    main()
