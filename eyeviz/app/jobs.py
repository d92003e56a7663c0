"""Long work off the GUI thread (issue 12 item 9): a busy cursor and a status message while
it runs, the window stays live (drags, repaints), the result comes back on the GUI thread.

Jobs get plain copies of what they need (a Scene copy, a predictions dict), never the live
model, so a drag during an export cannot change what is being written.
"""

from __future__ import annotations

import atexit
import weakref
from collections.abc import Callable

from PyQt5 import QtCore, QtWidgets

__all__ = ["Job", "JobRunner"]


class _Signals(QtCore.QObject):
    finished = QtCore.pyqtSignal(object, object)  # result, exception


class Job(QtCore.QRunnable):
    def __init__(self, fn: Callable[[], object]) -> None:
        super().__init__()
        self.fn = fn
        self.signals = _Signals()
        self.setAutoDelete(False)

    def run(self) -> None:  # worker thread
        try:
            res, err = self.fn(), None
        except BaseException as exc:  # noqa: BLE001 (reported on the GUI thread)
            res, err = None, exc
        try:
            self.signals.finished.emit(res, err)
        except RuntimeError:  # the window (and its receiver) is gone: nothing to report
            pass


class JobRunner(QtCore.QObject):
    """Runs jobs one at a time on a private thread pool; shows a busy cursor meanwhile."""

    def __init__(
        self, status: Callable[[str, int], None], parent: QtCore.QObject | None = None
    ) -> None:
        super().__init__(parent)
        self.pool = QtCore.QThreadPool(self)
        self.pool.setMaxThreadCount(1)
        self.status = status
        self.running: list[Job] = []
        ref = weakref.ref(self)
        atexit.register(lambda: _drain(ref))

    def start(
        self,
        fn: Callable[[], object],
        message: str,
        done: Callable[[object], None],
        failed: Callable[[BaseException], None],
    ) -> Job:
        job = Job(fn)

        def finish(res, err) -> None:
            self.running.remove(job)
            QtWidgets.QApplication.restoreOverrideCursor()
            self.status("", 0)
            if err is None:
                done(res)
            else:
                failed(err)

        job.signals.finished.connect(  # type: ignore[call-arg]  # the stub lacks connect's type
            finish, QtCore.Qt.ConnectionType.QueuedConnection
        )
        self.running.append(job)
        QtWidgets.QApplication.setOverrideCursor(QtCore.Qt.CursorShape.BusyCursor)
        self.status(message, 0)
        self.pool.start(job)
        return job

    def busy(self) -> bool:
        return bool(self.running)

    def wait(self, msecs: int = 60000) -> bool:
        """Block until the pool is idle (tests and shutdown), then deliver results."""
        ok = self.pool.waitForDone(msecs)
        QtCore.QCoreApplication.sendPostedEvents()
        QtWidgets.QApplication.processEvents()
        return ok


def _drain(ref) -> None:
    """At interpreter exit: let a running job finish (never kill a half-written file)."""
    runner = ref()
    if runner is None:
        return
    try:
        runner.pool.waitForDone(120000)
    except RuntimeError:  # already deleted with its window
        pass
