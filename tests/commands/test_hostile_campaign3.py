"""The third adversarial pass, second part (issue 36): messages that name the problem,
options that would be ignored, and one integer rule for counts. Each case runs the real
command line (``cli.main``) and reads its one line on stderr."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from eyeviz import cli
from eyeviz.model import scene as scene_mod
from eyeviz.resources import scenes_dir


def _run(argv: list[str], capsys) -> tuple[int, str, str]:
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def _one_line(rc: int, err: str) -> str:
    assert rc == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eyeviz: error: "), err
    return lines[0]


# --- item 6: huge ranges name the problem, not "(34, 'Numerical result out of range')"


@pytest.mark.parametrize("extra", [["--g-max", "1e300"], ["--h", "1e300"]])
def test_huge_ranges_of_a_3d_data_set_are_named(tmp_path, capsys, extra):
    out = tmp_path / "a.npz"
    rc, _, err = _run(["generate", "--nside", "8", "-n", "3", "-o", out, "--quiet", *extra], capsys)
    line = _one_line(rc, err)
    assert "Numerical result out of range" not in line
    assert ("h =" in line or "h=" in line) if extra[0] == "--h" else "visible" in line
    assert not out.exists()


# --- item 7: the output path is checked before any work, in every command


def _a_dir(tmp_path: Path, name: str) -> Path:
    d = tmp_path / name
    d.mkdir()
    (d / "keep.txt").write_text("mine")
    return d


def test_an_output_that_is_a_directory_is_refused_before_any_work(tmp_path, capsys):
    scene = scenes_dir() / "default.toml"
    data = tmp_path / "d.csv"
    assert _run(["generate", "-n", "20", "-o", data, "--quiet", "--seed", "7"], capsys)[0] == 0
    cases = [
        ["generate", "-n", str(10**12), "-o", "{d}"],  # -n is refused later: the path first
        ["generate", "--nside", "8", "-n", "5", "-o", "{d}", "--seed", "7"],
        ["predict", "-e", "analytic", data, "-o", "{d}"],
        ["snapshot", scene, "-o", "{d}"],
        ["study", "-o", "{d}", "--h", "40", "--l", "20", "--m", "720", "--n", "10"],
    ]
    for i, argv in enumerate(cases):
        d = _a_dir(tmp_path, f"out{i}.{'npz' if 'nside' in argv else 'png'}")
        argv = [str(d) if a == "{d}" else a for a in argv]
        rc, out, err = _run(argv, capsys)
        line = _one_line(rc, err)
        assert line == f"eyeviz: error: output {str(d)!r} is a directory; give a file name"
        assert out == ""  # no seed line, no progress: nothing was started
        assert sorted(p.name for p in d.iterdir()) == ["keep.txt"]


def test_a_report_folder_that_is_a_file_is_refused_before_any_work(tmp_path, capsys):
    data = tmp_path / "d.csv"
    assert _run(["generate", "-n", "20", "-o", data, "--quiet", "--seed", "7"], capsys)[0] == 0
    f = tmp_path / "f"
    f.write_text("mine")
    rc, _, err = _run(["report", "dataset", data, "-o", f], capsys)
    assert _one_line(rc, err).endswith(
        f"output {str(f)!r} is not a folder (a report writes a folder)"
    )
    rc, _, err = _run(["report", "dataset", data, "-o", f / "sub"], capsys)
    assert _one_line(rc, err).endswith(f"its folder {str(f)!r} is not a folder")
    rc, _, err = _run(["train", "bayes", "-o", f / "x.npz"], capsys)
    assert _one_line(rc, err).endswith(f"its folder {str(f)!r} is not a folder")
    assert f.read_text() == "mine"


# --- item 14: enough digits, and options that would be ignored are refused


def test_a_design_is_printed_with_the_digits_it_has(tmp_path, capsys):
    rc, _, err = _run(
        ["generate", "-n", "3", "--l", "39.999999", "-o", tmp_path / "x.csv", "--seed", "7"],
        capsys,
    )
    line = _one_line(rc, err)
    assert "l=39.999999" in line and "l=40" not in line


def test_segments_in_single_mode_and_m_with_nside_are_refused(tmp_path, capsys):
    rc, _, err = _run(["generate", "-n", "3", "--segments", "4", "-o", tmp_path / "x.csv"], capsys)
    assert _one_line(rc, err).endswith(
        "--segments 4 is for --mode multi; a single pass has no segments"
    )
    argv = ["generate", "-n", "3", "--nside", "8", "--segments", "4", "-o", tmp_path / "x.npz"]
    assert "--mode multi" in _one_line(*_run(argv, capsys)[::2])
    # --m 720 is the planar default: it used to pass unnoticed beside --nside
    argv = ["generate", "-n", "3", "--nside", "8", "--m", "720", "-o", tmp_path / "x.npz"]
    assert "--m is the planar eye's" in _one_line(*_run(argv, capsys)[::2])
    assert not list(tmp_path.iterdir())
    # multi mode takes it
    argv = ["generate", "-n", "30", "--mode", "multi", "--segments", "4", "--seed", "7"]
    assert _run([*argv, "-o", tmp_path / "x.csv", "--quiet"], capsys)[0] == 0


# --- item 15: a count is an integer or a float holding a whole number, everywhere


def test_a_whole_float_is_a_count_in_scenes_and_on_the_command_line(tmp_path, capsys):
    base = "[eyes]\nh = 40.0\nl = 20.0\nnside = {}\n"
    for text in ("8", "8.0", "0x8"):  # TOML's hex literal is the integer 8
        assert scene_mod.loads(base.format(text)).eyes.nside == 8
    with pytest.raises(scene_mod.SceneError, match=r"nside must be an even integer"):
        scene_mod.loads(base.format("8.5"))
    rows = []
    for nside in ("8", "8.0"):
        out = tmp_path / f"a{nside}.npz"
        argv = ["generate", "--nside", nside, "-n", "4.0", "-o", out, "--seed", "7", "--quiet"]
        assert _run(argv, capsys)[0] == 0
        rows.append(out.read_bytes())
    assert rows[0] == rows[1]  # --nside 8.0 is --nside 8, -n 4.0 is -n 4
    with pytest.raises(SystemExit) as info:  # argparse's own refusal, exit 2
        cli.main(["generate", "--nside", "8.5", "-n", "4", "-o", str(tmp_path / "b.npz")])
    assert info.value.code == 2
    assert "argument --nside: invalid int value: '8.5'" in capsys.readouterr().err


# --- item 11: predict names what its data path is, and what an NPZ that is none is


def test_predict_names_a_data_path_that_is_no_regular_file(tmp_path, capsys):
    d = tmp_path / "dir.npz"
    d.mkdir()
    fifo = tmp_path / "pipe.npz"
    os.mkfifo(fifo)
    loop = tmp_path / "loop.npz"
    os.symlink(tmp_path / "loop2.npz", loop)
    os.symlink(loop, tmp_path / "loop2.npz")
    out = tmp_path / "o.csv"
    for path, words in (
        (d, "is not a regular file: it is a directory"),
        (fifo, "is not a regular file: it is a FIFO (named pipe)"),
        (Path("/dev/zero"), "is not a regular file: it is a character device"),
        (loop, ": a loop of symbolic links"),
        (tmp_path / "absent.npz", ": not found"),
    ):
        rc, _, err = _run(["predict", "-e", "analytic3d", path, "-o", out], capsys)
        line = _one_line(rc, err)
        assert (
            line == f"eyeviz: error: data file {str(path)!r}{'' if words[0] == ':' else ' '}{words}"
        )
    assert not out.exists()


def test_predict_says_an_npz_is_none_rather_than_the_other_kind(tmp_path, capsys):
    good = tmp_path / "good.npz"
    argv = ["generate", "--nside", "8", "-n", "20", "-o", good, "--seed", "7", "--quiet"]
    assert _run(argv, capsys)[0] == 0
    data = good.read_bytes()
    cases = {"empty.npz": b"", "garbage.npz": os.urandom(300), "truncated.npz": data[:-100]}
    for name, body in cases.items():
        p = tmp_path / name
        p.write_bytes(body)
        for est in ("analytic3d", "analytic"):  # neither kind is named
            rc, _, err = _run(["predict", "-e", est, p, "-o", tmp_path / "o.csv"], capsys)
            line = _one_line(rc, err)
            assert f"{p}: not an eyeviz NPZ data set (" in line, line
            assert "planar" not in line and "use one of" not in line


# --- item 12: a data set without rows is named


def test_report_estimators_names_a_data_set_without_rows(tmp_path, capsys):
    import dataclasses

    import numpy as np

    from eyeviz.core.domain import Domain3D
    from eyeviz.dataset import sparse3d
    from eyeviz.dataset.algorithm1_3d import generate3d, make_params3d

    p = make_params3d(Domain3D(nside=8), "single", 1, None)
    ds = generate3d(2, p.domain, "single", 1)
    empty = {
        f.name: np.zeros(1, np.int64) if f.name.startswith("indptr") else getattr(ds, f.name)[:0]
        for f in dataclasses.fields(ds)
        if isinstance(getattr(ds, f.name), np.ndarray)
    }
    path = tmp_path / "zero.npz"
    sparse3d.write_chunks3d(path, 0, p.domain, p.as_dict(), [dataclasses.replace(ds, **empty)])
    rc, _, err = _run(["report", "estimators", "--data", path, "-o", tmp_path / "rep"], capsys)
    line = _one_line(rc, err)
    assert str(path) in line and "metrics need at least one value" not in line
    assert not (tmp_path / "rep").exists()


# --- item 4: a fatal error in the app ends the process


def test_out_of_memory_in_the_app_exits_even_with_a_job_running(tmp_path):
    import subprocess
    import sys

    code = (
        "import sys, threading, time\n"
        "import eyeviz.app.main as m\n"
        "def run_app(*a, **k):\n"
        "    threading.Thread(target=time.sleep, args=(600,)).start()  # a job never ending\n"
        "    raise MemoryError\n"
        "m.run_app = run_app\n"
        "from eyeviz import cli\n"
        f"sys.exit(cli.main(['app', '--screenshot', {str(tmp_path / 'x.png')!r}]))\n"
    )
    root = Path(__file__).resolve().parents[2]
    env = {**os.environ, "PYTHONPATH": str(root), "DISPLAY": ":987", "QT_QPA_PLATFORM": "offscreen"}
    p = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )  # before: "out of memory", then alive until killed (here: the 120 s timeout)
    assert p.returncode == 2, p.stderr
    assert p.stderr.strip().splitlines() == ["eyeviz: error: out of memory"]


# --- item 5 (and 4): the largest nside, lit facets and balls each path draws, held


def _ball_scene(path: Path, nside: int, balls: list[tuple[float, float, float, float]]) -> Path:
    fs = [
        scene_mod.Feature(f"b{i}", x, y, g, scene_mod.OKABE_ITO[i % 7], z)
        for i, (x, y, z, g) in enumerate(balls)
    ]
    layers = ["eyes", "features", "bitmaps", "readout"]
    scene_mod.save(scene_mod.Scene(scene_mod.Eyes(40.0, 20.0, nside=nside), fs, layers), path)
    return path


@pytest.fixture
def no_lit_sets(monkeypatch):
    """Any lit set computed fails the test: a refusal must come before allocating."""
    from eyeviz.core.geometry3d import EyePair3D

    def boom(*_a, **_k):
        raise AssertionError("lit sets were computed")

    monkeypatch.setattr(EyePair3D, "lit_csr", boom)


def test_each_path_refuses_beyond_its_nside_and_lit_facets_before_allocating(
    tmp_path, capsys, no_lit_sets, monkeypatch
):
    from eyeviz.model import draw_bounds as db

    monkeypatch.setenv("DISPLAY", ":987")  # no xvfb-run copy: the refusal comes first

    big = _ball_scene(tmp_path / "big.toml", 2048, [(0.0, 150.0, 0.0, 120.0)])
    for out, path in (("f.png", "a PNG snapshot"), ("f.svg", "an SVG/PDF figure")):
        rc, _, err = _run(["snapshot", big, "-o", tmp_path / out], capsys)
        line = _one_line(rc, err)
        assert "facets of an eye at nside 2048" in line and path in line
        assert f"draws at most {db.MAX_DRAWN_LIT['vector']:,}" in line
    huge = _ball_scene(tmp_path / "huge.toml", 2 * db.MAX_DRAW_NSIDE["vector"], [(0, 900, 0, 1)])
    rc, _, err = _run(["snapshot", huge, "-o", tmp_path / "f.pdf"], capsys)
    assert _one_line(rc, err).endswith(
        f"nside = {2 * db.MAX_DRAW_NSIDE['vector']}: an SVG/PDF figure draws spherical eyes up "
        f"to nside {db.MAX_DRAW_NSIDE['vector']} (a larger nside is for data sets and estimators)"
    )
    app = _ball_scene(tmp_path / "app.toml", 2 * db.MAX_DRAW_NSIDE["app"], [(0, 900, 0, 1)])
    rc, _, err = _run(["app", app, "--screenshot", tmp_path / "s.png"], capsys)
    assert "the app's 3D view draws spherical eyes up to nside" in _one_line(rc, err)
    many = [(float(x), 2000.0, 0.0, 5.0) for x in range(db.MAX_APP_BALLS + 1)]
    crowd = _ball_scene(tmp_path / "crowd.toml", 16, many)
    rc, _, err = _run(["app", crowd, "--screenshot", tmp_path / "s.png"], capsys)
    assert f"the app's 3D view draws at most {db.MAX_APP_BALLS}" in _one_line(rc, err)
    assert sorted(p.suffix for p in tmp_path.iterdir()) == [".toml"] * 4


def test_the_lit_estimate_brackets_the_exact_count():
    from eyeviz.model import draw_bounds as db
    from eyeviz.model.state3d import compute_state3d

    for nside, ball in ((64, (0.0, 150.0, 0.0, 120.0)), (128, (30.0, 900.0, 50.0, 60.0))):
        sc = scene_mod.Scene(
            scene_mod.Eyes(40.0, 20.0, nside=nside),
            [scene_mod.Feature("b", ball[0], ball[1], ball[3], "#D55E00", ball[2])],
            ["eyes"],
        )
        st = compute_state3d(sc)
        exact = max(int(st.facets_a[0]), int(st.facets_b[0]))
        assert exact <= db.lit_estimate(sc) <= 2 * exact + 100, (nside, exact)
