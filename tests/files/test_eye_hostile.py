"""Hostile eye files: each is refused with one EyevizError line, nothing is run, nothing
outside the file's folder is read, and every size the file declares is bounded.

The classes covered are listed in HOSTILE_CLASSES (the README's hostile-input table
counts them); each has at least one case below.
"""

from __future__ import annotations

import base64
import json
import os
import struct

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured_from import as_measured
from eyeviz.files import limits
from eyeviz.measured import load_eyes, save_eyes

GOOD = "-1 0 0 0 0 -1 0.05 0.2\n1 0 0 0 0 -1 0.05 0.2\n"

EYE_CASES = {
    # class: (file text, message fragment)
    "eye: a word in a row": ("-1 0 0 0 0 -1 0.05 0.2\n1 0 zero 0 0 -1 0.05 0.2\n", "line 2"),
    "eye: a malformed number": ("-1 0 0 0 0 -1 0.05 0.2\n1 0 1-2 0 0 -1 0.05 0.2\n", "line 2"),
    "eye: too few numbers": (GOOD + "1 0 0 0 0 -1 0.05\n", "line 3: 7 numbers"),
    "eye: too many numbers": ("-1 0 0 0 0 -1 0.05 0.2 9\n" + GOOD, "line 1: 9 numbers"),
    "eye: NaN": (GOOD + "\n1 nan 0 0 0 -1 0.05 0.2\n", "line 4"),
    "eye: overflow to infinity": (
        GOOD + "1 1e999 0 0 0 -1 0.05 0.2\n",
        "line 3: a number is not finite",
    ),
    "eye: zero axis": (GOOD + "1 0 0 0 0 0 0.05 0.2\n", "line 3: the axis is zero"),
    "eye: zero acceptance": (GOOD + "1 0 0 0 0 -1 0 0.2\n", "line 3: acceptance"),
    "eye: negative acceptance": (GOOD + "1 0 0 0 0 -1 -0.05 0.2\n", "line 3: acceptance"),
    "eye: acceptance >= pi": (GOOD + "1 0 0 0 0 -1 3.1415926535897931 0.2\n", "not in (0, pi)"),
    "eye: binary bytes": (GOOD + "1 0 0 0 0 -1 0.05 \x00\x01\n", "line 3"),
    "eye: non-ASCII text": (GOOD + "1 0 0 0 0 −1 0.05 0.2\n", "line 3"),
    "eye: Python-only number syntax (1_0)": (GOOD + "1_0 0 0 0 0 -1 0.05 0.2\n", "line 3"),
    "eye: empty file": ("\n\n  \n", "no ommatidia"),
    "eye: one eye, not a pair": ("1 0 0 0 0 -1 0.05 0.2\n2 0 0 0 0 -1 0.05 0.2\n", "not a pair"),
}


def _one_line(exc: pytest.ExceptionInfo) -> str:
    text = str(exc.value)
    assert "\n" not in text and text, text
    return text


@pytest.mark.parametrize("case", sorted(EYE_CASES))
def test_eye_file_refused(tmp_path, case):
    text, frag = EYE_CASES[case]
    p = tmp_path / "bad.eye"
    p.write_bytes(text.encode("utf-8"))
    with pytest.raises(EyevizError) as exc:
        load_eyes(p)
    assert frag in _one_line(exc)


def test_10e8_rows_refused_before_reading(tmp_path):
    p = tmp_path / "huge.eye"
    with open(p, "wb") as f:  # a sparse file as long as 10^8 rows of 16 bytes
        f.truncate(10**8 * 16)
    with pytest.raises(EyevizError) as exc:
        load_eyes(p)
    assert f"more than {limits.MAX_EYE_FILE_BYTES}" in _one_line(exc)


def test_row_bound_counts_lines_before_parsing(tmp_path, monkeypatch):
    monkeypatch.setattr(limits, "MAX_EYE_ROWS", 50)
    p = tmp_path / "many.eye"
    p.write_text(GOOD * 26)
    with pytest.raises(EyevizError) as exc:
        load_eyes(p)
    assert "53 lines, more than the bound of 50" in _one_line(exc)
    p.write_text(GOOD * 24)
    assert load_eyes(p).facet_counts == (24, 24)


