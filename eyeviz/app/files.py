"""File handling of the window: open, save, recent files, unsaved-changes prompts.

Nothing is lost silently (issue 12 item 2): Quit, closing the window, Open and Open recent
ask Save / Discard / Cancel when the scene has unsaved changes; a scene shipped with eyeviz
(``assets/``) opens as "untitled", so Ctrl+S acts as Save As and never writes into the
installed assets.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from PyQt5 import QtWidgets

from eyeviz.model.scene import SceneError, load, save
from eyeviz.resources import assets_dir

if TYPE_CHECKING:
    from eyeviz.app.settings import Settings
    from eyeviz.app.view3d import Scene3DHost
    from eyeviz.model.app_model import AppModel

    _MainWindow = QtWidgets.QMainWindow
else:
    _MainWindow = object  # MainWindow brings QMainWindow

__all__ = ["FilesMixin", "RECENT_MAX", "is_bundled"]

RECENT_MAX = 8


def is_bundled(path: str | os.PathLike) -> bool:
    """True for a file inside eyeviz's shipped assets (never saved over)."""
    try:
        Path(path).resolve().relative_to(assets_dir().resolve())
    except (ValueError, OSError):
        return False
    return True


class FilesMixin(_MainWindow):
    """Mixed into MainWindow: needs ``model``, ``undo_stack``, ``settings``,
    ``recent_menu``, ``statusBar``, ``fit_view`` and ``fit_inset``."""

    # MainWindow's (set in its __init__ and build_menus)
    model: AppModel
    undo_stack: QtWidgets.QUndoStack
    settings: Settings
    recent_menu: QtWidgets.QMenu
    last_error: str
    error_box: QtWidgets.QMessageBox | None
    unsaved_box: QtWidgets.QMessageBox | None
    host3d: Scene3DHost

    if TYPE_CHECKING:  # for mypy only: at run time QMainWindow's and CanvasMixin's

        def statusBar(self) -> QtWidgets.QStatusBar: ...  # noqa: N802 (never None in a QMainWindow)

        def fit_view(self) -> None: ...

        def fit_inset(self) -> None: ...

    path: Path | None = None
    source: Path | None = None  # the file the scene came from (a bundled one included)

    def _set_path(self, path: str | os.PathLike | None) -> None:
        self.source = Path(path) if path else None
        self.path = None if path is None or is_bundled(path) else Path(path)

    # --- title and dirty state --------------------------------------------------------
    def _clean_changed(self, _clean: bool) -> None:
        try:
            self._update_title()
        except RuntimeError:  # the stack is being destroyed with the window
            pass

    def is_modified(self) -> bool:
        return self.model.live_open or not self.undo_stack.isClean()

    def _update_title(self) -> None:
        if self.path:
            name = self.path.name
        elif self.source:
            name = f"untitled (from {self.source.name})"
        else:
            name = "untitled"
        star = "" if self.undo_stack.isClean() else " *"
        self.setWindowTitle(f"eyeviz — {name}{star}")

    def maybe_save(self) -> bool:
        """Unsaved changes: ask Save / Discard / Cancel. True when it is fine to go on."""
        self.model.finish_gestures()
        if self.undo_stack.isClean():
            return True
        box = QtWidgets.QMessageBox(
            QtWidgets.QMessageBox.Warning,
            "Unsaved changes",
            "The scene has unsaved changes. Save them first?",
            QtWidgets.QMessageBox.Save
            | QtWidgets.QMessageBox.Discard
            | QtWidgets.QMessageBox.Cancel,
            self,
        )
        box.setDefaultButton(QtWidgets.QMessageBox.Save)
        # keys for each answer: Enter saves, Escape cancels, Alt+S / Alt+D (Qt's standard
        # texts carry no mnemonics: a keyboard user had to Tab to Discard)
        for button, text in ((QtWidgets.QMessageBox.Save, "&Save"),
                             (QtWidgets.QMessageBox.Discard, "&Discard")):  # fmt: skip
            b = box.button(button)
            assert b is not None
            b.setText(text)
        box.setObjectName("unsaved_prompt")
        self.unsaved_box = box
        answer = box.exec_()
        self.unsaved_box = None
        if answer == QtWidgets.QMessageBox.Save:
            return self.save_current()
        return answer == QtWidgets.QMessageBox.Discard

    # --- recent files -----------------------------------------------------------------
    def recent_files(self) -> list[str]:
        v = self.settings.value("recent", [])
        if isinstance(v, str):
            v = [v]
        return [str(p) for p in (v or []) if isinstance(p, str)]

    def _add_recent(self, path: Path) -> None:
        p = str(Path(path).resolve())
        rec = [p] + [r for r in self.recent_files() if r != p]
        self.settings.setValue("recent", rec[:RECENT_MAX])
        self.settings.sync()
        self._refresh_recent()

    def _refresh_recent(self) -> None:
        self.recent_menu.clear()
        for p in self.recent_files():
            a = self.recent_menu.addAction(p)
            assert a is not None  # addAction(text) returns the action it made

            def open_recent(_checked: bool = False, p: str = p) -> None:
                self.open_file(p)

            a.triggered.connect(open_recent)
        self.recent_menu.setEnabled(bool(self.recent_files()))

    def frame_bundled(self) -> None:
        """A scene shipped with eyeviz is framed to the window (its saved view was made for
        another window size: features fell under the title); a user's file keeps its view."""
        if self.source is not None and is_bundled(self.source) and self.isVisible():
            self.fit_view()

    # --- open and save ------------------------------------------------------------------
    def show_error(self, title: str, text: str) -> None:
        """A window-modal, non-blocking dialog (tests can read and close it)."""
        self.last_error = text
        self.statusBar().showMessage(text, 10000)
        box = QtWidgets.QMessageBox(
            QtWidgets.QMessageBox.Critical, title, text, QtWidgets.QMessageBox.Ok, self
        )
        box.open()
        self.error_box = box

    def open_dialog(self) -> None:
        if not self.maybe_save():
            return
        start = str(self.path.parent) if self.path else str(Path.cwd())
        p, _ = QtWidgets.QFileDialog.getOpenFileName(self, "Open scene", start, "Scenes (*.toml)")
        if p:
            self.open_path(p)

    def open_file(self, path: str | os.PathLike) -> bool:
        """Open recent: ask about unsaved changes, then open."""
        return self.maybe_save() and self.open_path(path)

    def open_path(self, path: str | os.PathLike) -> bool:
        """Load a scene; an invalid file shows a dialog and the open scene is kept."""
        try:
            scene = load(path)
        except SceneError as exc:
            self.show_error("Cannot open scene", str(exc))
            return False
        if scene.in_space and not self.host3d.check(scene):
            return False  # lit sets the 3D view cannot hold: one line, the scene kept
        self.model.finish_gestures()
        self._set_path(path)
        self.undo_stack.clear()
        if scene.in_space:  # issue 22: the 3D page (eyeviz.app.view3d)
            self.host3d.open(scene)
        else:
            self.host3d.leave()
            self.model.selected = None
            self.model.set_scene(scene)
            self.fit_inset()
            self.frame_bundled()
        if not is_bundled(path):
            self._add_recent(Path(path))
        self._update_title()
        return True

    def save_dialog(self) -> bool:
        start = str(self.path) if self.path else str(Path.cwd() / "scene.toml")
        p, _ = QtWidgets.QFileDialog.getSaveFileName(self, "Save scene", start, "Scenes (*.toml)")
        return self.save_path(p) if p else False

    def save_current(self) -> bool:
        """Ctrl+S: save over the scene's file; untitled or bundled scenes ask for a name."""
        return self.save_path(self.path) if self.path else self.save_dialog()

    def save_path(self, path: str | os.PathLike) -> bool:
        if is_bundled(path):
            self.show_error("Cannot save scene", f"{path}: eyeviz's shipped scenes are read-only")
            return False
        self.model.finish_gestures()
        try:
            save(self.host3d.scene_or(self.model.scene), path)
        except (OSError, SceneError) as exc:
            self.show_error("Cannot save scene", f"{path}: {exc}")
            return False
        self._set_path(path)
        self.undo_stack.setClean()
        self._add_recent(Path(path))
        self._update_title()
        self.statusBar().showMessage(f"saved {path}", 5000)
        return True
