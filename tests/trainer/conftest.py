"""Fixtures the trainer's tests share."""
import json
import shutil

import pytest

from trainer.paths import CLIP_DIR, DEFAULT_MANIFEST


@pytest.fixture(scope="module")
def tiny_library(tmp_path_factory):
    """Two training and one held-out clip per behaviour of the sample library: its FBX files and their
    manifest entries, in a folder of their own (so they are imported afresh); the manifest's path."""
    folder = tmp_path_factory.mktemp("clips")
    entries = json.loads(DEFAULT_MANIFEST.read_text())["clips"]
    chosen = [e for behaviour in ("POINT", "WAVE") for split, count in (("train", 2), ("test", 1))
              for e in [f for f in entries if f["behaviour"] == behaviour and f["split"] == split][:count]]
    for entry in chosen:
        shutil.copyfile(CLIP_DIR / entry["file"], folder / entry["file"])
    (folder / "manifest.json").write_text(json.dumps({"fps": 30, "clips": chosen}))
    return folder / "manifest.json"
