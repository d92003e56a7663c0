"""The docs in the repository: every file the code cites exists, and the >>> snippets run.

Doctests run from the docs pages (docs/*.md, README.md) and from every module of the
package whose docstrings hold a ``>>>`` example (the Qt app's modules have none).
"""

from __future__ import annotations

import doctest
import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CODE = [
    p
    for top in ("eyeviz", "scripts", "tests", "examples")
    for p in sorted((ROOT / top).rglob("*"))
    if p.suffix in {".py", ".sh", ".toml"} and p.is_file()
]
DOC_REF = re.compile(r"\bdocs/[\w./-]+\.(?:md|png|svg|csv|json)\b")
PAGES = sorted((ROOT / "docs").glob("*.md"))
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _modules_with_examples() -> list[str]:
    out = []
    for p in sorted((ROOT / "eyeviz").rglob("*.py")):
        if "/app/" in p.as_posix() or ">>>" not in p.read_text(encoding="utf-8"):
            continue
        rel = p.relative_to(ROOT).with_suffix("")
        parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
        out.append(".".join(parts))
    return out


def test_the_docs_exist():
    names = {p.name for p in PAGES}
    assert {"architecture.md", "extending.md", "conventions.md", "contract.md"} <= names


def test_no_code_cites_a_missing_file():
    missing = []
    for p in CODE + [ROOT / "README.md"]:
        text = p.read_text(encoding="utf-8", errors="replace")
        for ref in DOC_REF.findall(text):
            if not (ROOT / ref).exists():
                missing.append(f"{p.relative_to(ROOT)}: {ref}")
    assert not missing, "cited but not in the repository:\n" + "\n".join(missing)


#: A citation of the guidance or the paper's text kept outside the repository (issue 35.12:
#: the package's docstring cited ``shared/paper.md``); the docs stand alone.
ALL_MD = [ROOT / "README.md"] + [
    p
    for top in ("docs", "eyeviz", "examples", "scripts")
    for p in sorted((ROOT / top).rglob("*.md"))
]
OUTSIDE = re.compile(r"DESIGN\.md|\bshared/|paper\.md")


def test_no_code_or_doc_cites_a_file_outside_the_repository():
    bad = [
        str(p.relative_to(ROOT))
        for p in CODE + ALL_MD
        if p.name != "test_docs.py"
        and OUTSIDE.search(p.read_text(encoding="utf-8", errors="replace"))
    ]
    assert not bad, f"these cite a file that is not in the repository: {bad}"


@pytest.mark.parametrize("page", PAGES + [ROOT / "README.md"], ids=lambda p: p.name)
def test_doc_page_snippets_run(page):
    res = doctest.testfile(str(page), module_relative=False, optionflags=FLAGS, verbose=False)
    assert res.failed == 0, f"{res.failed} of {res.attempted} examples failed in {page.name}"


@pytest.mark.parametrize("name", _modules_with_examples())
def test_module_docstring_examples_run(name):
    mod = importlib.import_module(name)
    res = doctest.testmod(mod, optionflags=FLAGS, verbose=False)
    assert res.attempted > 0 and res.failed == 0, f"{res.failed} of {res.attempted} failed"
