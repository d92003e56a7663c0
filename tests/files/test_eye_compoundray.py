"""CompoundRay .eye files: round trips to the last bit, frames, units, the size warning."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
from eyeviz.files.eye_frames import FRAMES, EyeSizeWarning, parse_frame
from eyeviz.measured import load_eyes, save_eyes, shipped_eye

SHIPPED = [
    "AM_60185-real.eye",
    "BT_77967-real.eye",
    "BT_77973-real.eye",
    "1000-horizontallyAcute-variableDegree.eye",
]


def _bits(pair):
    out = []
    for e in (pair.eye_a, pair.eye_b):
        fo = e.focal_offset
        out += [e.positions.tobytes(), e.axes.tobytes(), e.acceptance.tobytes()]
        out.append(None if fo is None else fo.tobytes())
    return out


def _random_pair(rng, n=300):
    def eye(sign, name):
        pos = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-3, 2, size=(n, 1))
        pos[:, 0] = sign * (np.abs(pos[:, 0]) + 1e-3)
        ax = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-300, 300, size=(n, 1))
        acc = rng.uniform(np.nextafter(0, 1), np.nextafter(math.pi, 0), size=n)
        fo = rng.normal(size=n) * 10.0 ** rng.uniform(-5, 5, size=n)
        return MeasuredEye(pos, ax, acc, fo, name=name)

    return MeasuredEyePair(eye(-1, "A"), eye(1, "B"))


def test_shipped_files_load_in_eyeviz_frame():
    pair = load_eyes(shipped_eye("AM_60185-real.eye"))
    assert pair.facet_counts == (3187, 3187)
    pa, axa, acc = pair.facets("A")
    assert (pa[:, 0] < 0).all() and (pair.facets("B")[0][:, 0] >= 0).all()
    # the bee looks forward: most axes have y > 0 in eyeviz's frame (file -z)
    assert (axa[:, 1] > 0).mean() > 0.5
    assert np.all(acc == 0.0453785606)
    # line 1 of the file is (1.6017502946 0.0764177149 -0.2529123005 ...) at x > 0: eye B
    b0 = pair.eye_b.positions[0]
    assert b0.tolist() == [1.6017502946, 0.2529123005, 0.0764177149]


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_round_trip_bit_exact(tmp_path, name):
    pair = load_eyes(shipped_eye(name))
    out = save_eyes(pair, tmp_path / "x.eye")
    assert _bits(load_eyes(out)) == _bits(pair)


def test_random_doubles_round_trip_bit_exact(tmp_path):
    rng = np.random.default_rng(7)
    pair = _random_pair(rng)
    for frame in ("compoundray", "gltf", "eyeviz", "-y,x,z"):
        save_eyes(pair, tmp_path / "r.eye", frame=frame)
        assert _bits(load_eyes(tmp_path / "r.eye", frame=frame)) == _bits(pair)


def test_negative_zero_survives(tmp_path):
    a = MeasuredEye([[-1.0, -0.0, 0.0]], [[0.0, -0.0, 1.0]], [0.1], [0.0], name="A")
    b = MeasuredEye([[1.0, 0.0, -0.0]], [[-0.0, 1.0, 0.0]], [0.1], [-0.0], name="B")
    pair = MeasuredEyePair(a, b)
    save_eyes(pair, tmp_path / "z.eye")
    assert _bits(load_eyes(tmp_path / "z.eye")) == _bits(pair)


def test_tolerated_layouts(tmp_path):
    text = (
        "\n  -1.0\t0 0,  0 0 -1 0.05 0.2  \r\n\n"
        "1.0, 0, 0, 0, 0, -1, 0.05, 0.2\r\n"
        "-1.5 0 0 0 0 -1 0.05 0.2\n1.5 0 0 0 0 -1 0.05 0.2"
    )
    (tmp_path / "t.eye").write_text(text)
    pair = load_eyes(tmp_path / "t.eye")
    assert pair.facet_counts == (2, 2)
    assert pair.eye_a.positions[:, 0].tolist() == [-1.0, -1.5]
    assert pair.eye_a.axes[0].tolist() == [0.0, 1.0, 0.0]  # file -z is eyeviz forward
    assert pair.eye_a.focal_offset.tolist() == [0.2, 0.2]


def test_seven_numbers_mean_no_focal_offset(tmp_path):
    (tmp_path / "s.eye").write_text("-1 0 0 0 0 -1 0.05\n1 0 0 0 0 -1 0.05\n")
    pair = load_eyes(tmp_path / "s.eye")
    assert pair.eye_a.focal_offset is None
    save_eyes(pair, tmp_path / "s2.eye")
    assert (tmp_path / "s2.eye").read_text().split("\n")[0].split()[-1] == "0.0"


def test_units_scale_lengths_not_angles(tmp_path):
    (tmp_path / "u.eye").write_text("-0.001 0 0 0 0 -1 0.05 0.0002\n0.001 0 0 0 0 -1 0.05 0.0002\n")
    pair = load_eyes(tmp_path / "u.eye", units="m")
    assert pair.eye_a.positions[0].tolist() == [-1.0, 0.0, 0.0]
    assert pair.eye_a.focal_offset[0] == pytest.approx(0.2)
    assert pair.eye_a.acceptance[0] == 0.05
    (tmp_path / "v.eye").write_text("-1500 0 0 0 0 -1 0.05 20\n1500 0 0 0 0 -1 0.05 20\n")
    um = load_eyes(tmp_path / "v.eye", units="um")
    assert um.eye_b.positions[0].tolist() == [1.5, 0.0, 0.0]
    assert um.eye_b.focal_offset[0] == pytest.approx(0.02)
    with pytest.raises(EyevizError, match="units must be one of"):
        load_eyes(tmp_path / "u.eye", units="inch")


def test_metres_read_as_mm_warns_and_names_the_fix(tmp_path):
    pair = load_eyes(shipped_eye("AM_60185-real.eye"))
    save_eyes(pair, tmp_path / "ant.eye", units="m")  # written in metres, as the ant file
    with pytest.warns(EyeSizeWarning, match=r"units='m'"):
        load_eyes(tmp_path / "ant.eye")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = load_eyes(tmp_path / "ant.eye", units="m")
    assert np.allclose(back.eye_a.positions, pair.eye_a.positions, rtol=1e-12)


def test_no_warning_for_plausible_sizes():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in SHIPPED:
            load_eyes(shipped_eye(name))


def test_frames_parse_and_refuse_reflections():
    assert parse_frame("compoundray").text == FRAMES["compoundray"]
    v = np.array([[1.0, 2.0, 3.0]])
    fr = parse_frame("x,-z,y")
    assert fr.to_eyeviz(v).tolist() == [[1.0, -3.0, 2.0]]
    assert fr.from_eyeviz(fr.to_eyeviz(v)).tolist() == v.tolist()
    for bad in ("x,y", "x,x,z", "a,b,c", "x,--y,z", 3):
        with pytest.raises(EyevizError, match="frame"):
            parse_frame(bad)
    with pytest.raises(EyevizError, match="reflection"):
        parse_frame("x,z,y")


def test_explicit_frame_changes_the_split(tmp_path):
    # eyes side by side along the file's z: only a frame mapping file z to eyeviz x pairs them
    (tmp_path / "f.eye").write_text("0 0 -1 0 1 0 0.1 0\n0 0 1 0 1 0 0.1 0\n")
    with pytest.raises(EyevizError, match="one eye, not a pair"):
        load_eyes(tmp_path / "f.eye")
    pair = load_eyes(tmp_path / "f.eye", frame="z,x,y")
    assert pair.eye_a.positions.tolist() == [[-1.0, 0.0, 0.0]]
    assert pair.eye_a.axes.tolist() == [[0.0, 0.0, 1.0]]


def test_unknown_shipped_name_lists_the_shipped():
    with pytest.raises(EyevizError, match="AM_60185-real.eye"):
        shipped_eye("../eyes/x.eye")


def test_pieces_keep_rows_and_line_numbers(tmp_path, monkeypatch):
    from eyeviz.files import eye_compoundray

    pair = load_eyes(shipped_eye("1000-horizontallyAcute-variableDegree.eye"))
    save_eyes(pair, tmp_path / "p.eye")
    monkeypatch.setattr(eye_compoundray, "_CHUNK", 300)  # a few lines a piece
    assert _bits(load_eyes(tmp_path / "p.eye")) == _bits(pair)
    lines = (tmp_path / "p.eye").read_text().splitlines()
    good = lines[736]
    lines[736] = "1-2 " + good.split(" ", 1)[1]  # passes the character check, not float()
    lines[900] = " ".join(lines[900].split()[:7])
    (tmp_path / "p.eye").write_text("\n\n" + "\n".join(lines))
    with pytest.raises(EyevizError, match=r"line 739: '1-2' is not a number"):
        load_eyes(tmp_path / "p.eye")
    lines[736] = good
    (tmp_path / "p.eye").write_text("\n\n" + "\n".join(lines))
    with pytest.raises(EyevizError, match=r"line 903: 7 numbers, expected 8 as on line 3"):
        load_eyes(tmp_path / "p.eye")