@pytest.mark.parametrize("suffix", [".eye", ".gltf", ".glb"])
def test_non_regular_files_refused(tmp_path, suffix):
    fifo = tmp_path / f"pipe{suffix}"
    os.mkfifo(fifo)
    with pytest.raises(EyevizError, match="not a regular file"):
        load_eyes(fifo)  # would block forever if opened for reading
    folder = tmp_path / f"dir{suffix}"
    folder.mkdir()
    with pytest.raises(EyevizError, match="not a regular file"):
        load_eyes(folder)
    link = tmp_path / f"zero{suffix}"
    link.symlink_to("/dev/zero")
    with pytest.raises(EyevizError, match="not a regular file"):
        load_eyes(link)
    with pytest.raises(EyevizError, match="cannot read"):
        load_eyes(tmp_path / f"missing{suffix}")


def test_unknown_suffix_refused(tmp_path):
    (tmp_path / "x.csv").write_text(GOOD)
    with pytest.raises(EyevizError, match="unknown eye file type"):
        load_eyes(tmp_path / "x.csv")


# --- glTF / OCES ------------------------------------------------------------------------
@pytest.fixture
def oces(tmp_path):
    """A valid OCES .gltf with its buffer in an external b.bin: (doc, write(doc) -> path)."""
    save_eyes(as_measured(EyePair3D(40, 20, 2)), tmp_path / "ok.gltf")
    doc = json.loads((tmp_path / "ok.gltf").read_text())
    blob = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    (tmp_path / "b.bin").write_bytes(blob)
    doc["buffers"][0]["uri"] = "b.bin"

    def write(d, name="bad.gltf"):
        p = tmp_path / name
        p.write_text(json.dumps(d))
        return p

    assert load_eyes(write(doc)).facet_counts == (48, 48)
    return doc, write


def _set(doc, path, value):
    o = doc
    for k in path[:-1]:
        o = o[k]
    if value is _DEL:
        del o[path[-1]]
    else:
        o[path[-1]] = value


