"""Where the trainer reads and writes: every repository path it uses, in one place."""
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
SAMPLE_RIG_BLEND = REPO_ROOT / "sample_rigs" / "character.blend"
SAMPLE_RIG_FBX = REPO_ROOT / "sample_rigs" / "character.fbx"
CLIP_DIR = REPO_ROOT / "sample_rigs" / "clips"
DEFAULT_MANIFEST = CLIP_DIR / "manifest.json"
DEFAULT_OUTPUT = REPO_ROOT / "runs" / "default"
INSTALLED_AGENT = REPO_ROOT / "rlanimate_addon" / "agents" / "default.npz"
RESULTS_DIR = REPO_ROOT / "docs" / "results"
CONTACT_SHEET = REPO_ROOT / "docs" / "contact_sheet.png"
#: Real motion capture, read in place beside the repository (CC BY-NC: never copied into it).
REALMOCAP_DIR = REPO_ROOT.parent / "shared" / "realmocap"
REALMOCAP_RUNS = REPO_ROOT / "runs" / "realmocap"


def seed_folder(root, seed):
    """`root` for seed 0, its sibling <root>_seed<N> for another seed, so that no seed reuses another's runs."""
    root = Path(root)
    return root if seed == 0 else root.with_name(f"{root.name}_seed{seed}")


def shown(path):
    """`path` relative to the repository when inside it, so docs and reports name no machine paths."""
    path = Path(path).resolve()
    return path.relative_to(REPO_ROOT) if path.is_relative_to(REPO_ROOT) else path
