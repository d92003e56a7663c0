"""OCES eyes: glTF 2.0 with the ``OCES_eyes`` extension, ``POINT_OMMATIDIAL`` eyes
(Open Compound Eye Standard, draft 0.4.0; docs/eye_files.md).

The extension's root object lists ``ommatidialProperties`` (each an ``ACCESSOR`` of
per-ommatidium values or a ``COARSE`` value for all), ``eyes`` (a ``POINT_OMMATIDIAL`` eye
names its POSITION VEC3, ORIENTATION VEC3, DIAMETER SCALAR and FOCAL_OFFSET SCALAR, or
VEC3 in the ommatidium's U, V, W frame, among them) and ``mirrorPlanes``. Nodes attach
eyes (``{"eye": i}``) and heads (``{"head": true}``). Lengths are in metres. A missing
property takes the specification's default (POSITION [0,0,0], ORIENTATION [0,0,1],
DIAMETER 1, FOCAL_OFFSET -1).

The sampling cone of an ommatidium has its tip at W = FOCAL_OFFSET (< 0) behind the lens
and passes the lens's rim, so its full acceptance angle is 2 atan((DIAMETER / 2) / -W)
(the specification's W = lens radius / tan(acceptance / 2)). Sheared cones (U or V
non-zero) are refused.

Eyes are placed by their nodes' world transforms (rotations, translations and uniform
scales; a non-uniform scale would not keep a cone a cone and is refused); an eye with
mirror planes (on the eye or on its node, in its head's frame) gives its mirror image as
well. The file must come to two eyes, or to one eye holding both (split at x = 0 as
``.eye`` files are). Without nodes naming eyes, the extension's eyes are taken as they are.
"""

from __future__ import annotations

import datetime
import math

import numpy as np

from eyeviz import __version__
from eyeviz.files.eye_frames import Frame
from eyeviz.files.gltf import Gltf, encode_gltf, load_gltf

__all__ = ["read_oces", "encode_oces"]

_DEFAULTS = {"POSITION": [0.0, 0.0, 0.0], "ORIENTATION": [0.0, 0.0, 1.0], "DIAMETER": 1.0}
_DEFAULTS["FOCAL_OFFSET"] = -1.0
_TYPES: dict[str, tuple[str, ...]] = {
    "POSITION": ("VEC3",),
    "ORIENTATION": ("VEC3",),
    "DIAMETER": ("SCALAR",),
}
_TYPES["FOCAL_OFFSET"] = ("SCALAR", "VEC3")
_AXES = {
    **dict.fromkeys(("X", "FRONTAL", "LEFT", "RIGHT"), (1.0, 0.0, 0.0)),
    **dict.fromkeys(("Y", "TRANSVERSE", "DORSOVENTRAL", "UP", "DOWN"), (0.0, 1.0, 0.0)),
    **dict.fromkeys(
        (
            "Z",
            "SAGITTAL",
            "ANTERIOR",
            "POSTERIOR",
            "ANTEPOSTERIOR",
            "ANTEROPOSTERIOR",
            "FORWARD",
            "BACKWARD",
            "FRONT",
            "BACK",
        ),
        (0.0, 0.0, 1.0),
    ),
}


def _ext(obj) -> dict | None:
    e = obj.get("extensions") if isinstance(obj, dict) else None
    o = e.get("OCES_eyes") if isinstance(e, dict) else None
    return o if isinstance(o, dict) else None


def _property(g: Gltf, root: dict, eye: dict, key: str, what: str):
    """(per-ommatidium array (n, k), or None) and (coarse value array, or None)."""
    refs = eye.get("ommatidialProperties", {})
    if not isinstance(refs, dict):
        raise g.fail(f"{what}: ommatidialProperties must be an object")
    if key not in refs:
        return None, np.atleast_1d(np.array(_DEFAULTS[key], dtype=np.float64))
    props = root.get("ommatidialProperties", [])
    i = refs[key]
    if not isinstance(props, list) or isinstance(i, bool) or not isinstance(i, int):
        raise g.fail(f"{what}: {key} must index the extension's ommatidialProperties")
    if not 0 <= i < len(props) or not isinstance(props[i], dict):
        raise g.fail(f"{what}: {key} names ommatidialProperties[{i}], which does not exist")
    p = props[i]
    w = f"{what}: {key} (ommatidialProperties[{i}])"
    if p.get("type") == "COARSE":
        v = p.get("value")
        vals = v if isinstance(v, list) else [v]
        ok = all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in vals)
        arr = np.array(vals, dtype=np.float64) if ok and vals else np.zeros(0)
        if arr.size not in (1, 3) or not np.isfinite(arr).all():
            raise g.fail(f"{w}: a COARSE value must be 1 or 3 finite numbers")
        return None, arr
    if p.get("type") != "ACCESSOR":
        raise g.fail(f"{w}: type {p.get('type')!r:.20} is not supported (ACCESSOR or COARSE)")
    if p.get("dataStride", 1) != 1:
        raise g.fail(f"{w}: dataStride must be 1")
    return g.accessor(p.get("value"), _TYPES[key], w), None


