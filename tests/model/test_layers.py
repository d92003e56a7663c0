"""The layer table (eyeviz.model.layers) and predictions computed once (issue 20 items 1-2).

The table is the one list of layers: the scene file accepts exactly its names, every hook
it names resolves, the state computes what the shown layers' entries say they need, and a
scene's predictions are computed by one function (eyeviz.model.predictor.
scene_predictions) once per frame, whether the app model, build_frame or the exported
figure asks.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from eyeviz.model import frame as frame_mod
from eyeviz.model import layers
from eyeviz.model import predictor as predictor_mod
from eyeviz.model.app_model import AppModel
from eyeviz.model.frame import build_frame
from eyeviz.model.layers import LayerSpec, layer_names, register_layer, unregister_layer
from eyeviz.model.predictor import Predictor, scene_predictions
from eyeviz.model.scene import Eyes, Feature, Scene, SceneError, loads
from eyeviz.model.state import compute_state

SHIPPED = (
    "eyes",
    "bfv",
    "features",
    "bitmaps",
    "readout",
    "tangents",
    "sectors",
    "labels",
    "predictions",
    "ambiguity",
    "posterior",
    "trajectory",
)

SCENE = """
[eyes]
h = 40.0
l = 20.0
m = 720

[[features]]
name = "a"
x = 100.0
y = 2000.0
g = 50.0

[layers]
show = {show}
"""


def _toml(names) -> str:
    return SCENE.format(show="[" + ", ".join(f'"{n}"' for n in names) + "]")


# --- (b) the table covers every layer the scene accepts, and only those ------------------


def test_the_scene_file_accepts_exactly_the_tables_layers():
    assert layer_names("planar") == SHIPPED  # the shipped layers, in the panel's order
    for name in layer_names("planar"):
        assert loads(_toml([name])).layers == [name]
    with pytest.raises(SceneError, match=r"layers.show: unknown layer 'wobble' \(known: eyes"):
        loads(_toml(["eyes", "wobble"]))
    for name in ("plane", "cones", "responses"):  # the spherical side's own: not planar
        with pytest.raises(SceneError, match=f"unknown layer '{name}'"):
            loads(_toml([name]))


def test_each_layer_states_the_eye_models_it_applies_to():
    """The table says which models a layer applies to (issue 37.2); the spherical scene's
    layers, its planar-only refusals and the 3D menu's per-model layers are read from it."""
    from eyeviz.model.scene import LAYER_KINDS, SPHERICAL_LAYERS, SPHERICAL_ONLY

    space = set(layer_names("spherical")) | set(layer_names("measured"))
    assert set(SPHERICAL_LAYERS) == space and len(SPHERICAL_LAYERS) == len(space)
    assert SPHERICAL_ONLY == ("plane", "cones", "responses")
    assert LAYER_KINDS == {"predictions": ("spherical",), "cones": ("measured",)}
    assert not layers.applies("sectors", "spherical") and layers.applies("cones", "measured")
    assert not layers.applies("cones", "spherical") and not layers.applies("wobble", "planar")
    with pytest.raises(ValueError, match="kinds must be among planar, spherical, measured"):
        LayerSpec("odd", "a layer of this test", kinds=("toy",))
    with pytest.raises(ValueError, match="kinds must be among"):
        LayerSpec("odd", "a layer of this test", kinds=())
    # the 3D view's painters come from the table, in their draw order
    names = [s.name for s in layers.ordered("vtk3d")]
    assert names == ["bfv", "eyes", "features", "cones"]


def test_a_registered_layer_is_a_scene_layer_until_it_is_removed():
    with pytest.raises(SceneError, match="unknown layer 'extra'"):
        loads(_toml(["extra"]))
    register_layer(LayerSpec("extra", "a layer of this test"))
    try:
        assert loads(_toml(["eyes", "extra"])).layers == ["eyes", "extra"]
        with pytest.raises(ValueError, match="already registered"):
            register_layer(LayerSpec("extra", "twice"))
    finally:
        unregister_layer("extra")
    with pytest.raises(SceneError, match="unknown layer 'extra'"):
        loads(_toml(["extra"]))


