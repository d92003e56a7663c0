"""Drawing the spherical eyes allocates per lit facet, not per facet of the eye, and a
figure refuses an eye with more lit facets than it draws (issue 35, item 6: a whole-eye
ball at nside 1024 took a snapshot to 11.6 GB; at nside 16384 facet_owner made 12 GiB)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from eyeviz import cli
from eyeviz.model import shapes3d
from eyeviz.model.scene import loads
from eyeviz.model.state3d import compute_state3d

ROOT = Path(__file__).resolve().parents[2]


def _scene(nside: int, balls) -> str:
    text = f'title = "t"\n[eyes]\nh = 40.0\nl = 20.0\nnside = {nside}\n'
    for i, (x, y, z, g) in enumerate(balls):
        text += f'[[features]]\nname = "b{i}"\nx = {x}\ny = {y}\nz = {z}\ng = {g}\n'
    return text


def test_lit_owner_is_facet_owner_on_the_lit_facets():
    balls = [(0.0, 300.0, 0.0, 80.0), (30.0, 320.0, 20.0, 90.0), (-200.0, 400.0, -50.0, 40.0)]
    st = compute_state3d(loads(_scene(8, balls)))
    for eye in "AB":
        own = shapes3d.facet_owner(st, eye)
        pix, owner = shapes3d.lit_owner(st, eye)
        assert np.array_equal(pix, np.flatnonzero(own >= 0))
        assert np.array_equal(owner, own[pix])  # the last ball lighting a facet wins


def test_a_figure_refuses_more_lit_facets_than_its_bound(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(shapes3d, "MAX_DRAWN_FACETS", 50)
    scene = tmp_path / "s.toml"
    scene.write_text(_scene(8, [(0.0, 100.0, 0.0, 60.0)]))
    out = tmp_path / "s.png"
    rc = cli.main(["snapshot", str(scene), "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and err.strip().splitlines() == [
        "eyeviz: error: eye A has "
        + err.split("eye A has ")[1].split(" lit")[0]
        + " lit facets; a figure draws at most 50 per eye (MAX_DRAWN_FACETS): a smaller "
        "nside or smaller balls"
    ], err
    assert not out.exists()


_BIG_NSIDE = """
import resource, sys, tracemalloc
resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
from eyeviz.model.scene import loads
from eyeviz.model.state3d import compute_state3d
from eyeviz.render.mpl import perspective3d
text = sys.argv[1]
scene = loads(text)
st = compute_state3d(scene)
cam = perspective3d.default_camera(st)
tracemalloc.start()
perspective3d._eye_batches(st, scene, cam)
print(tracemalloc.get_traced_memory()[1])
"""


def test_the_view_at_nside_16384_allocates_per_lit_facet():
    """12 * 16384^2 = 3.2e9 facets an eye: an int32 per facet is 12 GiB, which the child's
    3 GiB address space refuses (MemoryError); per lit facet it is a few MB."""
    text = _scene(16384, [(0.0, 1500.0, 0.0, 1.0)])
    r = subprocess.run(
        [sys.executable, "-c", _BIG_NSIDE, text],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"},
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert int(r.stdout.split()[-1]) < 200 << 20
