"""OCES glTF eyes: round trips to float32 precision, and files written by hand as another
tool would (interleaved buffer views, an external .bin, mirror planes, node transforms)."""

from __future__ import annotations

import base64
import json
import math
import struct

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured_from import as_measured
from eyeviz.measured import load_eyes, save_eyes, shipped_eye


def _close32(p, q, acc_rtol=4e-7):
    for e, f in ((p.eye_a, q.eye_a), (p.eye_b, q.eye_b)):
        assert e.n == f.n
        scale = np.abs(e.positions).max()
        assert np.abs(e.positions - f.positions).max() <= 2**-23 * scale
        assert np.abs(e.unit_axes - f.unit_axes).max() <= 2**-22
        assert np.allclose(f.acceptance, e.acceptance, rtol=acc_rtol, atol=0)


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
@pytest.mark.parametrize("name", ["AM_60185-real.eye", "1000-horizontallyAcute-variableDegree.eye"])
def test_round_trip_float32(tmp_path, suffix, name):
    pair = load_eyes(shipped_eye(name))
    out = save_eyes(pair, tmp_path / f"bee{suffix}")
    back = load_eyes(out)
    _close32(pair, back)
    fo = pair.eye_a.focal_offset
    if (fo > 0).all():
        assert np.allclose(back.eye_a.focal_offset, fo, rtol=2**-22)


def test_glb_layout_is_glb(tmp_path):
    save_eyes(as_measured(EyePair3D(40, 20, 2)), tmp_path / "e.glb")
    data = (tmp_path / "e.glb").read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    jlen, jtype = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20 : 20 + jlen])
    assert jtype == 0x4E4F534A and doc["extensionsUsed"] == ["OCES_eyes"]
    eyes = doc["extensions"]["OCES_eyes"]["eyes"]
    assert [e["type"] for e in eyes] == ["POINT_OMMATIDIAL"] * 2
    assert set(eyes[0]["ommatidialProperties"]) == {
        "POSITION",
        "ORIENTATION",
        "DIAMETER",
        "FOCAL_OFFSET",
    }


def test_healpix_export_keeps_its_cones(tmp_path):
    pair = as_measured(EyePair3D(40, 20, 4))
    save_eyes(pair, tmp_path / "h.gltf")
    back = load_eyes(tmp_path / "h.gltf")
    _close32(pair, back)
    # focal offset l: the lens diameter is 2 l tan(acc / 2), W = -l (in metres)
    doc = json.loads((tmp_path / "h.gltf").read_text())
    uri = doc["buffers"][0]["uri"].split(",", 1)[1]
    blob = base64.b64decode(uri)
    views = doc["bufferViews"]
    w = np.frombuffer(blob, "<f4", count=1, offset=views[3]["byteOffset"])[0]
    assert w == np.float32(-0.02)


def _hand_file(tmp_path, n=5, interleave=True, mirror=False, transform=None, uri=None):
    """An OCES file as another tool might write it: one eye (the left, in glTF's frame:
    +x is the head's left) in an interleaved bufferView with byteStride, an external
    .bin, per-eye COARSE diameter, FOCAL_OFFSET as a VEC3 [0, 0, W]."""
    rng = np.random.default_rng(3)
    pos = np.column_stack([0.001 + rng.uniform(0, 3e-4, n), rng.uniform(-2e-4, 2e-4, (n, 2))])
    ax = np.column_stack([np.ones(n), rng.uniform(-0.5, 0.5, n), np.ones(n)])
    ax = ax / np.linalg.norm(ax, axis=1)[:, None]
    w = -rng.uniform(1e-4, 3e-4, n)
    rec = np.zeros(n, dtype=[("p", "<f4", 3), ("pad", "<f4"), ("a", "<f4", 3), ("w", "<f4", 3)])
    rec["p"], rec["a"], rec["w"][:, 2] = pos, ax, w
    blob = b"\xab" * 8 + rec.tobytes()
    stride = rec.itemsize
    views = [{"buffer": 0, "byteOffset": 8, "byteLength": len(blob) - 8, "byteStride": stride}]
    acc = [
        {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": n, "type": "VEC3"},
        {"bufferView": 0, "byteOffset": 16, "componentType": 5126, "count": n, "type": "VEC3"},
        {"bufferView": 0, "byteOffset": 28, "componentType": 5126, "count": n, "type": "VEC3"},
    ]
    (tmp_path / "eye data.bin").write_bytes(blob)
    node = {"name": "left eye", "extensions": {"OCES_eyes": {"eye": 0}}}
    if mirror:
        node["extensions"]["OCES_eyes"]["mirrorPlanes"] = [0]
    head = {"name": "head", "children": [1], "extensions": {"OCES_eyes": {"head": True}}}
    if transform:
        head.update(transform)
    doc = {
        "asset": {"version": "2.0", "generator": "hand"},
        "extensionsUsed": ["OCES_eyes"],
        "scenes": [{"nodes": [0]}],
        "nodes": [head, node],
        "accessors": acc,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob), "uri": uri or "eye%20data.bin"}],
        "extensions": {
            "OCES_eyes": {
                "version": "0.4.0",
                "mirrorPlanes": [{"name": "sagittal", "normal": "X"}],
                "ommatidialProperties": [
                    {"type": "ACCESSOR", "value": 0},
                    {"type": "ACCESSOR", "value": 1, "dataStride": 1},
                    {"type": "ACCESSOR", "value": 2},
                    {"type": "COARSE", "value": 2e-5},
                ],
                "eyes": [
                    {
                        "name": "left",
                        "type": "POINT_OMMATIDIAL",
                        "ommatidialProperties": {
                            "POSITION": 0,
                            "ORIENTATION": 1,
                            "FOCAL_OFFSET": 2,
                            "DIAMETER": 3,
                        },
                    },
                    {"name": "map", "type": "SPHERICAL", "ommatidialCount": 10},
                ],
            }
        },
    }
    path = tmp_path / "hand.gltf"
    path.write_text(json.dumps(doc))
    return path, pos, ax, w, doc


