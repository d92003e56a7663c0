"""Issue 12 item 1 (docks side): the trajectory dock survives the playing feature's
deletion (Space, Del, Space on trajectory.toml crashed with an IndexError)."""

from PyQt5.QtTest import QTest

from eyeviz.model.scene import load
from eyeviz.resources import scene_path


def test_space_delete_space_does_not_crash_and_animates_nobody_else(make_window, qtbot):
    win = make_window(load(scene_path("trajectory")), scene_path("trajectory"))
    win.model.add_feature(2500.0, 2500.0)  # a bystander that must not start moving
    names = [f.name for f in win.model.scene.features]
    played = names[0]
    win.model.select(0)
    win.toggle_play()  # Space (View > Play / pause)
    panel = win.trajectory_panel
    qtbot.waitUntil(lambda: panel.timer.isActive(), timeout=3000)
    qtbot.waitUntil(lambda: panel.player_pos > 0, timeout=3000)
    win.model.select(0)
    win.delete_selected()  # Del
    assert played not in [f.name for f in win.model.scene.features]
    bystander = [(f.x, f.y, f.g) for f in win.model.scene.features]
    win.toggle_play()  # Space: used to raise IndexError in set_playing
    QTest.qWait(300)
    win.toggle_play()
    QTest.qWait(200)
    assert win.isVisible()
    assert played not in [f.name for f in win.model.scene.features]
    # Space after the deletion plays nobody (the bystander was selected by the deletion,
    # not by the user) and says why; nobody moved meanwhile
    assert not panel.timer.isActive() and not win.model.player.playing
    assert [(f.x, f.y, f.g) for f in win.model.scene.features] == bystander
    assert "select a feature" in win.statusBar().currentMessage()
    win.model.select(0)  # the user picks the bystander: now Space plays it
    win.toggle_play()
    qtbot.waitUntil(lambda: panel.timer.isActive(), timeout=3000)
    assert win.model.player.feature == win.model.scene.features[0].name
    # undo brings the deleted feature back, the dock still works
    win.model.player.stop()
    win.undo_stack.undo()
    QTest.qWait(50)
    panel.refresh()
    assert panel.play_button.isEnabled()
