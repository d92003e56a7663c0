"""The CLI on fuzzed inputs: `snapshot` on mutated scenes, `report dataset` on mutated
data sets. Property: exit 0 with the output written, or exit 2 with one line and no
output; the input unchanged; never a traceback. Outcomes are recorded and
`test_no_cli_bugs` fails while any bug was seen, showing the first scene of each kind."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from eyeviz.cli import main

from .conftest import count, digest, fuzz_settings
from .test_dataset_fuzz import CSV_PAPER, NPZ_PAPER, mutated
from .test_scene_fuzz import mutated_scene

# test_no_*_bugs reads what this module's other tests recorded in BUGS: under
# pytest-xdist (--dist loadgroup) the whole module runs on one worker, in order
pytestmark = pytest.mark.xdist_group("fuzz_cli")
BUGS: dict[str, int] = {}
HANG_S = 120.0  # a snapshot subprocess still running after this is recorded as a hang
ROOT = Path(__file__).resolve().parents[2]


def _cli(argv) -> tuple[int, str]:
    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        code = main(argv)
    return code, err.getvalue()


EXAMPLES: dict[str, str] = {}


def _record(
    category: str, code: int, err: str, output_exists: bool, example: str = "", hung=False
) -> None:
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    if hung:
        what = f"hangs (still running after {HANG_S:.0f} s)"
    elif code == 0 and output_exists:
        count(category, "ok")
        return
    elif code == 2 and len(lines) == 1 and "unexpected " not in lines[0] and not output_exists:
        count(category, "refused")
        return
    else:
        what = lines[-1][:80] if lines else f"exit {code}"
        if "unexpected " in what:
            what = what.split("unexpected ")[1].split(":")[0]
    count(category, f"bug: {what}")
    BUGS[f"{category}: {what}"] = BUGS.get(f"{category}: {what}", 0) + 1
    if example:
        EXAMPLES.setdefault(f"{category}: {what}", f"{example}\n--- stderr:\n{err[-3000:]}")


@pytest.mark.slow
@fuzz_settings(25)
@given(mutated_scene())
def test_snapshot_mutated_scene(tmp_path_factory, text):
    d = tmp_path_factory.mktemp("snap")
    p = d / "s.toml"
    p.write_text(text, encoding="utf-8", errors="surrogatepass")
    before = digest(p)
    out = d / "o.svg"
    code, err = _cli(["snapshot", str(p), "-o", str(out)])
    assert digest(p) == before
    _record("cli: snapshot scene", code, err, out.exists(), text)


COORD = st.one_of(
    st.floats(-1e4, 1e4),
    st.sampled_from([0.0, 1e-300, -1e-300, 1e12, -1e12, 123456789.125, 5e-324]),
)
NAMES = st.one_of(
    st.text(
        st.characters(blacklist_categories=("Cc", "Cs", "Zl", "Zp")), min_size=1, max_size=12
    ).filter(lambda t: t.strip()),
    st.sampled_from(["$\\undefined$", "$x^$", "a_b^c", "%s %d {}", "<svg>&amp;", "n" * 200]),
)


@st.composite
def extreme_scene(draw):
    """Valid scenes at the edges of the bounds: what the renderer must draw or refuse."""
    m = draw(st.sampled_from([4, 6, 72, 720, 5000]))
    n = draw(st.integers(0, 6))
    names = draw(st.lists(NAMES, min_size=n, max_size=n, unique=True))
    feats = []
    for name in names:
        x, y = draw(COORD), draw(COORD)
        g = draw(st.sampled_from([1e-6, 0.5, 50.0, 1e6, 1e12]))
        esc = name.replace("\\", "\\\\").replace('"', '\\"')
        feats.append(f'[[features]]\nname = "{esc}"\nx = {x!r}\ny = {y!r}\ng = {g!r}\n')
    width = draw(st.sampled_from([1e-6, 1.0, 8000.0, 1e12]))
    cx, cy = draw(COORD), draw(COORD)
    layers = draw(
        st.lists(
            st.sampled_from(["eyes", "bfv", "features", "bitmaps", "readout", "labels",
                             "tangents", "sectors", "ambiguity"]),
            unique=True,
        )
    )  # fmt: skip
    return (
        f"[eyes]\nm = {m}\n"
        + "".join(feats)
        + "[layers]\nshow = ["
        + ", ".join(f'"{x}"' for x in layers)
        + f"]\n[view]\ncenter = [{cx!r}, {cy!r}]\nwidth = {width!r}\n"
    )


@pytest.mark.slow
@fuzz_settings(8)
@given(extreme_scene())
def test_snapshot_extreme_valid_scene(tmp_path_factory, text):
    """In a subprocess with a time limit: a renderer that hangs (Agg on huge coordinates)
    is recorded as a bug instead of hanging the suite; a fresh process also keeps the
    state other tests leave (Qt, matplotlib backends) out of it."""
    d = tmp_path_factory.mktemp("snapx")
    p = d / "s.toml"
    p.write_text(text, encoding="utf-8", errors="surrogatepass")
    out = d / "o.png"
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "eyeviz", "snapshot", str(p), "-o", str(out)],
            env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"},
            capture_output=True,
            text=True,
            timeout=HANG_S,
        )
        code, err, hung = proc.returncode, proc.stderr, False
    except subprocess.TimeoutExpired:
        code, err, hung = -1, "", True
    _record("cli: snapshot extreme scene", code, err, out.exists(), text, hung=hung)


@pytest.mark.parametrize("fmt", ["csv", "npz"])
@fuzz_settings(6)
@given(data=st.data())
def test_report_dataset(tmp_path_factory, fmt, data):
    src = CSV_PAPER if fmt == "csv" else NPZ_PAPER
    blob = data.draw(mutated(src, region=(0.5, 1.0) if fmt == "csv" else (0.0, 1.0)))
    d = tmp_path_factory.mktemp("rep")
    p = d / f"d.{fmt}"
    p.write_bytes(blob)
    before = digest(p)
    out = d / "report"
    code, err = _cli(["report", "dataset", str(p), "-o", str(out)])
    assert digest(p) == before
    _record(f"cli: report dataset {fmt}", code, err, out.exists())


def test_no_cli_bugs():
    shown = "".join(f"\n=== {k}:\n{v}" for k, v in EXAMPLES.items())
    assert not BUGS, f"{BUGS}{shown}"
