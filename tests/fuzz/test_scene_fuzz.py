"""Scene TOML: mutated and generated documents load to a Scene that round-trips, or raise
one SceneError line naming the file."""

from __future__ import annotations

import math

from hypothesis import given
from hypothesis import strategies as st

from eyeviz.core.bounds import MAX_M
from eyeviz.model import scene as S

from .conftest import assert_one_line, count, fuzz_settings

BASE = """title = "fuzz"

[eyes]
h = 40.0
l = 20.0
m = 720

[[features]]
name = "a"
x = 0.0
y = 1500.0
g = 50.0
color = "#D55E00"

[layers]
show = ["eyes", "bfv", "features", "ambiguity"]

[predictions]
estimators = ["compact"]

[view]
center = [0.0, 1500.0]
width = 4000.0
"""

HOSTILE_VALUES = [
    "0", "-1", "2000000000", "9223372036854775807", "1" + "0" * 400, "-" + "9" * 5000,
    "1e308", "-1e308", "5e-324", "inf", "nan", "-0.0", "1e-300", "true", '""',
    '"a\\nb"', '"a\\u0000b"', '"$\\\\undefined$"', '"' + "x" * 300 + '"', "[]",
    "[1, 2, 3]", "[[[[[[1]]]]]]", "{a = 1}", '"#12345g"', "2026-01-01", "[" * 200 + "]" * 200,
    "0x7fffffffffffffff", '"\\u2028"', "1_000", '"eyes"',
]  # fmt: skip


@st.composite
def mutated_scene(draw):
    lines = BASE.splitlines()
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["value", "value", "delete", "dup", "junk", "header"]))
        if op == "value" and "=" in lines[i]:
            key = lines[i].split("=")[0]
            lines[i] = key + "= " + draw(st.sampled_from(HOSTILE_VALUES))
        elif op == "delete":
            del lines[i]
            if not lines:
                lines = [""]
        elif op == "dup":
            lines.insert(i, lines[i])
        elif op == "junk":
            lines.insert(i, draw(st.text(max_size=30)))
        else:
            lines.insert(i, draw(st.sampled_from(["[eyes]", "[[features]]", "[view]", "[x]"])))
    return "\n".join(lines)


def _check(text: str, category: str) -> None:
    try:
        sc = S.loads(text, "fuzz.toml")
    except S.SceneError as exc:
        assert_one_line(str(exc))
        assert str(exc).startswith("fuzz.toml")
        count(category, "refused")
        return
    # a correct result: every rule holds and it round-trips
    assert 4 <= sc.eyes.m <= MAX_M and sc.eyes.m % 2 == 0 and type(sc.eyes.m) is int
    for f in sc.features:
        assert all(math.isfinite(v) and abs(v) <= S.MAX_SCENE_COORD for v in (f.x, f.y, f.g))
        assert f.g > 0 and S._bad_text(f.name) is None
    assert sc.view.width >= S.MIN_VIEW_WIDTH
    assert S.loads(S.dumps(sc)) == sc
    count(category, "ok")


@fuzz_settings(300)
@given(mutated_scene())
def test_mutated_scene_text(text):
    _check(text, "scene: mutated TOML")


@fuzz_settings(150)
@given(st.text(max_size=400))
def test_arbitrary_text(text):
    _check(text, "scene: arbitrary text")


@fuzz_settings(40)
@given(st.integers(1, 5000), st.sampled_from(["[", "{a = "]))
def test_deep_nesting(depth, opener):
    closer = "]" if opener == "[" else "}"
    _check("a = " + opener * depth + "1" + closer * depth, "scene: deep nesting")


@fuzz_settings(60)
@given(mutated_scene())
def test_scene_files_through_load(tmp_path_factory, text):
    p = tmp_path_factory.mktemp("s") / "s.toml"
    p.write_text(text, encoding="utf-8", errors="surrogatepass")
    before = p.read_bytes()
    try:
        sc = S.load(p)
    except S.SceneError as exc:
        assert_one_line(str(exc))
        count("scene: files (load/save)", "refused")
    else:
        out = p.with_name("out.toml")
        S.save(sc, out)
        assert S.load(out) == sc
        count("scene: files (load/save)", "ok")
    assert p.read_bytes() == before
