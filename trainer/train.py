"""Train an RLAnimate agent: `python trainer/train.py [ARGS]` or `blender -b -P trainer/train.py -- [ARGS]`.

A thin shim for the two ways that run a file rather than a module: it puts the repository on sys.path
and runs trainer/scripts/train.py (`python -m trainer.scripts.train` is the same).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from trainer.scripts import cli, train  # noqa: E402

if __name__ == "__main__":
    sys.exit(cli.run_main(train.main, interrupted=train.INTERRUPTED))
