"""Menus, actions and the undo command of the main window.

Play / pause: Space works only while the view has the keyboard focus (a focused check box
or button keeps its own Space); the menu's shortcut P works everywhere except in text
fields.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import TYPE_CHECKING

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.app.help import HELP_NAME
from eyeviz.model.app_model import AppModel
from eyeviz.model.camera3d import Camera3D
from eyeviz.model.scene import Scene, View

if TYPE_CHECKING:
    from eyeviz.app.window import MainWindow

__all__ = [
    "PLANAR_ONLY",
    "PLAY_SHORTCUT",
    "CameraSceneCommand",
    "SceneCommand",
    "build_menus",
    "command3d",
]

PLAY_SHORTCUT = "P"


class SceneCommand(QtWidgets.QUndoCommand):
    """The one undo step of either page (issue 37.2): the scene before and after.

    The planar page's view is left where the user put it (``keep_view``); the 3D page's
    camera is not in its scene (``keep_view=False``). A 3D drag's step carries the camera
    too (``camera``: the view's getter and setter, ``at_press``: the camera the drag
    started from): undo puts back that camera as well as the scene, redo the camera undo
    left (issue 32.5: after a drag the view may have been re-framed, and Ctrl+Z restored
    the ball but not the view)."""

    def __init__(
        self,
        model: AppModel,
        before: Scene,
        after: Scene,
        text: str,
        merge_key: object = None,
        keep_view: bool = True,
        camera: tuple[Callable[[], Camera3D], Callable[[Camera3D], None]] | None = None,
        at_press: Camera3D | None = None,
    ) -> None:
        super().__init__(text)
        self.model, self.before, self.after, self.merge_key = model, before, after, merge_key
        self.keep_view = keep_view
        self.get_camera: Callable[[], Camera3D] | None = None
        self.set_camera: Callable[[Camera3D], None] | None = None
        if camera is not None:
            self.get_camera, self.set_camera = camera
        self.at_press = at_press
        self.at_undo: Camera3D | None = None

    def _set(self, scene: Scene) -> None:
        if not self.keep_view:
            self.model.set_scene(scene)
            return
        # a shallow replace: set_scene makes the one copy (issue 25: copies cost at 10^4)
        view = View(self.model.scene.view.center, self.model.scene.view.width)
        self.model.set_scene(dataclasses.replace(scene, view=view))

    def redo(self) -> None:
        self._set(self.after)
        if self.at_undo is not None and self.set_camera is not None:
            self.set_camera(self.at_undo)

    def undo(self) -> None:
        if self.at_press is not None and self.get_camera is not None:
            self.at_undo = self.get_camera()
        self._set(self.before)
        if self.at_press is not None and self.set_camera is not None:
            self.set_camera(self.at_press)

    def id(self) -> int:  # noqa: A003 (Qt name)
        return 1 if self.merge_key is not None else -1

    def mergeWith(self, other) -> bool:  # noqa: N802 (Qt name)
        if getattr(other, "model", None) is not self.model or other.merge_key != self.merge_key:
            return False
        self.after = other.after
        return True


def command3d(
    model: AppModel,
    before: Scene,
    after: Scene,
    text: str,
    merge_key: object,
    camera: tuple[Callable[[], Camera3D], Callable[[Camera3D], None]],
    at_press: Camera3D | None,
) -> SceneCommand:
    """The 3D page's undo step: with ``at_press`` (a drag's camera at its press) one
    that puts the view back too; a drag's step merges with none."""
    if at_press is None:
        return SceneCommand(model, before, after, text, merge_key, keep_view=False)
    return SceneCommand(
        model, before, after, text, None, keep_view=False, camera=camera, at_press=at_press
    )


#: The 3D drag's undo step is a :class:`SceneCommand` with a camera (the old name).
CameraSceneCommand = SceneCommand


