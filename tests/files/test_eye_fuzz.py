"""Random damage to OCES and .eye files: every failure is one EyevizError line, never
another exception (a TypeError from a list where a number belongs, a KeyError, ...)."""

from __future__ import annotations

import copy
import json
import random

import pytest

from eyeviz import EyevizError
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured_from import as_measured
from eyeviz.measured import load_eyes, save_eyes

pytestmark = pytest.mark.filterwarnings("ignore::eyeviz.measured.EyeSizeWarning")

ODD = [None, True, -1, 0, 1, 2**64, 1.5, float("inf"), "x", "", [], [1], [0, 0, 0], {}, {"a": 1}]


def _paths(o, prefix=()):
    yield prefix
    if isinstance(o, dict):
        for k, v in o.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(o, list):
        for i, v in enumerate(o[:6]):
            yield from _paths(v, (*prefix, i))


def _mutated(doc, rng):
    d = json.loads(json.dumps(doc))
    paths = [p for p in _paths(d) if p and p[-1] != "uri"]
    for _ in range(rng.randint(1, 3)):
        path = rng.choice(paths)
        o = d
        try:
            for k in path[:-1]:
                o = o[k]
            o[path[-1]] = copy.deepcopy(rng.choice(ODD))
        except (KeyError, IndexError, TypeError):
            pass
    return d


def test_random_json_damage(tmp_path):
    save_eyes(as_measured(EyePair3D(40, 20, 2)), tmp_path / "ok.gltf")
    doc = json.loads((tmp_path / "ok.gltf").read_text())
    doc["extensions"]["OCES_eyes"]["mirrorPlanes"] = [{"normal": "X"}]
    doc["nodes"][0]["scale"] = [1, 1, 1]
    doc["nodes"][1]["extensions"]["OCES_eyes"]["mirrorPlanes"] = [0]
    doc["nodes"][2]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    doc["extensions"]["OCES_eyes"]["eyes"][0]["mirrorPlanes"] = [0]
    rng = random.Random(11)
    refused = 0
    for i in range(600):
        p = tmp_path / f"m{i % 5}.gltf"
        p.write_text(json.dumps(_mutated(doc, rng), allow_nan=True))
        try:
            load_eyes(p)
        except EyevizError as exc:
            assert "\n" not in str(exc)
            refused += 1
    assert refused > 100  # most damage is noticed


@pytest.mark.parametrize("suffix", [".glb", ".eye"])
def test_random_byte_damage(tmp_path, suffix):
    save_eyes(as_measured(EyePair3D(40, 20, 2)), tmp_path / f"ok{suffix}")
    data = (tmp_path / f"ok{suffix}").read_bytes()
    rng = random.Random(5)
    for i in range(300):
        b = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        if rng.random() < 0.2:
            b = b[: rng.randrange(len(b))]
        p = tmp_path / f"m{i % 5}{suffix}"
        p.write_bytes(bytes(b))
        try:
            load_eyes(p)
        except EyevizError as exc:
            assert "\n" not in str(exc)
