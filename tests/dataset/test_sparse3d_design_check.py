"""A 3D data set whose lit sets are not its design's is refused on read (issues 35.9 and
36.2): a meta edited to h = 44 over lit sets of h = 40 was answered by limit3d with a DD
error of 9.2 %, and swapped eye A / eye B members (valid CRCs) scored ~100 % on every row,
silently. The reader re-computes a few rows' lit sets from their stored balls and the
design, for every file (nothing needs to be stored for that)."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from eyeviz import EyevizError, cli
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import sparse3d


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    p = tmp_path_factory.mktemp("d") / "h40.npz"
    sparse3d.write3d(p, 40, Domain3D(h=40.0, nside=8), seed=5)
    return p


def _rewrite(src, dst, rename=None, meta=None):
    """A copy of the zip with members renamed and/or the meta replaced: every CRC valid."""
    rename = rename or {}
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_STORED) as zout:
        for info in zin.infolist():
            data = zin.read(info.filename)
            name = rename.get(info.filename, info.filename)
            if name == "meta.npy" and meta is not None:
                import io

                buf = io.BytesIO()
                np.lib.format.write_array(buf, np.array(json.dumps(meta)), allow_pickle=False)
                data = buf.getvalue()
            zout.writestr(name, data)
    return dst


def _meta(path):
    with np.load(path, allow_pickle=False) as z:
        return json.loads(str(z["meta"][()]))


def test_an_edited_design_is_refused_naming_the_row(good, tmp_path):
    meta = _meta(good)
    meta["domain"]["h"] = 44.0
    bad = _rewrite(good, tmp_path / "h44.npz", meta=meta)
    with pytest.raises(EyevizError) as info:
        sparse3d.load3d(bad)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(f"{bad}: the lit sets do not match the file's")
    assert "h=44" in msg and "row 1: eye A lights" in msg


def test_swapped_eye_members_are_refused_as_swapped(good, tmp_path):
    swap = {}
    for what in ("indptr", "indices"):
        swap[f"{what}_a.npy"] = f"{what}_b.npy"
        swap[f"{what}_b.npy"] = f"{what}_a.npy"
    meta = _meta(good)
    meta["nnz_a"], meta["nnz_b"] = meta["nnz_b"], meta["nnz_a"]
    bad = _rewrite(good, tmp_path / "swapped.npz", rename=swap, meta=meta)
    with pytest.raises(
        EyevizError, match=r"row \d+: the file's eye A and eye B lit sets are swapped"
    ):
        sparse3d.load3d(bad)


def test_predict_refuses_an_edited_design_in_one_line(good, tmp_path, capsys):
    meta = _meta(good)
    meta["domain"]["h"] = 44.0
    bad = _rewrite(good, tmp_path / "h44.npz", meta=meta)
    out = tmp_path / "p.csv"
    rc = cli.main(["predict", "-e", "analytic3d", str(bad), "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "the lit sets do not match the file's design h=44" in err, err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


def test_the_untouched_file_reads(good):
    assert len(sparse3d.load3d(good)) == 40
