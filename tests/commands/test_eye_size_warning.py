"""A scene whose eye file looks the wrong size warns in one line on the command line (as
`eyeviz eye info` and `generate --eye` do), not with Python's two-line warning that
quotes the loader's source."""

from __future__ import annotations

from eyeviz import cli
from eyeviz.measured import shipped_eye

SCENE = """title = "a bee in metres"

[eyes]
file = "{eye}"
units = "m"

[[features]]
name = "far"
x = 0.0
y = 30000.0
z = -30000.0
g = 3000.0
"""


def test_snapshot_of_a_scene_with_an_implausible_eye_size_warns_in_one_line(tmp_path, capsys):
    scene = tmp_path / "bee_m.toml"
    scene.write_text(SCENE.format(eye=shipped_eye("BT_77973-real.eye").as_posix()))
    out = tmp_path / "bee.png"
    assert cli.main(["snapshot", str(scene), "-o", str(out)]) == 0
    assert out.stat().st_size > 0
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    warn = [ln for ln in err if "plausible" in ln]
    assert len(warn) == 1 and warn[0].startswith("eyeviz: warning: BT_77973-real.eye:"), err
    assert not any("load_eyes(" in ln or "EyeSizeWarning" in ln for ln in err), err