def test_every_hook_of_the_table_resolves_to_a_callable():
    for spec in layers.LAYERS:
        for hook in ("frame", "mpl", "vtk", "vtk3d"):
            ref = getattr(spec, hook)
            if ref is not None:
                assert callable(layers.resolve(ref)), (spec.name, hook)
    # the Qt panels draw these in the app: no VTK painter, a matplotlib one
    planar = [s for s in layers.LAYERS if "planar" in s.kinds]
    assert {s.name for s in planar if s.vtk is None} == {"bitmaps", "readout"}
    assert all(s.mpl is not None for s in planar)


@pytest.mark.parametrize(
    "bad, words",
    [
        (dict(name="two words", help="x"), "name must be an identifier"),
        (dict(name="a", help=""), "help must be one non-empty line"),
        (dict(name="a", help="x\ny"), "help must be one non-empty line"),
        (dict(name="a", help="x", needs=frozenset({"pixels"})), "needs must be among"),
        (dict(name="a", help="x", vtk_stage="later"), "vtk_stage must be"),
    ],
)
def test_a_bad_entry_is_refused_naming_the_field(bad, words):
    with pytest.raises(ValueError, match=words):
        LayerSpec(**bad)


def test_a_hook_must_name_module_and_attribute():
    with pytest.raises(ValueError, match="'package.module:attribute', got 'nocolon'"):
        layers.resolve("nocolon")
    with pytest.raises(ValueError, match="no such hook"):
        layers.resolve(None)


@pytest.mark.parametrize("name", SHIPPED)
def test_the_state_holds_what_each_layer_needs(name):
    sc = Scene(Eyes(40.0, 20.0, 72), [Feature("a", 100.0, 900.0, 50.0)], [name])
    st = compute_state(sc)
    need = layers.layer(name).needs
    assert (st.LA is not None) == ("intervals" in need)
    assert (st.owner_a is not None) == ("owners" in need)
    assert (st.r is not None and st.in_bfv is not None) == ("readout" in need)
    build_frame(sc, st)  # each builder finds what it reads


def test_the_posterior_alone_has_its_intervals():
    """The table says posterior needs the intervals: alone it still gets its posterior
    (the old sets left them out, and the frame built none)."""
    sc = Scene(Eyes(40.0, 20.0, 720), [Feature("a", 300.0, 2500.0, 60.0)], ["posterior"])
    fr = build_frame(sc)
    assert fr.posterior[0] is not None and not fr.posterior[0].empty


def test_the_draw_orders_are_the_renderers_orders():
    assert [s.name for s in layers.ordered("mpl")] == [
        "bfv", "sectors", "eyes", "tangents", "ambiguity", "trajectory", "features",
        "predictions", "posterior", "labels", "bitmaps", "readout",
    ]  # fmt: skip
    assert [s.name for s in layers.ordered("vtk")] == [
        "bfv", "eyes", "features", "labels", "tangents", "sectors", "ambiguity",
        "trajectory", "predictions", "posterior",
    ]  # fmt: skip
    assert [s.name for s in layers.ordered("frame", {"eyes", "bfv", "readout"})] == [
        "eyes",
        "bfv",
    ]


# --- (c) predictions: one function, once per frame --------------------------------------


class CountingPredictor(Predictor):
    """A Predictor that counts its scene predictions."""

    def __init__(self) -> None:
        super().__init__()
        self.calls = 0

    def predict(self, scene, state):
        self.calls += 1
        return super().predict(scene, state)


def _pred_scene() -> Scene:
    fs = [
        Feature("in", 100.0, 2000.0, 50.0, "#D55E00"),
        Feature("out", -3000.0, 100.0, 50.0, "#0072B2"),  # outside the BFV: NaN
    ]
    layers_ = ["eyes", "features", "readout", "labels", "predictions"]
    return Scene(Eyes(40.0, 20.0, 720), fs, layers_, estimators=["analytic"])


