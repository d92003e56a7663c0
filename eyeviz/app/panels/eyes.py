"""The Eyes panel: h, l, m typed and applied together (issue 12 item 11)."""

from __future__ import annotations

from PyQt5 import QtWidgets

from eyeviz.app.panels.common import ERROR_STYLE, _Unelide, set_message, wrap_label
from eyeviz.model.app_model import AppModel
from eyeviz.model.scene_eyes import check_m  # the scene's own bound on m


def _num(v: float) -> str:
    """A float as typed back: the shortest text that reads as the same float ("40", not
    "40.0"; 40.123456789 in full, never rounded to "40.1235")."""
    t = repr(float(v))
    return t[:-2] if t.endswith(".0") else t


EYE_FIELDS = (("h", "origin to eye centre"), ("l", "eye radius"), ("m", "ommatidia per eye"))
PENDING_STYLE = "background: #fff4c2;"  # a typed value not applied yet


class EyesPanel(QtWidgets.QWidget):
    """h, l, m entered together (issue 12 item 11).

    Enter in any field (or Apply) checks the triple as
    :class:`~eyeviz.core.geometry.EyePair` does (0 < l < h, finite numbers, m an even
    integer in [4, :data:`~eyeviz.core.bounds.MAX_M`], the bound of every entry point, so a
    scene the window draws can be saved) and changes the eyes in one undo step. Moving between
    fields applies nothing, so with l = 20 one can type h = 10, then l = 5, then Enter. A
    refused triple leaves the scene as it was, keeps what was typed (never clamped or
    reset behind the user's back) and says why in one line; Revert shows the scene's
    values again. Fields holding a value not applied yet are tinted.
    """

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        form = QtWidgets.QFormLayout(self)
        self.edits: dict[str, QtWidgets.QLineEdit] = {}
        for key, tip in EYE_FIELDS:
            e = QtWidgets.QLineEdit()
            e.setObjectName(f"eyes_{key}")
            e.setToolTip(f"{tip}; Enter applies h, l and m together")
            e.returnPressed.connect(self.apply)  # type: ignore[arg-type]  # its bool unused
            e.textEdited.connect(self._mark)
            form.addRow(f"{key}  ({tip})", e)
            self.edits[key] = e
        row = QtWidgets.QHBoxLayout()
        self.apply_button = QtWidgets.QPushButton("Apply")
        self.apply_button.setToolTip("set h, l and m together (Enter in a field does the same)")
        self.apply_button.clicked.connect(self.apply)  # type: ignore[arg-type]  # its bool unused
        self.revert_button = QtWidgets.QPushButton("Revert")
        self.revert_button.setToolTip("show the scene's h, l and m again")
        self.revert_button.clicked.connect(self.revert)
        row.addWidget(self.apply_button)
        row.addWidget(self.revert_button)
        row.addStretch(1)
        form.addRow(row)
        self.message = wrap_label(QtWidgets.QLabel(""))
        self.message.setStyleSheet(ERROR_STYLE)
        form.addRow(self.message)
        self._shown: dict[str, str] | None = None  # the scene's values last filled in

    def scene_texts(self) -> dict[str, str]:
        e = self.model.scene.eyes
        return {"h": _num(e.h), "l": _num(e.l), "m": str(int(e.m))}

    def texts(self) -> dict[str, str]:
        return {k: w.text().strip() for k, w in self.edits.items()}

    def refresh(self) -> None:
        """Show the scene's h, l, m when they changed (an edit, undo, a file opened); a
        value typed and not applied survives other refreshes (a drag, a layer toggle)."""
        now = self.scene_texts()
        if now != self._shown:
            self._shown = now
            for key, val in now.items():
                self.edits[key].setText(val)
            self.message.setText("")
        self._mark()

    def pending(self) -> bool:
        return self.texts() != self.scene_texts()

    def _mark(self, *_args) -> None:
        now = self.scene_texts()
        for key, w in self.edits.items():
            w.setStyleSheet(PENDING_STYLE if w.text().strip() != now[key] else "")
        on = self.pending()
        self.apply_button.setEnabled(on)
        self.revert_button.setEnabled(on)

    def revert(self) -> None:
        self._shown = None
        self.refresh()

    def parse(self) -> tuple[float, float, int]:
        """The typed triple as numbers; ValueError naming the field otherwise."""
        t = self.texts()
        vals: list[float] = []
        for key in ("h", "l"):
            try:
                vals.append(float(t[key]))
            except ValueError:
                raise ValueError(f"{key} must be a number, got {t[key]!r}") from None
        m: int | float | str = t["m"]
        for number in (int, float):  # "720", or "720.0" (the integer rule of check_int)
            try:
                m = number(t["m"])
                break
            except ValueError:
                pass
        return vals[0], vals[1], check_m(m)

    def apply(self) -> bool:
        """Check the typed triple together; True if the scene now has it."""
        before = self.scene_texts()
        try:
            h, l, m = self.parse()
            self.model.set_eyes(h, l, m)  # EyePair's checks; nothing changes if refused
        except ValueError as exc:
            keep = ", ".join(f"{k} = {v}" for k, v in before.items())
            set_message(self.message, f"Refused: {exc} (the eyes stay {keep})")
            self._mark()
            return False
        self.message.setText("")
        self.revert()  # the applied values as the scene holds them
        return True
