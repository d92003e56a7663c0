"""The estimator picker takes its names and help from the registry (issue 9 item 4)."""

from eyeviz.estimators import registry
from eyeviz.model.app_model import AppModel
from eyeviz.model.scene import Eyes, Feature, Scene, View


def _scene():
    return Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("target", 300.0, 3000.0, 60.0, "#D55E00")],
        ["eyes", "bfv", "features", "predictions"],
        estimators=[],
        view=View((0.0, 2300.0), 7000.0),
    )


def test_every_registered_estimator_is_in_the_picker_with_the_registry_help(qtbot):
    from eyeviz.app.docks import EstimatorPicker

    plug = registry.Entry(
        "zz_plugin_probe",
        "a probe plug-in: its help must reach the picker",
        load=lambda **kw: None,
        any_design=True,
        design=None,
    )
    registry.register(plug)
    try:
        picker = EstimatorPicker(AppModel(_scene()))
        qtbot.addWidget(picker)
        picker.refresh()
        names = registry.available()
        assert "zz_plugin_probe" in names
        assert list(picker.boxes) == names
        for name in names:
            assert picker.boxes[name].toolTip() == registry.get(name).help, name
        # the help the issue names: bayes answers with a posterior median, not a mean
        assert "median" in picker.boxes["bayes"].toolTip()
        assert "mean" not in picker.boxes["bayes"].toolTip()
    finally:
        registry.unregister("zz_plugin_probe")
    assert "zz_plugin_probe" not in registry.available()
