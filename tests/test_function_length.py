"""No function of the project is over 60 lines (def line to last line, nested functions and methods each
counted on their own): the extension, the trainer, the sample-rig builder and the top-level package.
tests/ and benchmarks/ (a benchmark's main may be a long script) are left out."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The folders checked, and the top-level modules beside them.
CHECKED = ("rlanimate_addon", "trainer", "sample_rigs", "scripts")
LIMIT = 60


def long_functions(path: Path, limit: int = LIMIT) -> list[tuple[str, int, int]]:
    """[(name, first line, lines)] of the functions in the file at `path` longer than `limit` lines."""
    tree = ast.parse(path.read_text(), str(path))
    return [(node.name, node.lineno, node.end_lineno - node.lineno + 1) for node in ast.walk(tree)
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            and node.end_lineno is not None and node.end_lineno - node.lineno + 1 > limit]


def _checked_files() -> list[Path]:
    return sorted(ROOT.glob("*.py")) + [path for folder in CHECKED for path in sorted((ROOT / folder).rglob("*.py"))]


def test_no_function_outside_tests_and_benchmarks_is_over_60_lines():
    files = _checked_files()
    assert any(path.name == "runtime.py" for path in files) and len(files) > 100  # the tree was found
    offenders = [f"{path.relative_to(ROOT)}:{line} {name} ({lines} lines)" for path in files
                 for name, line, lines in long_functions(path)]
    assert not offenders, f"Functions over {LIMIT} lines (split them by stage):\n" + "\n".join(offenders)


def test_the_check_counts_a_function_from_its_def_to_its_last_line(tmp_path):
    module = tmp_path / "long.py"
    body = "\n".join(f"x{k} = {k}" for k in range(LIMIT - 1))
    fits, method = body.replace("x", "    x"), body.replace("x", "        x")
    module.write_text(f"def fits():\n{fits}\n\n\nclass A:\n    def method(self):\n{method}\n        return x0\n")
    assert long_functions(module) == [("method", LIMIT + 4, LIMIT + 1)]  # `fits`, of 60 lines, fits
