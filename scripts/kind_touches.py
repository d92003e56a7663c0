"""Where the package names an eye model instead of asking it (issue 37): the places a new
model would have to look at.

Counts, over eyeviz/**/*.py:

1. comparisons (``==``, ``!=``, ``in``, ``not in``) against the kind strings "planar",
   "spherical", "healpix", "measured" (found with ``ast``: a literal, or a tuple, list or
   set holding one, on either side);
2. the modules that import ``EyePair`` (the planar eyes' class) by name;
3. the modules that import ``Domain3D`` by name;

and the union of the files of all three. ``-v`` lists each comparison and module.

    .venv/bin/python scripts/kind_touches.py [-v]
"""

from __future__ import annotations

import argparse
import ast
from collections import Counter
from pathlib import Path

KINDS = {"planar", "spherical", "healpix", "measured"}
ROOT = Path(__file__).resolve().parents[1]


def _kind_literals(node: ast.expr) -> list[ast.Constant]:
    if isinstance(node, ast.Constant) and node.value in KINDS:
        return [node]
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return [e for e in node.elts if isinstance(e, ast.Constant) and e.value in KINDS]
    return []


def _names_a_kind(node: ast.Compare) -> bool:
    ops = (ast.Eq, ast.NotEq, ast.In, ast.NotIn)
    if not any(isinstance(op, ops) for op in node.ops):
        return False
    return any(_kind_literals(x) for x in (node.left, *node.comparators))


def count(root: Path = ROOT) -> tuple[Counter[str], list[str], set[str], set[str]]:
    """(comparisons per file, their lines, files importing EyePair, files importing
    Domain3D), paths relative to ``root``."""
    per_file: Counter[str] = Counter()
    lines: list[str] = []
    eye_pair: set[str] = set()
    domain3d: set[str] = set()
    for p in sorted((root / "eyeviz").rglob("*.py")):
        rel = p.relative_to(root).as_posix()
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Compare) and _names_a_kind(node):
                per_file[rel] += 1
                lines.append(f"{rel}:{node.lineno}: {ast.unparse(node)}")
            elif isinstance(node, ast.ImportFrom):
                names = {a.name for a in node.names}
                if "EyePair" in names:
                    eye_pair.add(rel)
                if "Domain3D" in names:
                    domain3d.add(rel)
    return per_file, lines, eye_pair, domain3d


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-v", action="store_true", help="list each comparison and module")
    verbose = ap.parse_args().v
    per_file, lines, eye_pair, domain3d = count()
    if verbose:
        print("\n".join(sorted(lines)))
        print("EyePair:", ", ".join(sorted(eye_pair)))
        print("Domain3D:", ", ".join(sorted(domain3d)))
    print(f"kind comparisons: {sum(per_file.values())} in {len(per_file)} files")
    print(f"modules importing EyePair: {len(eye_pair)}")
    print(f"modules importing Domain3D: {len(domain3d)}")
    print(f"files touched by any of them: {len(set(per_file) | eye_pair | domain3d)}")


if __name__ == "__main__":
    main()
