"""The spherical eyes' part of `eyeviz report stability` (eyeviz.reports.stability)."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.reference import stability_cases
from eyeviz.reports import stability


def test_every_class_builds_valid_balls():
    for name in stability_cases.CLASSES3D:
        cs = stability_cases.make(name, 5, seed=1, kind="spherical")
        assert cs.x.shape == cs.y.shape == cs.z.shape == cs.g.shape == (5,)
        assert np.all(np.isfinite([cs.x, cs.y, cs.z, cs.g])) and np.all(cs.g > 0)


@pytest.mark.slow
def test_equator_ties_are_on_the_plane_with_their_rims_on_vertices():
    cs = stability_cases.make("equator_ties", 6, seed=2, kind="spherical")
    assert np.all(cs.z == 0.0)
    row = stability.measure_case3d(cs)
    assert row.diffs["eyeviz core"] == 0
    assert row.exact + row.sampled > 0  # ties reach the core's slower stages


@pytest.mark.slow
def test_tiny_and_far_balls_match_the_reference():
    row = stability.measure_case3d(stability_cases.make("extreme", 3, seed=106, kind="spherical"))
    assert row.diffs["eyeviz core"] == 0


def test_report_files(tmp_path):
    rows = [stability.measure_case3d(stability_cases.make("poles", 2, seed=3, kind="spherical"))]
    stability.write3d(rows, tmp_path)
    md = (tmp_path / "stability3d.md").read_text()
    assert "| over a pole | 2 | 8 |" in md
    assert (tmp_path / "stability3d.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "stability3d.csv").read_text().count("\n") == 2
