"""scripts/mutation.py (docs/mutation.md) on a tiny package of its own: the mutants it
makes, kills and a survivor reported, the copy restored byte for byte, this checkout refused."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "mutation.py"


def _load():
    spec = importlib.util.spec_from_file_location("mutation_script", SCRIPT)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up there
    spec.loader.exec_module(mod)
    return mod


SOURCE = '''"""Docstring with a < b and 1 + 2."""


def f(a, /, b, *, c=1):
    if a < b and not c:
        return -a + 2
    return a in (b, "x < y")  # a comment: x == y
'''


def test_mutants_are_single_tokens_of_code_that_compile():
    mut = _load()
    got = {(m.line, m.old, m.new) for m in mut.mutants_of("f.py", SOURCE)}
    assert got == {
        (4, "1", "2"),
        (5, "<", "<="),
        (5, "and", "or"),
        (5, "not ", ""),
        (6, "-", ""),
        (6, "+", "-"),
        (6, "2", "3"),
        (7, "in", "not in"),
    }
    for m in mut.mutants_of("f.py", SOURCE):
        compile(m.apply(SOURCE), "f.py", "exec")


@pytest.mark.slow
def test_a_tiny_run_reports_a_kill_and_restores_the_copy(tmp_path, capsys):
    mut = _load()
    (tmp_path / "tinypkg" / "sub").mkdir(parents=True)
    (tmp_path / "tinypkg" / "__init__.py").write_text("")
    (tmp_path / "tinypkg" / "sub" / "__init__.py").write_text("")
    tiny = tmp_path / "tinypkg" / "sub" / "tiny.py"
    tiny.write_text("def inc(x):\n    return x + 1\n\n\ndef untested():\n    return 5\n")
    (tmp_path / "tests" / "sub").mkdir(parents=True)
    (tmp_path / "tests" / "sub" / "test_tiny.py").write_text(
        "from tinypkg.sub.tiny import inc\n\n\ndef test_inc():\n    assert inc(1) == 2\n"
    )
    before = tiny.read_bytes()
    out = tmp_path / "out.json"
    args = ["--root", str(tmp_path), "--packages", "tinypkg/sub", "--tests", "tests/sub"]
    assert mut.main([*args, "--per-module", "5", "--json", str(out)]) == 0
    res = json.loads(out.read_text())["results"]
    assert sorted((r["old"], r["new"], r["status"]) for r in res) == [
        ("+", "-", "killed"),
        ("1", "2", "killed"),
        ("5", "6", "survived"),
    ]
    text = capsys.readouterr().out
    assert "kill rate 2/3 = 66.7 %" in text and "SURVIVED tinypkg/sub/tiny.py:6:" in text
    assert tiny.read_bytes() == before


def test_it_refuses_to_mutate_its_own_checkout():
    mut = _load()
    with pytest.raises(SystemExit, match="mutate a copy"):
        mut.main(["--root", str(SCRIPT.parents[1]), "--per-module", "1"])


def test_the_frames_modules_also_run_the_render_tests(tmp_path):
    """The frame's drawing data is read by the painters: tests/render runs after the
    package's mirror for the modules EXTRA_TESTS names (when the copy has it), only those."""
    mut = _load()
    for d in ("eyeviz/model", "tests/model", "tests/render"):
        (tmp_path / d).mkdir(parents=True)
    (tmp_path / "tests/model/test_frame.py").write_text("")
    frame, scene = tmp_path / "eyeviz/model/frame.py", tmp_path / "eyeviz/model/scene.py"
    assert mut.tests_for(tmp_path, frame, "tests/model") == [
        "tests/model/test_frame.py",
        "tests/model",
        "tests/render",
    ]
    assert mut.tests_for(tmp_path, scene, "tests/model") == ["tests/model"]
    (tmp_path / "tests/render").rmdir()
    assert mut.tests_for(tmp_path, frame, "tests/model") == [
        "tests/model/test_frame.py",
        "tests/model",
    ]


def test_the_spherical_set_names_modules_and_tests_that_exist(capsys):
    """--spherical: every module and test file of SPHERICAL is in this checkout (a rename
    would silently drop it from the run), and --list counts the draws without running."""
    mut = _load()
    root = SCRIPT.parents[1]
    for module, tests in mut.SPHERICAL.items():
        assert (root / module).is_file(), module
        files = [t.split("::")[0] for t in tests]  # a test file, or one test in it
        assert tests and all((root / f).is_file() for f in files), (module, tests)
    args = ["--root", str(root), "--spherical", "--list", "--per-module", "2"]
    assert mut.main([*args, "--modules", "measured_grid", "measured_from"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("eyeviz/core/measured_from.py: 2 of ")
    assert out[1].startswith("eyeviz/core/measured_grid.py: 2 of ")
    assert out[-1].startswith("4 mutants of ") and out[-1].endswith(" would run")
