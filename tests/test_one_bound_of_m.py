"""One bound for m at every entry point (issue 20): ``eyeviz.core.bounds.MAX_M`` is accepted
and ``MAX_M + 2`` refused, with one line naming m, by the API (EyePair, Domain), scene
files and Save, data set and model files, and the command line (generate, predict, study,
snapshot). The app's Eyes panel and its Save: tests/app/test_m_bound.py."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError, cli, dataset
from eyeviz.core.bounds import MAX_M
from eyeviz.core.domain import Domain
from eyeviz.core.geometry import EyePair
from eyeviz.estimators import compact
from eyeviz.model.scene import Scene, SceneError, load, loads, save
from eyeviz.study.grid import design_grid

OVER = MAX_M + 2
RULE = f"m must be an even integer >= 4 and <= {MAX_M}, got {OVER}"


def _one_line_rule(text: str) -> None:
    text = text.strip()
    assert "\n" not in text and RULE in text, text


def test_the_bound():
    assert MAX_M == 2**20 and MAX_M % 2 == 0


def test_api():
    assert EyePair(40.0, 20.0, MAX_M).m == MAX_M
    assert Domain(m=MAX_M).m == MAX_M
    for make in (lambda: EyePair(40.0, 20.0, OVER), lambda: Domain(m=OVER)):
        with pytest.raises(EyevizError) as info:
            make()
        _one_line_rule(str(info.value))


def test_scene_files_and_save(tmp_path):
    scene = loads(f"[eyes]\nh = 40.0\nl = 20.0\nm = {MAX_M}\n", "max.toml")
    assert scene.eyes.m == MAX_M
    save(scene, tmp_path / "max.toml")
    assert load(tmp_path / "max.toml").eyes.m == MAX_M
    with pytest.raises(SceneError) as info:
        loads(f"[eyes]\nh = 40.0\nl = 20.0\nm = {OVER}\n", "over.toml")
    _one_line_rule(str(info.value))
    assert str(info.value).startswith("over.toml:4: eyes.m: ")
    over = Scene()
    over.eyes.m = OVER
    with pytest.raises(SceneError) as info:
        save(over, tmp_path / "over.toml")
    _one_line_rule(str(info.value))
    assert not (tmp_path / "over.toml").exists()


def _npz_with_meta(path: Path, meta: dict) -> None:
    with zipfile.ZipFile(path, "w") as z:
        for name, arr in (("meta", np.array(json.dumps(meta))), ("rows", np.zeros(0, "u1"))):
            buf = io.BytesIO()
            np.save(buf, arr)
            z.writestr(f"{name}.npy", buf.getvalue())


def test_data_set_and_model_files(tmp_path):
    p = tmp_path / "max.npz"
    dataset.write(p, 2, eyes=EyePair(40.0, 20.0, MAX_M))
    assert dataset.load(p).eyes.m == MAX_M
    _npz_with_meta(tmp_path / "over.npz", {"version": 1, "m": OVER, "n": 0, "params": {}})
    with pytest.raises(EyevizError) as info:
        dataset.load(tmp_path / "over.npz")
    _one_line_rule(str(info.value))
    # a compact model directory whose data domain has m beyond the bound
    d = tmp_path / "model"
    d.mkdir()
    for f in ("compact.json", "compact_dd.pt", "compact_ad.pt"):
        (d / f).write_bytes((compact.default_dir() / f).read_bytes())
    meta = json.loads((d / "compact.json").read_text())
    meta["data"]["m"] = MAX_M
    (d / "compact.json").write_text(json.dumps(meta))
    assert compact.load(d).domain.m == MAX_M
    meta["data"]["m"] = OVER
    (d / "compact.json").write_text(json.dumps(meta))
    with pytest.raises(EyevizError) as info:
        compact.load(d)
    _one_line_rule(str(info.value))


def _cli(capsys, *argv: str) -> tuple[int, str]:
    code = cli.main(list(argv))
    return code, capsys.readouterr().err


def test_command_line(tmp_path, capsys):
    data = str(tmp_path / "max.csv")
    assert _cli(capsys, "generate", "-n", "2", "--m", str(MAX_M), "-o", data, "--quiet")[0] == 0
    pred = str(tmp_path / "pred.csv")
    argv = ["predict", "-e", "analytic", data, "-o", pred]
    assert _cli(capsys, *argv, "--m", str(MAX_M))[0] == 0
    scene = tmp_path / "max.toml"
    scene.write_text(f"[eyes]\nm = {MAX_M}\n")
    assert _cli(capsys, "snapshot", str(scene), "-o", str(tmp_path / "max.png"))[0] == 0
    assert [p.m for p in design_grid(h=[40.0], l=[20.0], m=[MAX_M])] == [MAX_M]

    over = tmp_path / "over.toml"
    over.write_text(f"[eyes]\nm = {OVER}\n")
    refusals = [
        ["generate", "-n", "2", "--m", str(OVER), "-o", str(tmp_path / "over.csv")],
        [*argv, "--m", str(OVER)],
        ["study", "--h", "40", "--l", "20", "--m", str(OVER), "-o", str(tmp_path / "s.csv")],
        ["snapshot", str(over), "-o", str(tmp_path / "over.png")],
    ]
    for refused in refusals:
        code, err = _cli(capsys, *refused)
        assert code == 2, (refused, err)
        assert err.startswith("eyeviz"), err
        _one_line_rule(err)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "max.csv",
        "max.png",
        "max.toml",
        "over.toml",
        "pred.csv",
    ]
