"""Regenerate the sample clip library deterministically from one seed: synthesise, bake onto the sample rig,
export as FBX into sample_rigs/clips/ with its manifest.json.

    python -m trainer.scripts.clip_library [--seed S] [--out DIR] [--only FILE ...]
"""
import argparse
from pathlib import Path

from trainer.blender_io.clip_bake import build_library
from trainer.motion.library_plan import DEFAULT_SEED
from trainer.paths import CLIP_DIR
from trainer.scripts.cli import script_args


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED)
    parser.add_argument("--out", type=Path, default=CLIP_DIR)
    parser.add_argument("--only", nargs="*", help="regenerate just these files (e.g. point_left_000.fbx)")
    args = parser.parse_args(script_args(argv))
    manifest = build_library(args.out, args.seed, only=args.only)
    print(f"wrote {len(manifest['clips'])} clips and manifest.json to {args.out}")


if __name__ == "__main__":
    main()