_DEL = object()
OCES = ("extensions", "OCES_eyes")
GLTF_CASES = {
    "gltf: buffer byteLength lies (longer than its data)": (
        ("buffers", 0, "byteLength"),
        10**6,
        "byteLength says 1000000 bytes",
    ),
    "gltf: buffer byteLength beyond the file bound": (
        ("buffers", 0, "byteLength"),
        1 << 40,
        "byteLength must be an integer",
    ),
    "gltf: bufferView past its buffer": (
        ("bufferViews", 1, "byteOffset"),
        10**5,
        "lie beyond its buffer",
    ),
    "gltf: bufferView length overflows (2^64)": (
        ("bufferViews", 0, "byteLength"),
        2**64,
        "byteLength must be an integer",
    ),
    "gltf: accessor count past its bufferView": (("accessors", 0, "count"), 49, "need 588 bytes"),
    "gltf: accessor count beyond the row bound": (
        ("accessors", 0, "count"),
        2**53,
        "count must be an integer",
    ),
    "gltf: accessor offset past its bufferView": (
        ("accessors", 2, "byteOffset"),
        8,
        "need 200 bytes",
    ),
    "gltf: negative index": (("accessors", 0, "bufferView"), -1, "is not one of"),
    "gltf: index out of range": (OCES + ("ommatidialProperties", 0, "value"), 99, "is not one of"),
    "gltf: boolean for an integer": (("bufferViews", 0, "byteOffset"), True, "must be an integer"),
    "gltf: byteStride not a multiple of 4": (("bufferViews", 0, "byteStride"), 14, "byteStride"),
    "gltf: not FLOAT components": (("accessors", 0, "componentType"), 5123, "FLOAT"),
    "gltf: wrong accessor type": (("accessors", 0, "type"), "VEC2", "type must be VEC3"),
    "gltf: sparse accessor": (("accessors", 0, "sparse"), {"count": 1}, "sparse"),
    "gltf: buffer URI with ..": (("buffers", 0, "uri"), "../b.bin", "leaves the file's folder"),
    "gltf: buffer URI %-encoded ..": (("buffers", 0, "uri"), "%2E%2E/b.bin", "leaves"),
    "gltf: absolute buffer path": (("buffers", 0, "uri"), "/etc/passwd", "not a relative path"),
    "gltf: URI with a scheme": (("buffers", 0, "uri"), "file:///etc/passwd", "not a relative"),
    "gltf: remote URI": (("buffers", 0, "uri"), "https://example.org/b.bin", "not a relative"),
    "gltf: data URI not base64": (
        ("buffers", 0, "uri"),
        "data:application/octet-stream;base64,@@@@",
        "not valid base64",
    ),
    "gltf: data URI without ;base64": (
        ("buffers", 0, "uri"),
        "data:application/octet-stream,AAAA",
        "must be base64",
    ),
    "gltf: no OCES_eyes extension": (("extensions",), _DEL, "no OCES_eyes extension"),
    "gltf: not glTF 2.0": (("asset", "version"), "1.0", "not glTF 2.0"),
    "oces: FOCAL_OFFSET >= 0": (
        OCES + ("ommatidialProperties", 3),
        {"type": "COARSE", "value": 0.0},
        "FOCAL_OFFSET < 0",
    ),
    "oces: DIAMETER <= 0": (
        OCES + ("ommatidialProperties", 2),
        {"type": "COARSE", "value": -1.0},
        "DIAMETER must",
    ),
    "oces: sheared cone": (
        OCES + ("ommatidialProperties", 3),
        {"type": "COARSE", "value": [0.1, 0, -1]},
        "sheared",
    ),
    "oces: texture property": (
        OCES + ("ommatidialProperties", 0),
        {"type": "TEXTURE", "value": 0},
        "not supported",
    ),
    "oces: dataStride other than 1": (
        OCES + ("ommatidialProperties", 0, "dataStride"),
        2,
        "dataStride",
    ),
    "oces: accessors disagree on the count": (("accessors", 1, "count"), 10, "disagree"),
    "oces: no eyes": (OCES + ("eyes",), [], "lists no eyes"),
    "oces: node names a missing eye": (
        ("nodes", 1, "extensions", "OCES_eyes", "eye"),
        7,
        "not one of",
    ),
    "oces: node cycle": (("nodes", 1, "children"), [0], "form a cycle"),
    "oces: non-uniform scale": (("nodes", 0, "scale"), [1, 2, 1], "uniform scale"),
    "oces: non-finite transform": (("nodes", 0, "translation"), [0, 1e999, 0], "finite"),
    "oces: missing mirror plane": (
        ("nodes", 1, "extensions", "OCES_eyes", "mirrorPlanes"),
        [3],
        "mirror plane 3",
    ),
}


@pytest.mark.parametrize("case", sorted(GLTF_CASES))
def test_gltf_refused(oces, case):
    doc, write = oces
    path, value, frag = GLTF_CASES[case]
    _set(doc, path, value)
    with pytest.raises(EyevizError) as exc:
        load_eyes(write(doc))
    assert frag in _one_line(exc)


def test_gltf_nan_in_accessor(oces, tmp_path):
    doc, write = oces
    blob = bytearray((tmp_path / "b.bin").read_bytes())
    blob[4:8] = struct.pack("<f", float("nan"))
    (tmp_path / "b.bin").write_bytes(bytes(blob))
    with pytest.raises(EyevizError, match="element 0 is not finite"):
        load_eyes(write(doc))


def test_gltf_buffer_symlink_out_of_folder(oces, tmp_path):
    doc, write = oces
    outside = tmp_path.parent / f"{tmp_path.name}-outside.bin"
    outside.write_bytes((tmp_path / "b.bin").read_bytes())
    (tmp_path / "b.bin").unlink()
    (tmp_path / "b.bin").symlink_to(outside)
    with pytest.raises(EyevizError, match="leads outside the file's folder"):
        load_eyes(write(doc))
    sub = tmp_path / "sub"
    sub.symlink_to(tmp_path.parent)  # a folder link out, then a name inside it
    doc["buffers"][0]["uri"] = f"sub/{outside.name}"
    with pytest.raises(EyevizError, match="leads outside"):
        load_eyes(write(doc))


