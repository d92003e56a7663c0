"""A small, bounded glTF 2.0 container reader and writer (``.gltf`` and ``.glb``).

Only what a point cloud of float attributes needs: the JSON, buffers (a ``.glb``'s BIN
chunk, a ``data:`` URI in base64, or a file beside the ``.gltf``), buffer views (with or
without ``byteStride``), FLOAT accessors (SCALAR, VEC2-4), and the nodes' world transforms.
Nothing the file declares is trusted: every index, offset, length and count is checked
against the bytes that are really there, before any array is made; a buffer URI may only
name a regular file inside the glTF's own folder (symlinks followed); nothing is fetched.
Every refusal is one :class:`eyeviz.EyevizError` line naming the object.
"""

from __future__ import annotations

import base64
import binascii
import json
import math
import struct
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.files import limits
from eyeviz.files.untrusted import open_regular, read_regular, resolve_inside

__all__ = ["Gltf", "encode_gltf", "load_gltf"]

_GLB_MAGIC = b"glTF"
_JSON = 0x4E4F534A
_BIN = 0x004E4942
_FLOAT = 5126
_NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
_MAX_INT = 1 << 53


def _int(obj: dict, key: str, what: str, default=None, lo: int = 0, hi: int = _MAX_INT) -> int:
    v = obj.get(key, default)
    if v is None:
        raise EyevizError(f"{what}: {key} is missing")
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise EyevizError(f"{what}: {key} must be an integer in [{lo}, {hi}], got {v!r:.40}")
    return v


def _numbers(v, n: int, what: str) -> np.ndarray:
    ok = isinstance(v, list) and len(v) == n
    ok = ok and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
    a = np.array(v, dtype=np.float64) if ok else np.zeros(0)
    if not ok or not np.isfinite(a).all():
        raise EyevizError(f"{what}: expected {n} finite numbers")
    return a


