"""``eyeviz eye export|info``: real files written and opened, one-line errors, exit 2."""

from __future__ import annotations

import pytest

from eyeviz.cli import main
from eyeviz.measured import load_eyes, save_eyes, shipped_eye


def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("suffix", [".eye", ".gltf", ".glb"])
def test_export_healpix(tmp_path, capsys, suffix):
    out = tmp_path / f"hp{suffix}"
    code, text, err = _run(capsys, "eye", "export", "--nside", "2", "-o", str(out))
    assert code == 0, err
    assert "48 + 48 ommatidia" in text
    assert load_eyes(out).facet_counts == (48, 48)


def test_export_ring_and_file(tmp_path, capsys):
    code, _, err = _run(
        capsys,
        "eye",
        "export",
        "--m",
        "12",
        "--h",
        "3",
        "--l",
        "1",
        "-o",
        str(tmp_path / "ring.glb"),
    )
    assert code == 0, err
    pair = load_eyes(tmp_path / "ring.glb")
    assert pair.facet_counts == (12, 12) and pair.h == pytest.approx(3.0)
    src = shipped_eye("BT_77973-real.eye")
    code, _, err = _run(capsys, "eye", "export", str(src), "-o", str(tmp_path / "bb.gltf"))
    assert code == 0, err
    assert load_eyes(tmp_path / "bb.gltf").facet_counts == (1889, 1889)


def test_info(capsys):
    code, text, err = _run(capsys, "eye", "info", str(shipped_eye("AM_60185-real.eye")))
    assert code == 0, err
    assert "A 3187, B 3187" in text
    assert "x,-z,y" in text
    assert "median interommatidial angle" in text
    # the honeybee's facets are a few degrees apart
    angle = float(text.split("median interommatidial angle ")[1].split(" deg")[0])
    assert 0.5 < angle < 5


def test_info_warns_one_line_for_metres(tmp_path, capsys):
    save_eyes(load_eyes(shipped_eye("AM_60185-real.eye")), tmp_path / "m.eye", units="m")
    code, text, err = _run(capsys, "eye", "info", str(tmp_path / "m.eye"))
    assert code == 0
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eyeviz: warning:") and "units='m'" in err
    code, text, err = _run(capsys, "eye", "info", "--units", "m", str(tmp_path / "m.eye"))
    assert code == 0 and err == ""


@pytest.mark.parametrize(
    "argv,frag",
    [
        (["eye", "export", "--nside", "3", "-o", "{d}/x.eye"], "nside"),
        (["eye", "export", "--nside", "2", "-o", "{d}/x.obj"], "unknown eye file type"),
        (["eye", "export", "--nside", "2", "-o", "{d}/no/x.eye"], "does not exist"),
        (["eye", "export", "--nside", "2", "-o", "{d}/adir.eye"], "directory"),
        (["eye", "export", "{d}/bad.eye", "-o", "{d}/x.eye"], "line 1"),
        (["eye", "export", "--m", "8", "--frame", "x,z,y", "-o", "{d}/x.eye"], "input FILE"),
        (["eye", "info", "--frame", "x,z,y", "{d}/bad.eye"], "reflection"),
        (["eye", "export", "{d}/bad.eye", "--h", "40", "-o", "{d}/x.eye"], "not for an eye FILE"),
        (["eye", "info", "{d}/missing.eye"], "cannot read"),
    ],
)
def test_errors_are_one_line_exit_2(tmp_path, capsys, argv, frag):
    (tmp_path / "bad.eye").write_text("1 2 three\n")
    (tmp_path / "adir.eye").mkdir()
    code, _, err = _run(capsys, *[a.format(d=tmp_path) for a in argv])
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and err.startswith("eyeviz: error:")
    assert frag in err
    assert not (tmp_path / "x.eye").exists()


def test_source_is_required_and_exclusive(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["eye", "export", "--nside", "2", "--m", "8", "-o", str(tmp_path / "x.eye")])
    assert exc.value.code == 2
    with pytest.raises(SystemExit) as exc:
        main(["eye", "export", "-o", str(tmp_path / "x.eye")])
    assert exc.value.code == 2