def test_gltf_buffer_fifo_refused(oces, tmp_path):
    doc, write = oces
    (tmp_path / "b.bin").unlink()
    os.mkfifo(tmp_path / "b.bin")
    with pytest.raises(EyevizError, match="not a regular file"):
        load_eyes(write(doc))


@pytest.mark.parametrize(
    "text,frag",
    [
        ("{", "not valid glTF JSON"),
        ("[1, 2]", "must be an object"),
        ("[" * 100000 + "]" * 100000, "nested too deeply"),
        ('{"asset": {"version": "2.0"}, "x": 1' + "0" * 5000 + "}", "not valid glTF JSON"),
    ],
)
def test_gltf_json_refused(tmp_path, text, frag):
    (tmp_path / "j.gltf").write_text(text)
    with pytest.raises(EyevizError) as exc:
        load_eyes(tmp_path / "j.gltf")
    assert frag in _one_line(exc)


def _glb(tmp_path):
    save_eyes(as_measured(EyePair3D(40, 20, 2)), tmp_path / "ok.glb")
    return bytearray((tmp_path / "ok.glb").read_bytes())


@pytest.mark.parametrize(
    "mutate,frag",
    [
        (lambda b: b.__setitem__(slice(0, 4), b"gLTF"), "no 'glTF' header"),
        (lambda b: struct.pack_into("<I", b, 4, 1), "version 1"),
        (lambda b: struct.pack_into("<I", b, 8, len(b) + 4), "the header says"),
        (lambda b: struct.pack_into("<I", b, 12, 1 << 31), "runs past the end"),
        (lambda b: struct.pack_into("<I", b, 16, 0x004E4942), "first chunk must be JSON"),
    ],
)
def test_glb_header_lies(tmp_path, mutate, frag):
    b = _glb(tmp_path)
    mutate(b)
    (tmp_path / "bad.glb").write_bytes(bytes(b))
    with pytest.raises(EyevizError) as exc:
        load_eyes(tmp_path / "bad.glb")
    assert frag in _one_line(exc)


def test_glb_bin_chunk_shorter_than_its_buffer(tmp_path):
    b = _glb(tmp_path)
    (jlen,) = struct.unpack_from("<I", b, 12)
    pos = 20 + jlen
    struct.pack_into("<I", b, pos, 16)  # the BIN chunk now says 16 bytes
    b = b[: pos + 8 + 16]
    struct.pack_into("<I", b, 8, len(b))
    (tmp_path / "short.glb").write_bytes(bytes(b))
    with pytest.raises(EyevizError, match="byteLength says"):
        load_eyes(tmp_path / "short.glb")


HOSTILE_CLASSES = sorted(
    set(EYE_CASES)
    | set(GLTF_CASES)
    | {
        "eye: 10^8 rows (file byte bound, before reading)",
        "eye: row bound (lines counted before parsing)",
        "any: FIFO",
        "any: /dev/zero (a device)",
        "any: a folder",
        "any: unknown suffix",
        "gltf: NaN in an accessor",
        "gltf: buffer file symlinked out of the folder",
        "gltf: buffer file is a FIFO",
        "gltf: broken JSON",
        "gltf: JSON nested too deeply",
        "gltf: integer too long for JSON",
        "glb: bad magic",
        "glb: wrong version",
        "glb: header length lies",
        "glb: chunk length past the end",
        "glb: BIN chunk shorter than its buffer",
    }
)


def test_hostile_class_count():
    # the number the README's hostile-input table quotes
    assert len(HOSTILE_CLASSES) == 67, len(HOSTILE_CLASSES)
    assert np.all([":" in c for c in HOSTILE_CLASSES])