class Gltf:
    """A parsed glTF: ``doc`` (the JSON) and bounded access to its buffers."""

    def __init__(self, doc: dict, folder: Path, name: str, glb_bin: bytes | None):
        self.doc, self.folder, self.name, self._glb_bin = doc, folder, name, glb_bin
        self._buffers: dict[int, bytes] = {}

    def fail(self, msg: str) -> EyevizError:
        return EyevizError(f"{self.name}: {msg}")

    def objects(self, key: str) -> list:
        v = self.doc.get(key, [])
        if not isinstance(v, list):
            raise self.fail(f"{key} must be a list")
        if len(v) > limits.MAX_GLTF_OBJECTS:
            raise self.fail(f"{len(v)} {key}, more than {limits.MAX_GLTF_OBJECTS}")
        return v

    def obj(self, key: str, i, what: str) -> dict:
        lst = self.objects(key)
        if isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < len(lst):
            raise self.fail(f"{what}: {key} index {i!r:.40} is not one of the {len(lst)} {key}")
        o = lst[i]
        if not isinstance(o, dict):
            raise self.fail(f"{key}[{i}] must be an object")
        return o

    # --- buffers -----------------------------------------------------------------------
    def buffer(self, i: int) -> bytes:
        if i in self._buffers:
            return self._buffers[i]
        b = self.obj("buffers", i, "buffer")
        what = f"{self.name}: buffers[{i}]"
        n = _int(b, "byteLength", what, lo=1, hi=limits.MAX_EYE_FILE_BYTES)
        uri = b.get("uri")
        if uri is None:
            if self._glb_bin is None or i != 0:
                raise EyevizError(f"{what}: no uri (only a .glb's first buffer may omit it)")
            data = self._glb_bin
        elif not isinstance(uri, str):
            raise EyevizError(f"{what}: uri must be a string")
        elif uri.startswith("data:"):
            head, sep, payload = uri.partition(",")
            if not sep or not head.endswith(";base64"):
                raise EyevizError(f"{what}: a data: uri must be base64 ('data:...;base64,')")
            try:
                data = base64.b64decode(payload, validate=True)
            except (binascii.Error, ValueError):
                raise EyevizError(f"{what}: the data: uri is not valid base64") from None
        else:
            path = resolve_inside(self.folder, uri, what)
            with open_regular(path, limits.MAX_EYE_FILE_BYTES, f"{what} file") as (f, _):
                data = f.read(n)  # only the bytes the buffer declares
        if len(data) < n:
            raise EyevizError(f"{what}: byteLength says {n} bytes, the data holds {len(data)}")
        self._buffers[i] = data[:n]
        return self._buffers[i]

    def accessor(self, i: int, types: tuple[str, ...], what: str) -> np.ndarray:
        """Accessor ``i`` as float64 (count, components); FLOAT of one of ``types``."""
        a = self.obj("accessors", i, what)
        w = f"{self.name}: {what}: accessors[{i}]"
        if a.get("sparse") is not None:
            raise EyevizError(f"{w}: sparse accessors are not supported")
        if a.get("componentType") != _FLOAT:
            raise EyevizError(f"{w}: componentType must be 5126 (FLOAT)")
        typ = a.get("type")
        if typ not in types:
            raise EyevizError(f"{w}: type must be {' or '.join(types)}, got {typ!r:.20}")
        k = _NCOMP[typ]
        count = _int(a, "count", w, lo=1, hi=limits.MAX_EYE_ROWS)
        if a.get("bufferView") is None:  # glTF: an accessor without a view is all zeros
            return np.zeros((count, k))
        vi = a["bufferView"]
        v = self.obj("bufferViews", vi, w)
        vw = f"{self.name}: bufferViews[{vi}]"
        off = _int(v, "byteOffset", vw, default=0)
        length = _int(v, "byteLength", vw, lo=1)
        stride = v.get("byteStride")
        elem = 4 * k
        if stride is not None:
            stride = _int(v, "byteStride", vw, lo=4, hi=252)
            if stride % 4 or stride < elem:
                raise EyevizError(f"{vw}: byteStride {stride} is not a multiple of 4 >= {elem}")
        else:
            stride = elem
        buf = self.buffer(_int(v, "buffer", vw))
        if off + length > len(buf):
            raise EyevizError(
                f"{vw}: bytes {off}..{off + length} lie beyond its buffer ({len(buf)} bytes)"
            )
        aoff = _int(a, "byteOffset", w, default=0)
        if aoff % 4 or off % 4:
            raise EyevizError(f"{w}: byte offsets must be multiples of 4")
        need = aoff + stride * (count - 1) + elem
        if need > length:
            raise EyevizError(
                f"{w}: {count} elements need {need} bytes, its bufferView has {length}"
            )
        arr = np.ndarray(
            (count, k), dtype="<f4", buffer=buf, offset=off + aoff, strides=(stride, 4)
        )
        out = arr.astype(np.float64)
        if not np.isfinite(out).all():
            row = int(np.flatnonzero(~np.isfinite(out).all(axis=1))[0])
            raise EyevizError(f"{w}: element {row} is not finite")
        return out

    # --- nodes -------------------------------------------------------------------------
    def node_matrix(self, i: int) -> np.ndarray:
        """The node's local 4x4 transform (matrix, or translation * rotation * scale)."""
        n = self.obj("nodes", i, "node")
        w = f"{self.name}: nodes[{i}]"
        if "matrix" in n:
            return _numbers(n["matrix"], 16, f"{w}: matrix").reshape(4, 4).T
        t = _numbers(n.get("translation", [0, 0, 0]), 3, f"{w}: translation")
        q = _numbers(n.get("rotation", [0, 0, 0, 1]), 4, f"{w}: rotation")
        s = _numbers(n.get("scale", [1, 1, 1]), 3, f"{w}: scale")
        nq = math.sqrt(float(q @ q))
        if nq == 0:
            raise EyevizError(f"{w}: rotation is a zero quaternion")
        x, y, z, ww = q / nq
        r = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * ww), 2 * (x * z + y * ww)],
                [2 * (x * y + z * ww), 1 - 2 * (x * x + z * z), 2 * (y * z - x * ww)],
                [2 * (x * z - y * ww), 2 * (y * z + x * ww), 1 - 2 * (x * x + y * y)],
            ]
        )
        m = np.eye(4)
        m[:3, :3] = r * s
        m[:3, 3] = t
        return m

    def parents(self) -> dict[int, int]:
        """node -> its parent; refuses a node with two parents and a cycle."""
        nodes = self.objects("nodes")
        parent: dict[int, int] = {}
        for i in range(len(nodes)):
            ch = self.obj("nodes", i, "node").get("children", [])
            if not isinstance(ch, list):
                raise self.fail(f"nodes[{i}]: children must be a list")
            for c in ch:
                self.obj("nodes", c, f"nodes[{i}] child")
                if c in parent or c == i:
                    raise self.fail(f"nodes[{c}] has two parents or is its own child")
                parent[c] = i
        for i in parent:  # a cycle: walking up never ends
            seen, j = set(), i
            while j in parent:
                if j in seen:
                    raise self.fail(f"the nodes' children form a cycle (through nodes[{j}])")
                seen.add(j)
                j = parent[j]
        return parent

    def world_matrix(self, i: int, parent: dict[int, int]) -> np.ndarray:
        m = self.node_matrix(i)
        while i in parent:
            i = parent[i]
            m = self.node_matrix(i) @ m
        return m