def _action(win, menu, text, slot, shortcut=None) -> QtWidgets.QAction:
    a = QtWidgets.QAction(text, win)
    if shortcut is not None:
        a.setShortcut(QtGui.QKeySequence(shortcut))
        a.setShortcutContext(QtCore.Qt.ShortcutContext.WindowShortcut)
    a.triggered.connect(slot)
    menu.addAction(a)
    win.addAction(a)
    return a


def _undo_actions(win: MainWindow, menu: QtWidgets.QMenu) -> None:
    """Undo / Redo that first end a running gesture or playback (one step each)."""
    stack = win.undo_stack

    def undo() -> None:
        win.model.finish_gestures()
        stack.undo()

    def redo() -> None:
        win.model.finish_gestures()
        stack.redo()

    u = _action(win, menu, "&Undo", undo, QtGui.QKeySequence.Undo)
    r = _action(win, menu, "&Redo", redo, QtGui.QKeySequence.Redo)
    u.setProperty(HELP_NAME, "Undo")  # F1 lists the action, not the live "Undo Nudge ..."
    r.setProperty(HELP_NAME, "Redo")
    u.setEnabled(stack.canUndo())
    r.setEnabled(stack.canRedo())
    stack.canUndoChanged.connect(u.setEnabled)
    stack.canRedoChanged.connect(r.setEnabled)
    stack.undoTextChanged.connect(lambda t: u.setText(f"&Undo {t}".strip()))
    stack.redoTextChanged.connect(lambda t: r.setText(f"&Redo {t}".strip()))
    win.undo_action, win.redo_action = u, r


def _menu(parent: QtWidgets.QMenuBar | QtWidgets.QMenu, title: str) -> QtWidgets.QMenu:
    menu = parent.addMenu(title)
    assert menu is not None  # addMenu(title) returns the menu it made
    return menu


def build_menus(win: MainWindow) -> None:
    mb = win.menuBar()
    assert mb is not None  # a QMainWindow makes its menu bar on first use
    f = _menu(mb, "&File")
    _action(win, f, "&Open…", win.open_dialog, QtGui.QKeySequence.Open)
    win.recent_menu = _menu(f, "Open &recent")
    _action(win, f, "&Save", win.save_current, QtGui.QKeySequence.Save)
    _action(win, f, "Save &as…", win.save_dialog, QtGui.QKeySequence.SaveAs)
    f.addSeparator()
    _action(win, f, "&Export figure…", win.export_dialog, "Ctrl+E")
    f.addSeparator()
    _action(win, f, "&Quit", win.close, QtGui.QKeySequence.Quit)
    e = _menu(mb, "&Edit")
    _undo_actions(win, e)
    e.addSeparator()
    _action(win, e, "&Add feature at view centre", win.add_at_center, "Ctrl+N")
    _action(win, e, "&Duplicate feature", win.duplicate_selected, "Ctrl+D")
    _action(win, e, "De&lete feature", win.delete_selected, QtGui.QKeySequence.Delete)
    v = _menu(mb, "&View")
    _action(win, v, "&Fit view", win.fit_view, "F")
    _action(win, v, "Fit &inset to the eyes", win.fit_inset, "Shift+F")
    v.addSeparator()
    _action(win, v, "Eye &design: limit against distance", win.show_design)
    t = _menu(v, "&Trajectory")
    for kind in ("horizontal", "circular", "vertical"):
        t.addAction(kind.capitalize(), lambda k=kind: win.show_trajectory(k))
    win.play_action = _action(
        win, v, "&Play / pause trajectory (Space in the view)", win.toggle_play, PLAY_SHORTCUT
    )
    win._refresh_recent()


#: the window's actions that act on the planar scene only (disabled in the 3D view)
PLANAR_ONLY = frozenset(
    {
        "Fit view",
        "Fit inset to the eyes",
        "Eye design: limit against distance",
        "Play / pause trajectory (Space in the view)",
    }
)
