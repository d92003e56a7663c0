"""Model directories (compact: compact.json + two .pt files; bayes: one .npz): mutated
files give an estimator that predicts, or one error line; the loader never unpickles.

Each example's outcome is recorded (ok, refused, or ``bug: <stage>: <exception type>``)
and the last test of the file fails while any bug was seen: a refusal must be one
EyevizError line, and a loader's refusal must name the file it is about."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from eyeviz import EyevizError, estimators
from eyeviz import dataset as D

from .conftest import assert_one_line, count, digest, fuzz_settings
from .test_dataset_fuzz import mutated

MODELS = Path(__file__).resolve().parents[2] / "assets" / "models"
ROWS = D.generate(8, seed=4)


def _predicts(est) -> tuple:
    pred = est.predict(ROWS.omega_a, ROWS.omega_b)
    assert np.shape(pred.r) == (8,) and np.shape(pred.phi) == (8,)
    return np.asarray(pred.r), np.asarray(pred.phi)


# test_no_*_bugs reads what this module's other tests recorded in BUGS: under
# pytest-xdist (--dist loadgroup) the whole module runs on one worker, in order
pytestmark = pytest.mark.xdist_group("fuzz_models")
BUGS: dict[str, int] = {}


_REF: dict[str, tuple] = {}


def _reference(name: str) -> tuple:
    """The shipped model's prediction of ROWS (what an intact file must still give)."""
    if name not in _REF:
        _REF[name] = _predicts(estimators.load(name))
    return _REF[name]


def _try_load(
    name: str, category: str, names: tuple[str, ...] = (), exact: bool = False, **kw
) -> None:
    """Load then predict; a refusal must be one EyevizError line, and a refusal by the
    loader must name the file (one of ``names``) it is about. With ``exact`` (the bytes
    of a weights file were mutated), a model that loads must predict exactly what the
    shipped one does: a changed weight is refused, never used."""
    stage = "load"
    try:
        est = estimators.load(name, **kw)
        stage = "predict"
        pred = _predicts(est)
    except EyevizError as exc:
        msg = str(exc)
        if "\n" in msg.strip() or len(msg) >= 1000:
            _bug(category, "multi-line message")
            return
        assert_one_line(msg)
        if stage == "load" and names and not any(n in msg for n in names):
            _bug(category, f"message names no file: {msg[:80]}")
            return
        count(category, "refused")
        return
    except Exception as exc:  # noqa: BLE001 - recorded, asserted in test_no_loader_bugs
        _bug(category, f"{stage}: {type(exc).__name__}")
        return
    if exact and not all(np.array_equal(a, b) for a, b in zip(pred, _reference(name), strict=True)):
        _bug(category, "silently different predictions")
        return
    count(category, "ok")


def _bug(category: str, what: str) -> None:
    count(category, f"bug: {what}")
    BUGS[f"{category}: {what}"] = BUGS.get(f"{category}: {what}", 0) + 1


JSON_VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**64), 2**64),
    st.floats(allow_nan=True),
    st.text(max_size=8),
    st.lists(st.integers(0, 10), max_size=3),
    st.just({}),
)


@st.composite
def compact_meta(draw):
    meta = json.loads((MODELS / "compact.json").read_text())
    for _ in range(draw(st.integers(1, 3))):
        sect = draw(st.sampled_from(["top", "files", "data"]))
        tab = meta if sect == "top" else meta.setdefault(sect, {})
        if not isinstance(tab, dict):
            break
        keys = list(tab) or ["x"]
        k = draw(st.sampled_from(keys))
        if draw(st.booleans()):
            tab.pop(k, None)
        else:
            tab[k] = draw(JSON_VALUES)
    return meta


def _compact_dir(tmp: Path) -> Path:
    d = tmp / "m"
    d.mkdir()
    for f in ("compact.json", "compact_dd.pt", "compact_ad.pt"):
        shutil.copy(MODELS / f, d / f)
    return d


@fuzz_settings(120)
@given(compact_meta())
def test_compact_json(tmp_path_factory, meta):
    d = _compact_dir(tmp_path_factory.mktemp("cj"))
    (d / "compact.json").write_text(json.dumps(meta))
    _try_load("compact", "models: compact.json", ("compact.json", ".pt"), path=d)


@fuzz_settings(120)
@given(st.sampled_from(["compact_dd.pt", "compact_ad.pt"]), st.data())
def test_compact_weights_bytes(tmp_path_factory, which, data):
    d = _compact_dir(tmp_path_factory.mktemp("cw"))
    blob = data.draw(mutated((MODELS / which).read_bytes()))
    (d / which).write_bytes(blob)
    before = digest(d / which)
    _try_load("compact", "models: compact .pt bytes", (which,), exact=True, path=d)
    assert digest(d / which) == before


@fuzz_settings(60)
@given(st.data())
def test_bayes_table_bytes(tmp_path_factory, data):
    src = (MODELS / "bayes.npz").read_bytes()
    # mutations near the zip directory and member headers (the end and the start)
    region = data.draw(st.sampled_from([(0.0, 0.001), (0.999, 1.0), (0.0, 1.0)]))
    blob = data.draw(mutated(src, region=region))
    p = tmp_path_factory.mktemp("b") / "bayes.npz"
    p.write_bytes(blob)
    _try_load("bayes", "models: bayes.npz bytes", ("bayes.npz",), exact=True, path=p)


def test_no_loader_bugs():
    assert not BUGS, BUGS