@pytest.fixture
def through_one_function(monkeypatch):
    """Every call of scene_predictions, from wherever it is called."""
    calls: list[str] = []
    real = predictor_mod.scene_predictions

    def counted(scene, state, predictor=None):
        calls.append(scene.title)
        return real(scene, state, predictor)

    monkeypatch.setattr(predictor_mod, "scene_predictions", counted)
    monkeypatch.setattr(frame_mod, "scene_predictions", counted)
    return calls


def test_build_frame_computes_the_predictions_once(through_one_function):
    sc = _pred_scene()
    p = CountingPredictor()
    fr = build_frame(sc, predictor=p)
    assert p.calls == 1 and len(through_one_function) == 1
    want = scene_predictions(sc, compute_state(sc))["analytic"]
    np.testing.assert_array_equal(fr.predictions["analytic"].r_hat, want[0])
    np.testing.assert_array_equal(fr.predictions["analytic"].phi_hat, want[1])
    assert np.isnan(fr.predictions["analytic"].r_hat[1])
    # given predictions (the app model's) are carried, not computed again
    build_frame(sc, predictions={"analytic": want}, predictor=p)
    assert p.calls == 1 and len(through_one_function) == 1


def test_the_exported_figure_computes_the_predictions_once(through_one_function):
    from eyeviz.render.mpl import vector

    sc = _pred_scene()
    p = CountingPredictor()
    fig = vector.figure(sc, predictor=p)
    assert p.calls == 1 and len(through_one_function) == 1
    want = scene_predictions(sc, compute_state(sc))["analytic"]
    np.testing.assert_array_equal(fig._eyeviz_frame.predictions["analytic"].r_hat, want[0])


def test_the_app_model_computes_the_predictions_once_per_change(through_one_function):
    model = AppModel(_pred_scene())
    p = CountingPredictor()
    model.predictor = p
    first = model.predictions
    assert model.predictions is first  # kept
    assert p.calls == 1 and len(through_one_function) == 1
    # the window draws them through a Frame given them: no second computation
    fr = build_frame(model.scene, model.state, predictions=first)
    assert p.calls == 1 and len(through_one_function) == 1
    np.testing.assert_array_equal(fr.predictions["analytic"].r_hat, first["analytic"][0])
    model.live(0, x=150.0)  # a drag frame: computed again, once
    again = model.predictions
    assert model.predictions is again
    assert p.calls == 2 and len(through_one_function) == 2
    assert again["analytic"][0][0] != first["analytic"][0][0]


def test_no_predictions_layer_computes_nothing(through_one_function):
    sc = _pred_scene()
    sc.layers.remove("predictions")
    p = CountingPredictor()
    assert build_frame(sc, predictor=p).predictions == {}
    assert AppModel(sc).predictions == {}
    assert scene_predictions(sc, compute_state(sc), p) == {}
    assert p.calls == 0


def test_an_exported_figure_imports_no_vtk_and_no_qt(tmp_path):
    """Painters are named by strings, resolved on use: the matplotlib export of a scene
    showing every layer imports no VTK, pyvista or Qt."""
    scene = Path(__file__).parents[2] / "eyeviz" / "assets" / "scenes" / "predictions.toml"
    code = "\n".join(
        [
            "import sys",
            "from eyeviz.model.layers import layer_names",
            "from eyeviz.model.scene import load",
            "from eyeviz.render.mpl.export import export",
            f"sc = load({str(scene)!r})",
            "sc.layers, sc.estimators = list(layer_names()), ['analytic']",
            f"export(sc, {str(tmp_path / 'all.png')!r})",
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'vtkmodules', 'pyvista',"
            " 'PyQt5'}))",
        ]
    )
    env = {**os.environ, "MPLBACKEND": "Agg"}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
    assert (tmp_path / "all.png").stat().st_size > 0
