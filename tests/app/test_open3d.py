"""The app draws planar eyes only (issue 22's 3D view is not built yet): File > Open of a
spherical scene shows one line and keeps the open scene."""

from pathlib import Path

from eyeviz.model.scene import Eyes, Feature, Scene

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


def test_open_spherical_scene_is_refused_in_one_line(make_window):
    win = make_window(Scene(Eyes(40.0, 20.0, 720), [Feature("a", 0.0, 1500.0, 50.0)]))
    before = win.model.scene.copy()
    assert win.open_path(SCENES / "sphere_teaching.toml") is False
    assert win.model.scene == before
    text = win.error_box.text()
    assert "\n" not in text and "sphere_teaching.toml" in text
    assert "the app's 3D view is not built yet; use eyeviz snapshot" in text
    win.error_box.close()
