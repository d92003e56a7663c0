"""scripts/kind_touches.py (docs/extending.md's count of the places that name an eye
model) on a tiny package of its own: which comparisons and imports it counts."""

from __future__ import annotations

import importlib.util
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "kind_touches.py"

SOURCE = """from eyeviz.core.domain import Domain3D, domain_for
from eyeviz.core.geometry import EyePair


def f(d, x):
    if d.kind == "measured":
        return 1
    if "planar" != x or x in ("spherical", "other"):
        return 2
    if x == "healpix2" or x < "planar" or x == y:
        return 3
    return "measured"
"""


def test_it_counts_kind_comparisons_and_the_imports_by_name(tmp_path):
    spec = importlib.util.spec_from_file_location("kind_touches_script", SCRIPT)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    (tmp_path / "eyeviz" / "sub").mkdir(parents=True)
    (tmp_path / "eyeviz" / "sub" / "a.py").write_text(SOURCE)
    (tmp_path / "eyeviz" / "b.py").write_text("from eyeviz.core import domain\nx = 'planar'\n")
    per_file, lines, eye_pair, domain3d = mod.count(tmp_path)
    assert dict(per_file) == {"eyeviz/sub/a.py": 3}
    assert [ln.split(": ", 1)[0] for ln in lines] == [
        "eyeviz/sub/a.py:6", "eyeviz/sub/a.py:8", "eyeviz/sub/a.py:8"]  # fmt: skip
    assert eye_pair == domain3d == {"eyeviz/sub/a.py"}
