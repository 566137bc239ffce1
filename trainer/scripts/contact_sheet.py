"""Render the clip library's contact sheet (docs/contact_sheet.png).

    python -m trainer.scripts.contact_sheet [--out docs/contact_sheet.png] [--seed S]
"""
import argparse
from pathlib import Path

from trainer.motion.library_plan import DEFAULT_SEED
from trainer.paths import CONTACT_SHEET
from trainer.reporting.contact_sheet import render


def main(argv=None):
    parser = argparse.ArgumentParser(description="Render the clip library's contact sheet.")
    parser.add_argument("--out", type=Path, default=CONTACT_SHEET)
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED)
    args = parser.parse_args(argv)
    print(f"wrote {render(args.out, args.seed)}")


if __name__ == "__main__":
    main()
