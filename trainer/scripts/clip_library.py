"""Regenerate the sample clip library deterministically from one seed: synthesise, bake onto the sample rig,
export as FBX into sample_rigs/clips/ with its manifest.json.

    python -m trainer.scripts.clip_library [--seed S] [--out DIR] [--only FILE ...]
"""
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from trainer.blender_io.clip_bake import build_library
from trainer.motion.library_plan import DEFAULT_SEED
from trainer.paths import CLIP_DIR
from trainer.scripts import cli


@dataclass(frozen=True)
class LibrarySettings:
    """Which clips of the sample library to make, from which seed, and where."""
    seed: int = DEFAULT_SEED  # the library plan's seed: the same seed makes the same clips
    out: Path = CLIP_DIR  # the folder the FBX clips and manifest.json go to
    only: tuple[str, ...] = ()  # regenerate just these files, such as point_left_000.fbx (none: every clip)


def parse_settings(argv: Sequence[str] | None = None) -> LibrarySettings:
    """LibrarySettings from the command line."""
    return cli.parse_settings(LibrarySettings, argv, prog="python -m trainer.scripts.clip_library", doc=__doc__)


def main(argv=None):
    settings = parse_settings(argv)
    manifest = build_library(settings.out, settings.seed, only=settings.only)
    print(f"wrote {len(manifest['clips'])} clips and manifest.json to {settings.out}")


if __name__ == "__main__":
    main()
