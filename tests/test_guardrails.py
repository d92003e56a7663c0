"""The package's size rules (issue 37; COMMON standards): no module over 600 lines, and no
function over 80 lines without a comment saying why.

The reason is a comment starting ``# long:`` in the comment block right above the
function's ``def`` (or its decorators). Run this file with ``-s`` to see every long
function and its reason; a long function without one fails the test by name.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "eyeviz"
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80
MARK = "# long:"


def _reason(lines: list[str], node: ast.FunctionDef | ast.AsyncFunctionDef) -> str | None:
    """The ``# long:`` comment in the comment block directly above ``node``, or None."""
    top = min([node.lineno, *(d.lineno for d in node.decorator_list)])
    i = top - 2  # 0-based index of the line above
    block: list[str] = []
    while i >= 0 and lines[i].strip().startswith("#"):
        block.insert(0, lines[i].strip())
        i -= 1
    for k, line in enumerate(block):
        if line.startswith(MARK):
            rest = [line[len(MARK) :].strip()] + [b.lstrip("# ") for b in block[k + 1 :]]
            return " ".join(rest).strip() or None
    return None


def long_functions(root: Path = PACKAGE) -> list[tuple[str, int, str | None]]:
    """(``path:line name``, length, reason or None) of every function over the limit."""
    out = []
    for path in sorted(root.rglob("*.py")):
        src = path.read_text()
        lines = src.splitlines()
        for node in ast.walk(ast.parse(src)):
            if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            assert node.end_lineno is not None
            n = node.end_lineno - node.lineno + 1
            if n > MAX_FUNCTION_LINES:
                where = f"{path.relative_to(root.parent)}:{node.lineno} {node.name}"
                out.append((where, n, _reason(lines, node)))
    return out


def test_no_function_over_80_lines_without_a_reason():
    found = long_functions()
    for where, n, why in sorted(found, key=lambda t: -t[1]):
        print(f"{n:4d}  {where}: {why}")
    bare = [f"{where} ({n} lines)" for where, n, why in found if not why]
    assert not bare, "over 80 lines with no '# long: why' comment above: " + ", ".join(bare)


def test_no_module_over_600_lines():
    big = {
        str(p.relative_to(PACKAGE.parent)): n
        for p in sorted(PACKAGE.rglob("*.py"))
        if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES
    }
    assert not big, big


def test_the_check_finds_a_long_function_and_reads_its_reason(tmp_path):
    body = "".join(f"    x{k} = {k}\n" for k in range(85))
    (tmp_path / "m.py").write_text(
        "def short():\n    return 1\n\n\n"
        f"def bare():\n{body}\n\n"
        "# a comment\n# long: one table of cases, read top to bottom\n@staticmethod\n"
        f"def explained():\n{body}\n\n"
        "# long:\n"
        f"def empty_reason():\n{body}"
    )
    got = {w.split()[-1]: (n, why) for w, n, why in long_functions(tmp_path)}
    assert got == {
        "bare": (86, None),
        "explained": (86, "one table of cases, read top to bottom"),
        "empty_reason": (86, None),
    }


#: Files where 720 (or the pair 40, 20) is another quantity than the paper's design.
PAPER_NUMBER_ELSEWHERE = {
    "eyeviz/app/window.py": "the window's first size, 1280 x 720 pixels",
    "eyeviz/estimators/paper/nets.py": "the first dense layer's 720 units (Appendix A/B)",
    "eyeviz/reference/legacy_fastpath.py": "a frozen copy of the old fast path, kept verbatim",
}


def paper_numbers(root: Path = PACKAGE) -> list[str]:
    """``path:line`` of every 720 and every ``40, 20`` pair in code (not in strings or
    comments) outside ``core/paper.py``."""
    import io
    import tokenize

    skip = {tokenize.NL, tokenize.COMMENT, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT}
    out = []
    for path in sorted(root.rglob("*.py")):
        rel = str(path.relative_to(root.parent))
        if rel == "eyeviz/core/paper.py":
            continue
        toks = [
            t
            for t in tokenize.generate_tokens(io.StringIO(path.read_text()).readline)
            if t.type not in skip
        ]
        nums = {
            k: float(t.string.replace("_", ""))
            for k, t in enumerate(toks)
            if t.type == tokenize.NUMBER
            and t.string[:2].lower() not in ("0x", "0o", "0b")
            and not t.string.endswith(("j", "J"))
        }
        for k, v in nums.items():
            pair = v == 40 and toks[k + 1].string == "," and nums.get(k + 2) == 20
            if v == 720 or pair:
                out.append(f"{rel}:{toks[k].start[0]}")
    return out


def test_the_papers_numbers_are_written_in_core_paper_only():
    found = paper_numbers()
    stray = [w for w in found if w.split(":")[0] not in PAPER_NUMBER_ELSEWHERE]
    assert not stray, "the paper's numbers written outside eyeviz/core/paper.py: " + str(stray)
    # the check sees them: each allowed file still holds its other 720
    assert {w.split(":")[0] for w in found} == set(PAPER_NUMBER_ELSEWHERE)


def test_the_paper_number_check_finds_the_design_in_code_only(tmp_path):
    pkg = tmp_path / "eyeviz"
    (pkg / "core").mkdir(parents=True)
    (pkg / "core" / "paper.py").write_text("H, L, M = 40.0, 20.0, 720\n")
    (pkg / "a.py").write_text(
        '"""m = 720, h = 40, l = 20"""\n'  # prose: fine
        "x = 720  # a stray m\n"
        "y = f(40.0, 20.0, 8)\n"
        "z = (40, 21)  # another pair\n"
    )
    assert paper_numbers(pkg) == ["eyeviz/a.py:2", "eyeviz/a.py:3"]
