"""The 3D figure's readout table has narrow columns for r and g: a huge ball (g = 100000,
r in the millions) is written in exponent form and stays inside its column (it ran into
the BFV column as '100000no')."""

from __future__ import annotations

import numpy as np

from eyeviz.measured import load_eyes, shipped_eye
from eyeviz.model.scene import loads
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.mpl.figure3d import readout_rows


def test_huge_r_and_g_fit_their_columns():
    pair = load_eyes(shipped_eye("BT_77973-real.eye"))
    balls = [(0.0, 5.0, -6.0, 0.4), (0.0, 2.5e6, -1.0e6, 1.0e5), (0.0, 500.0, 0.0, 123.5)]
    text = "[eyes]\nh = 40.0\nl = 20.0\nnside = 2\n" + "".join(
        f'[[features]]\nname = "b{i}"\nx = {x}\ny = {y}\nz = {z}\ng = {g}\n'
        for i, (x, y, z, g) in enumerate(balls)
    )
    sc = loads(text)
    x, y, z, g = (np.array(c, float) for c in zip(*balls, strict=True))
    r = np.sqrt(x * x + y * y + z * z)
    el = np.arctan2(z, np.hypot(x, y))
    st = SceneState3D(pair, x, y, z, g, r=r, azimuth=np.arctan2(y, x), elevation=el)
    rows = readout_rows(st, sc)
    assert [row[1] for row in rows] == ["7.81", "3e+06", "500"]
    assert [row[4] for row in rows] == ["0.4", "1e+05", "123.5"]
    assert all(len(row[1]) <= 5 and len(row[4]) <= 5 for row in rows)
