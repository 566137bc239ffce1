"""trainer/'s folders import downwards only: a folder imports from its own layer's folder and the layers
below it, never from a folder above it (agent/, motion/ and blender_io/ import nothing from evaluation/,
reporting/, experiments/ or scripts/). Every import statement counts, those inside functions too."""
import ast
from pathlib import Path

TRAINER = Path(__file__).resolve().parents[2] / "trainer"

#: The trainer's folders, lowest first. Top-level modules (paths.py, files.py) sit below them all; the
#: folders of one layer do not import each other.
LAYERS = (("motion",), ("agent", "blender_io"), ("evaluation", "reporting"), ("experiments",), ("scripts",))
RANK = {folder: rank for rank, folders in enumerate(LAYERS) for folder in folders}


def _trainer_imports(path):
    """The trainer folders (or None for a top-level module) that the file at `path` imports from."""
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        names = ([alias.name for alias in node.names] if isinstance(node, ast.Import)
                 else [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module else [])
        for name in names:
            parts = name.split(".")
            if parts[0] == "trainer" and len(parts) > 1:
                yield node.lineno, parts[1] if parts[1] in RANK else None


def test_every_trainer_folder_is_in_a_layer():
    folders = {p.name for p in TRAINER.iterdir() if p.is_dir() and (p / "__init__.py").is_file()}
    assert folders == set(RANK)


def test_no_module_imports_from_a_folder_above_it_or_beside_it():
    upward = []
    for path in sorted(TRAINER.rglob("*.py")):
        folder = path.relative_to(TRAINER).parts[0]
        if folder not in RANK:
            continue  # train.py, paths.py, files.py
        for line, imported in _trainer_imports(path):
            if imported is not None and imported != folder and RANK[imported] >= RANK[folder]:
                upward.append(f"{path.relative_to(TRAINER.parent)}:{line} imports trainer.{imported}")
    assert not upward, "\n".join(upward)


def test_the_check_sees_an_upward_import(tmp_path):
    module = tmp_path / "run.py"
    module.write_text("def f():\n    from trainer.evaluation.scoring import score_motions\n")
    assert list(_trainer_imports(module)) == [(2, "evaluation")]