def _eye_arrays(
    g: Gltf, root: dict, k: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(pos, axes, diameter, W) of eye k in its own frame (file units)."""
    eyes = root.get("eyes")
    what = f"OCES eye {k}"
    if not isinstance(eyes, list) or not 0 <= k < len(eyes) or not isinstance(eyes[k], dict):
        raise g.fail(f"{what} does not exist")
    eye = eyes[k]
    got = {key: _property(g, root, eye, key, what) for key in _DEFAULTS}
    counts = {key: a.shape[0] for key, (a, _) in got.items() if a is not None}
    if not counts:
        raise g.fail(f"{what}: no property is an ACCESSOR: the number of ommatidia is unknown")
    if len(set(counts.values())) > 1:
        raise g.fail(f"{what}: its accessors disagree on the number of ommatidia: {counts}")
    n = next(iter(counts.values()))
    out = {}
    for key, (a, c) in got.items():
        out[key] = a if a is not None else np.broadcast_to(c, (n, c.size)).copy()
    fo = out["FOCAL_OFFSET"]
    if fo.shape[1] == 3:
        if (fo[:, :2] != 0).any():
            raise g.fail(
                f"{what}: sheared sampling cones (FOCAL_OFFSET U, V != 0) are not supported"
            )
        fo = fo[:, 2:]
    for key, shape in (("POSITION", 3), ("ORIENTATION", 3), ("DIAMETER", 1)):
        if out[key].shape[1] != shape:
            raise g.fail(f"{what}: {key} must have {shape} numbers per ommatidium")
    return out["POSITION"], out["ORIENTATION"], out["DIAMETER"][:, 0], fo[:, 0]


def _indices(g: Gltf, v, what: str) -> list[int]:
    """A list of mirror plane indices (None: none)."""
    if v is None:
        return []
    if not isinstance(v, list) or not all(
        isinstance(i, int) and not isinstance(i, bool) for i in v
    ):
        raise g.fail(f"{what}: mirrorPlanes must be a list of indices")
    return v


def _plane(g: Gltf, root: dict, i, what: str) -> tuple[np.ndarray, np.ndarray]:
    planes = root.get("mirrorPlanes", [])
    if isinstance(i, bool) or not isinstance(i, int) or not isinstance(planes, list):
        raise g.fail(f"{what}: mirror plane index {i!r:.20} is not valid")
    if not 0 <= i < len(planes) or not isinstance(planes[i], dict):
        raise g.fail(f"{what}: mirror plane {i} does not exist")
    p = planes[i]
    q = p.get("position", [0, 0, 0])
    nrm = p.get("normal", p.get("type", [1, 0, 0]))
    if isinstance(nrm, str):
        if nrm.upper() not in _AXES:
            raise g.fail(f"{what}: mirror plane {i}: unknown normal {nrm!r:.30}")
        nrm = list(_AXES[nrm.upper()])
    try:
        qa = np.array(q, dtype=np.float64).reshape(3)
        na = np.array(nrm, dtype=np.float64).reshape(3)
    except (TypeError, ValueError):
        raise g.fail(f"{what}: mirror plane {i}: position and normal must be 3 numbers") from None
    norm = float(np.linalg.norm(na))
    if not (np.isfinite(qa).all() and math.isfinite(norm) and norm > 0):
        raise g.fail(f"{what}: mirror plane {i}: needs a finite point and a non-zero normal")
    return qa, na / norm


def _similarity(g: Gltf, m: np.ndarray, what: str) -> float:
    """The uniform scale of a world transform's linear part (refuses anything else)."""
    lin = m[:3, :3]
    gram = lin.T @ lin
    s2 = float(np.trace(gram) / 3)
    if not (s2 > 0 and np.allclose(gram, s2 * np.eye(3), rtol=1e-6, atol=1e-12 * s2)):
        raise g.fail(f"{what}: its node transform is not a rotation with a uniform scale")
    if not np.allclose(m[3], [0, 0, 0, 1]):
        raise g.fail(f"{what}: its node transform is not affine")
    return math.sqrt(s2)


def _place(pos, ax, dia, w, m: np.ndarray, s: float):
    if np.array_equal(m, np.eye(4)):
        return pos, ax, dia, w
    return pos @ m[:3, :3].T + m[:3, 3], ax @ m[:3, :3].T, dia * s, w * s


def _mirror(pos, ax, q, n):
    d = (pos - q) @ n
    return pos - 2 * d[:, None] * n, ax - 2 * (ax @ n)[:, None] * n


def _instances(g: Gltf, root: dict) -> list[tuple[np.ndarray, ...]]:
    """Every POINT_OMMATIDIAL eye placed in the scene: (pos, axes, dia, W) in file units."""
    eyes = root.get("eyes")
    if not isinstance(eyes, list) or not eyes:
        raise g.fail("the OCES_eyes extension lists no eyes")
    nodes = g.objects("nodes")
    refs = []
    for i in range(len(nodes)):
        e = _ext(g.obj("nodes", i, "node"))
        if e is not None and "eye" in e and e.get("enabled", True) is not False:
            refs.append(i)
    parent = g.parents() if refs else {}
    placed = []
    todo = refs if refs else [None] * len(eyes)
    for j, ni in enumerate(todo):
        node = g.obj("nodes", ni, "node") if ni is not None else {}
        k = _ext(node)["eye"] if ni is not None else j  # type: ignore[index]
        if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < len(eyes):
            raise g.fail(f"nodes[{ni}]: eye {k!r:.20} is not one of the {len(eyes)} OCES eyes")
        eye = eyes[k] if isinstance(eyes[k], dict) else {}
        if eye.get("type") != "POINT_OMMATIDIAL" or eye.get("enabled", True) is False:
            continue
        what = f"OCES eye {k}"
        m = g.world_matrix(ni, parent) if ni is not None else np.eye(4)
        arrays = _place(*_eye_arrays(g, root, k), m, _similarity(g, m, what))
        placed.append(arrays)
        planes = _indices(g, eye.get("mirrorPlanes"), what) + _indices(
            g, (_ext(node) or {}).get("mirrorPlanes"), what
        )
        head = ni
        while head is not None and not (_ext(g.obj("nodes", head, "node")) or {}).get("head"):
            head = parent.get(head)
        hm = g.world_matrix(head, parent) if head is not None else np.eye(4)
        hs = _similarity(g, hm, f"{what}'s head")
        for pi in dict.fromkeys(planes):
            q, n = _plane(g, root, pi, what)
            qw, nw = hm[:3, :3] @ q + hm[:3, 3], hm[:3, :3] @ n / hs
            mp, ma = _mirror(arrays[0], arrays[1], qw, nw)
            placed.append((mp, ma, arrays[2], arrays[3]))
    if not placed:
        raise g.fail("no enabled POINT_OMMATIDIAL eye (surface and spherical eyes are not read)")
    return placed


def _acceptance(g: Gltf, dia: np.ndarray, w: np.ndarray, what: str) -> np.ndarray:
    bad = ~((dia > 0) & (w < 0))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise g.fail(
            f"{what}: ommatidium {i}: DIAMETER must be > 0 and FOCAL_OFFSET < 0 (behind the "
            f"lens), got {dia[i]!r} and {w[i]!r}"
        )
    return 2 * np.arctan2(dia / 2, -w)


def read_oces(path, frame: Frame, scale: float):
    """The two eyes of an OCES file as ((pos, axes, acc, fo) of A, of B) in eyeviz's
    frame and mm (``fo`` = -W, the focal offset in the ``.eye`` sense)."""
    g = load_gltf(path)
    root = _ext(g.doc)
    if root is None:
        raise g.fail("not an OCES file: the glTF has no OCES_eyes extension")
    eyes = []
    for k, (pos, ax, dia, w) in enumerate(_instances(g, root)):
        acc = _acceptance(g, dia, w, f"eye {k}")
        eyes.append((frame.to_eyeviz(pos) * scale, frame.to_eyeviz(ax), acc, -w * scale))
    if len(eyes) == 1:
        pos, ax, acc, fo = eyes[0]
        a = pos[:, 0] < 0
        if a.all() or not a.any():
            raise g.fail("one eye with every lens on one side of x = 0: not a pair")
        return tuple((pos[s], ax[s], acc[s], fo[s]) for s in (a, ~a))
    if len(eyes) != 2:
        raise g.fail(f"{len(eyes)} eyes; eyeviz reads a pair (two eyes)")
    eyes.sort(key=lambda e: float(e[0][:, 0].mean()))
    return tuple(eyes)


def _nominal_diameter(pos: np.ndarray) -> float:
    """A lens diameter for facets without a focal offset: the eye's size / sqrt(n)."""
    size = float(np.linalg.norm(pos - pos.mean(axis=0), axis=1).max()) if len(pos) else 0.0
    d = 2 * size / math.sqrt(max(len(pos), 1))
    return d if d > 0 else 1e-6


def encode_oces(eyes, frame: Frame, scale: float, binary: bool, name: str) -> bytes:
    """The bytes of an OCES ``.gltf`` (one file, buffer in a data: URI) or ``.glb``.

    Per eye: POSITION, ORIENTATION (unit), DIAMETER and FOCAL_OFFSET (W = -fo, the lens
    diameter 2 fo tan(acc / 2)); a facet without a positive focal offset gets a nominal
    diameter and the W that keeps its acceptance angle."""
    blob = bytearray()
    views: list[dict] = []
    accessors: list[dict] = []
    props: list[dict] = []
    oces_eyes: list[dict] = []

    def add(arr: np.ndarray, typ: str) -> int:
        a = np.ascontiguousarray(arr, dtype="<f4")
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": a.nbytes})
        blob.extend(a.tobytes())
        acc = {"bufferView": len(views) - 1, "componentType": 5126, "count": len(a), "type": typ}
        if typ == "VEC3":
            acc["min"] = a.min(axis=0).astype(float).tolist()
            acc["max"] = a.max(axis=0).astype(float).tolist()
        accessors.append(acc)
        props.append({"type": "ACCESSOR", "value": len(accessors) - 1})
        return len(props) - 1

    for label, (pos, ax, acc, fo) in zip(("A", "B"), eyes, strict=True):
        p = frame.from_eyeviz(np.asarray(pos, np.float64)) / scale
        a = frame.from_eyeviz(np.asarray(ax, np.float64))
        a = a / np.linalg.norm(a, axis=1)[:, None]
        acc = np.asarray(acc, np.float64)
        f = np.zeros(len(acc)) if fo is None else np.asarray(fo, np.float64) / scale
        t = np.tan(acc / 2)
        d_nom = _nominal_diameter(p)
        use = f > 0
        dia = np.where(use, 2 * f * t, d_nom)
        w = np.where(use, -f, -(d_nom / 2) / t)
        refs = {
            "POSITION": add(p, "VEC3"),
            "ORIENTATION": add(a, "VEC3"),
            "DIAMETER": add(dia, "SCALAR"),
            "FOCAL_OFFSET": add(w, "SCALAR"),
        }
        oces_eyes.append(
            {
                "name": f"{name} eye {label}",
                "type": "POINT_OMMATIDIAL",
                "ommatidialProperties": refs,
            }
        )
    now = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
    doc = {
        "asset": {"version": "2.0", "generator": f"eyeviz {__version__}"},
        "extensionsUsed": ["OCES_eyes"],
        "scene": 0,
        "scenes": [{"name": name, "nodes": [0]}],
        "nodes": [
            {"name": "head", "children": [1, 2], "extensions": {"OCES_eyes": {"head": True}}},
            {"name": "eye A", "extensions": {"OCES_eyes": {"eye": 0}}},
            {"name": "eye B", "extensions": {"OCES_eyes": {"eye": 1}}},
        ],
        "accessors": accessors,
        "bufferViews": views,
        "extensions": {
            "OCES_eyes": {
                "version": "0.4.0",
                "generator": {"program": "eyeviz", "version": __version__},
                "creationDatetime": now,
                "ommatidialProperties": props,
                "eyes": oces_eyes,
            }
        },
    }
    return encode_gltf(doc, bytes(blob), binary)
