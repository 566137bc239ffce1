"""The docs as a manual: every relative link and every docs/ path they name exists, and the pages under docs/
(outside docs/history/) carry no dated log."""
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MANUAL = sorted((ROOT / "docs").glob("*.md"))  # the manual's pages; docs/history/ holds the dated notes
READMES = [ROOT / "README.md", ROOT / "trainer" / "README.md", ROOT / "rlanimate_addon" / "README.md",
           ROOT / "sample_rigs" / "README.md"]
LINKED = [*READMES, *MANUAL, *sorted((ROOT / "docs" / "history").glob("*.md"))]

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")  # [text](target) and ![alt](target)
DOCS_PATH = re.compile(r"\bdocs/[\w./{},-]*[\w}]")  # docs/results/table4.{json,md}, docs/TRAINING.md
BRACES = re.compile(r"\{([^{}]*)\}")

# What a journal says and a manual does not. Each marker is narrow enough that a reference page's present
# tense ("Known limits", "before, through and after the gesture", "stop the run") does not match it.
DATED_LOG = {
    "an issue number": re.compile(r"\bissues? #?\d+", re.IGNORECASE),
    "a turn ago": re.compile(r"\bturns? ago\b", re.IGNORECASE),
    "a stop of a journey": re.compile(r"\b(?:first|second|third|fourth|fifth|sixth|next|last) stop\b|\bstop by stop\b",
                                      re.IGNORECASE),
    "what we tried": re.compile(r"\bwe (?:tried|first|then)\b", re.IGNORECASE),
    "until now": re.compile(r"\buntil now\b", re.IGNORECASE),
    "this work or change": re.compile(r"\b(?:before|after) this (?:work|change|round)\b|\bthis work\b", re.IGNORECASE),
    "a fix since made": re.compile(r"\bsince fixed\b|\bof (?:its|their) day\b|\bat the time\b|\bwas then\b",
                                   re.IGNORECASE),
    "what it used to do": re.compile(r"\b(?:it|they|we) used to\b|\bused to (?:be|fail|give|miss|keep|train|rest)\b",
                                     re.IGNORECASE),
    "a sentence opening 'Before,'": re.compile(r"(?:^|[.(]\s*)Before, "),
}


def _expanded(path: str) -> list[str]:
    """docs/a.{json,md} -> [docs/a.json, docs/a.md]."""
    match = BRACES.search(path)
    if not match:
        return [path]
    return [p for choice in match.group(1).split(",")
            for p in _expanded(path[:match.start()] + choice + path[match.end():])]


def _relative_links(page: Path) -> list[str]:
    """The page's links that point into the repository (no URL, no in-page anchor), without their anchors."""
    targets = (m.group(1) for m in LINK.finditer(page.read_text(encoding="utf-8")))
    return [t.split("#")[0] for t in targets if not re.match(r"[a-z]+:|#", t)]


@pytest.mark.parametrize("page", LINKED, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_resolves(page):
    missing = [t for t in _relative_links(page) if not (page.parent / t).exists()]
    assert not missing, f"{page.relative_to(ROOT)} links to what does not exist: {missing}"


@pytest.mark.parametrize("page", READMES + MANUAL, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_docs_path_named_exists(page):
    named = {p for m in DOCS_PATH.finditer(page.read_text(encoding="utf-8")) for p in _expanded(m.group(0))}
    missing = sorted(p for p in named if not (ROOT / p.rstrip(".,")).exists())
    assert not missing, f"{page.relative_to(ROOT)} names docs paths that do not exist: {missing}"


@pytest.mark.parametrize("page", MANUAL, ids=lambda p: p.name)
def test_the_manual_has_no_dated_log(page):
    text = page.read_text(encoding="utf-8")
    found = [f"line {text.count(chr(10), 0, m.start()) + 1}: {what} ({m.group(0).strip()!r})"
             for what, marker in DATED_LOG.items() for m in marker.finditer(text)]
    assert not found, f"{page.name} reads as a journal (move it to docs/history/): " + "; ".join(found)


def _layout_table() -> str:
    """The README's "Layout" section."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    return readme[readme.index("## Layout"):].split("\n## ", 1)[0]


def test_the_readme_layout_names_every_top_level_path():
    tracked = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if tracked.returncode != 0:
        pytest.skip(f"not a git checkout ({tracked.stderr.strip()}): the tracked paths are unknown")
    top = {line.split("/")[0] for line in tracked.stdout.splitlines()} - {"README.md", ".gitignore"}
    layout = _layout_table()
    missing = sorted(name for name in top if f"`{name}" not in layout)
    assert not missing, f"README.md's layout table leaves out {missing}"


def test_the_trainer_readme_names_every_module():
    listed = (ROOT / "trainer" / "README.md").read_text(encoding="utf-8")
    modules = [f.relative_to(ROOT / "trainer").as_posix() for f in sorted((ROOT / "trainer").rglob("*.py"))
               if f.name != "__init__.py"]
    missing = [m for m in modules if f"`{m}`" not in listed]
    assert not missing, f"trainer/README.md does not list {missing}"


def test_the_markers_catch_a_journal_and_pass_a_manual():
    """Each marker finds the journal sentence it is for, and none fires on a reference page's own phrasing."""
    journal = ["issue 26, after the fourth stop", "as a turn ago", "we tried 200 epochs", "shipped until now",
               "the trainer before this work", "a bug since fixed on main", "it used to fail the bake check",
               "the list. Before, it crashed"]
    manual = ["## Known limits", "standing before, through and after the gesture", "stop the run with Ctrl-C",
              "the influence they had before its fade", "time-scaled from the agent's 116-frame gesture",
              "The bake check plays 3 frames", "the history of its issues lives in docs/history/"]
    for sentence in journal:
        assert any(m.search(sentence) for m in DATED_LOG.values()), sentence
    for sentence in manual:
        assert not any(m.search(sentence) for m in DATED_LOG.values()), sentence