def _load_json(text: bytes, name: str) -> dict:
    try:
        doc = json.loads(text.decode("utf-8-sig"))
    except RecursionError:
        raise EyevizError(f"{name}: the JSON is nested too deeply") from None
    except (UnicodeDecodeError, ValueError) as exc:
        raise EyevizError(f"{name}: not valid glTF JSON ({str(exc)[:120]})") from None
    if not isinstance(doc, dict):
        raise EyevizError(f"{name}: the glTF JSON must be an object")
    asset = doc.get("asset")
    if not isinstance(asset, dict) or not str(asset.get("version", "")).startswith("2."):
        raise EyevizError(f"{name}: not glTF 2.0 (asset.version must be '2.x')")
    return doc


def _split_glb(data: bytes, name: str) -> tuple[bytes, bytes | None]:
    if len(data) < 20 or data[:4] != _GLB_MAGIC:
        raise EyevizError(f"{name}: not a binary glTF (no 'glTF' header)")
    version, length = struct.unpack_from("<II", data, 4)
    if version != 2:
        raise EyevizError(f"{name}: binary glTF version {version}, expected 2")
    if length != len(data):
        raise EyevizError(f"{name}: the header says {length} bytes, the file has {len(data)}")
    pos, chunks = 12, []
    while pos < length:
        if pos + 8 > length:
            raise EyevizError(f"{name}: a chunk header runs past the end of the file")
        clen, ctype = struct.unpack_from("<II", data, pos)
        if pos + 8 + clen > length:
            raise EyevizError(f"{name}: a chunk of {clen} bytes runs past the end of the file")
        chunks.append((ctype, data[pos + 8 : pos + 8 + clen]))
        pos += 8 + clen
    if not chunks or chunks[0][0] != _JSON:
        raise EyevizError(f"{name}: the first chunk must be JSON")
    if len(chunks[0][1]) > limits.MAX_GLTF_JSON_BYTES:
        raise EyevizError(f"{name}: the JSON chunk is larger than {limits.MAX_GLTF_JSON_BYTES}")
    binary = chunks[1][1] if len(chunks) > 1 and chunks[1][0] == _BIN else None
    return chunks[0][1], binary


def load_gltf(path) -> Gltf:
    """Parse a ``.gltf`` or ``.glb`` (bounded; buffers are read when first used)."""
    p = Path(path)
    if p.suffix.lower() == ".glb":
        data = read_regular(p, limits.MAX_EYE_FILE_BYTES, "glTF file")
        text, binary = _split_glb(data, p.name)
    else:
        text, binary = read_regular(p, limits.MAX_GLTF_JSON_BYTES, "glTF file"), None
    return Gltf(_load_json(text, p.name), p.parent, p.name, binary)


def encode_gltf(doc: dict, blob: bytes, binary: bool) -> bytes:
    """The bytes of a ``.glb`` (JSON and BIN chunks) or of a ``.gltf`` whose one buffer
    is a base64 ``data:`` URI; ``doc`` gets its ``buffers`` here."""
    doc = dict(doc)
    if binary:
        doc["buffers"] = [{"byteLength": len(blob)}]
        js = json.dumps(doc, separators=(",", ":")).encode()
        js += b" " * (-len(js) % 4)
        bn = blob + b"\0" * (-len(blob) % 4)
        total = 12 + 8 + len(js) + 8 + len(bn)
        return b"".join(
            [
                struct.pack("<4sII", _GLB_MAGIC, 2, total),
                struct.pack("<II", len(js), _JSON),
                js,
                struct.pack("<II", len(bn), _BIN),
                bn,
            ]
        )
    uri = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    doc["buffers"] = [{"byteLength": len(blob), "uri": uri}]
    return (json.dumps(doc, indent=1) + "\n").encode()
