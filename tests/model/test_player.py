"""The trajectory player as model state, without a display (issue 12 item 1)."""

import numpy as np
from undo_stack import Undo

from eyeviz.model.app_model import AppModel
from eyeviz.model.scene import Feature, Scene


class Path:
    def __init__(self, n=50, y=2000.0, g=30.0):
        self.x = np.linspace(-500.0, 500.0, n)
        self.y = np.full(n, y)
        self.g = g
        self.n = n


def model3():
    m = AppModel(
        Scene(
            features=[
                Feature("a", 0.0, 1000.0, 50.0),
                Feature("b", 100.0, 3000.0, 70.0),
                Feature("c", -300.0, 1500.0, 90.0),
            ]
        )
    )
    return m, Undo(m)


def test_play_step_pause_is_one_undo_step():
    m, undo = model3()
    m.select(1)
    m.player.set_path(Path())
    assert m.player.start() and m.player.playing
    for _ in range(5):
        m.player.step(3)
    b = m.scene.features[1]
    assert (b.x, b.y, b.g) == (Path().x[15], 2000.0, 30.0)
    m.player.stop()
    assert not m.player.playing and len(undo.steps) == 1 and undo.steps[0][2] == "Animate b"
    undo.undo()
    assert (m.scene.features[1].x, m.scene.features[1].y) == (100.0, 3000.0)


def test_deleting_the_played_feature_stops_playback_and_touches_no_other():
    m, undo = model3()
    m.select(0)
    m.player.set_path(Path())
    m.player.start()
    m.player.step(2)
    others = [(f.x, f.y, f.g) for f in m.scene.features[1:]]
    m.delete_feature(0)  # Del while playing
    assert not m.player.playing
    assert "deleted" in m.player.message
    assert m.player.step() is None  # a timer tick after the deletion moves nothing
    assert [(f.x, f.y, f.g) for f in m.scene.features] == others
    assert [t for _, _, t in undo.steps] == ["Animate a", "Delete a"]


def test_deleting_another_feature_keeps_playing_the_same_one():
    m, undo = model3()
    m.select(2)  # play "c", the last one
    m.player.set_path(Path())
    m.player.start()
    m.player.step(1)
    m.delete_feature(0)  # indices shift: c is now index 1
    assert m.player.playing and m.player.index() == 1
    b_before = (m.scene.features[0].x, m.scene.features[0].y)
    m.player.step(4)
    assert (m.scene.features[0].x, m.scene.features[0].y) == b_before  # b untouched
    assert m.scene.features[1].name == "c" and m.scene.features[1].x == Path().x[5]
    m.player.stop()
    assert [t for _, _, t in undo.steps] == ["Animate c", "Delete a", "Animate c"]


def test_no_path_no_play():
    m, _ = model3()
    assert not m.player.start() and "no trajectory" in m.player.message


def test_after_the_played_feature_is_deleted_start_waits_for_a_selection():
    m, undo = model3()
    m.select(0)
    m.player.set_path(Path())
    m.player.start()
    m.player.step(2)
    m.delete_feature(0)  # "b" is now selected by the clamp, not by the user
    others = [(f.x, f.y, f.g) for f in m.scene.features]
    assert not m.player.start() and "select a feature" in m.player.message
    assert m.player.step() is None and [(f.x, f.y, f.g) for f in m.scene.features] == others
    m.select(1)  # the user picks "c": Space plays it
    assert m.player.start() and m.player.feature == "c"
    m.player.stop()


def test_start_without_a_valid_selection_plays_the_first_feature():
    for sel in (None, 3, 7):  # nothing selected, or a stale index past the last feature
        m, _ = model3()
        m.selected = sel
        m.player.set_path(Path())
        assert m.player.start() and m.player.feature == "a"
        m.player.stop()


def test_a_one_point_path_steps_onto_its_point_and_an_empty_one_stops():
    m, _ = model3()
    m.select(1)
    m.player.set_path(Path(n=1))
    assert m.player.start()
    assert m.player.step() == (-500.0, 2000.0) and m.scene.features[1].x == -500.0
    m.player.stop()
    m.player.set_path(Path(n=0))
    assert m.player.start()
    assert m.player.step() is None and not m.player.playing
    assert "no trajectory" in m.player.message


def test_an_unrelated_edit_after_the_deletion_still_waits_for_a_selection():
    m, undo = model3()
    m.select(0)
    m.player.set_path(Path())
    m.player.start()
    m.player.step(2)
    m.delete_feature(0)
    m.set_feature(1, x=-250.0)  # another edit: "a" is still gone
    assert not m.player.start() and "select a feature" in m.player.message
    undo.undo()
    undo.undo()  # "a" is back: a start plays it again
    assert m.player.start() and m.player.feature == "a"
    m.player.stop()