def test_hand_written_interleaved_mirrored(tmp_path):
    path, pos, ax, w, _ = _hand_file(tmp_path, mirror=True)
    pair = load_eyes(path)
    assert pair.facet_counts == (5, 5)
    p32 = pos.astype("<f4").astype(float)
    a32 = ax.astype("<f4").astype(float)
    # glTF frame -> eyeviz: x = -X, y = Z, z = Y; metres -> mm. The file's eye (X > 0) is
    # the left eye A; its mirror image across X = 0 is B.
    assert np.array_equal(
        pair.eye_a.positions, np.column_stack([-p32[:, 0], p32[:, 2], p32[:, 1]]) * 1000
    )
    assert np.array_equal(pair.eye_b.positions[:, 0], -pair.eye_a.positions[:, 0])
    assert np.array_equal(pair.eye_a.axes, np.column_stack([-a32[:, 0], a32[:, 2], a32[:, 1]]))
    w32 = w.astype("<f4").astype(float)
    expect = 2 * np.arctan2(np.float32(2e-5) / 2, -w32)
    assert np.allclose(pair.eye_a.acceptance, expect, rtol=1e-15)
    assert np.array_equal(pair.eye_a.acceptance, pair.eye_b.acceptance)
    assert np.allclose(pair.eye_a.focal_offset, -w32 * 1000)


def test_hand_written_node_transform_and_data_uri(tmp_path):
    (tmp_path / "plain").mkdir()
    plain = load_eyes(_hand_file(tmp_path / "plain", mirror=True)[0], frame="x,-z,y")
    path, pos, ax, w, doc = _hand_file(tmp_path, mirror=True)
    blob = (tmp_path / "eye data.bin").read_bytes()
    (tmp_path / "eye data.bin").unlink()  # the data URI is all there is
    uri = base64.b64encode(blob).decode()
    doc["buffers"][0]["uri"] = "data:application/gltf-buffer;base64," + uri
    # the head is scaled by 2 and turned 90 degrees about +Y
    s = math.sqrt(0.5)
    doc["nodes"][0].update({"scale": [2, 2, 2], "rotation": [0, s, 0, s]})
    path.write_text(json.dumps(doc))
    pair = load_eyes(path, frame="x,-z,y")
    # a similarity keeps acceptance angles; distances double
    both = np.sort(np.concatenate([pair.eye_a.acceptance, pair.eye_b.acceptance]))
    both0 = np.sort(np.concatenate([plain.eye_a.acceptance, plain.eye_b.acceptance]))
    assert np.allclose(both, both0, rtol=1e-12)
    d = np.linalg.norm(pair.eye_a.positions[0] - pair.eye_a.positions[1])
    dp = np.linalg.norm(plain.eye_a.positions[0] - plain.eye_a.positions[1])
    assert d == pytest.approx(2 * dp, rel=1e-6)
    # turned about the vertical: the eyes now lie front and back, not left and right,
    # and the mirror plane (X, in the head's frame) turned with them
    ca, cb = pair.centers
    assert abs(ca[0] - cb[0]) < 1e-9 * abs(ca[1] - cb[1])


def test_single_eye_on_one_side_refused(tmp_path):
    path, pos, ax, w, doc = _hand_file(tmp_path)
    with pytest.raises(EyevizError, match="not a pair"):
        load_eyes(path)


def test_three_eyes_refused(tmp_path):
    path, *_, doc = _hand_file(tmp_path, mirror=True)
    doc["nodes"].append({"name": "third", "extensions": {"OCES_eyes": {"eye": 0}}})
    path.write_text(json.dumps(doc))
    with pytest.raises(EyevizError, match="3 eyes"):
        load_eyes(path)
