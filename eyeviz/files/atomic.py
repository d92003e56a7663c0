"""Atomic output files: nothing half-written survives an interruption or a full disk.

A temporary file is named ``.<name>.<pid>.<random>.part<suffix>`` next to the target:
hidden, carrying its writer's PID. Should the writer die without cleaning up (SIGKILL,
power loss), the next :func:`atomic_output` into that folder sweeps the temporary files
of eyeviz's own naming that are older than :data:`SWEEP_AGE_S` and whose writer is gone
(:func:`sweep_stale`). SIGTERM and SIGHUP are turned into an exception by
:func:`eyeviz.cli.main`, so they remove the temporary file like Ctrl-C does.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import stat
import time
from collections.abc import Iterator
from pathlib import Path

from eyeviz import EyevizError

#: A temporary file is swept only when older than this (seconds) and its writer is gone.
SWEEP_AGE_S = 600.0
#: Temporary files of earlier eyeviz versions (no PID in the name): swept after a day.
SWEEP_AGE_LEGACY_S = 86400.0

#: Interruptions (SIGINT, SIGTERM, SIGHUP under :func:`eyeviz.cli.main`) since the command
#: began. A library can swallow the exception a signal handler raises (one raised inside
#: numpy's lazy import of ``numpy.random`` was lost, and the whole output was kept):
#: :func:`atomic_output` raises it again rather than keep the file.
_interruptions: list[BaseException] = []


def note_interruption(exc: BaseException) -> None:
    """Remember a signal's exception (called by the signal handler before it raises it)."""
    _interruptions.append(exc)


def clear_interruptions() -> None:
    """Forget earlier interruptions (a new command begins)."""
    _interruptions.clear()


#: errno values that mean the disk (or the user's quota, or the largest file) is full.
_FULL = frozenset(
    e for e in (errno.ENOSPC, getattr(errno, "EDQUOT", None), errno.EFBIG) if e is not None
)


def full_disk_error(path, exc: OSError) -> EyevizError | None:
    """The one-line error naming ``path`` for a full disk (quota, file size limit), None
    for any other error. ``os.write`` and the writers built on it (zipfile, numpy,
    matplotlib) say only "[Errno 28] No space left on device", never which file."""
    if exc.errno not in _FULL:
        return None
    what = os.strerror(exc.errno) if exc.errno is not None else "disk full"
    return EyevizError(
        f"{path}: cannot write: {what} (a full disk, quota or file size limit); nothing "
        "was written and an existing file there is unchanged"
    )


_PART = re.compile(r"^\.(?P<name>.+)\.(?P<pid>\d+)\.(?P<rand>[0-9a-f]{16})\.part(\.[^.]*)?$")
_LEGACY = re.compile(r"^\.(?P<name>.+)\.(?P<rand>[A-Za-z0-9_]{8})\.part(\.[^.]*)?$")


def part_name(path: Path, pid: int | None = None) -> str:
    """The temporary name of ``path`` written by process ``pid`` (default: this one)."""
    pid = os.getpid() if pid is None else pid
    return f".{path.name}.{pid}.{secrets.token_hex(8)}.part{path.suffix}"


def _pid_alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return pid < 2**22  # someone else's live process (or an absurd PID: dead)
    return True


def sweep_stale(folder, now: float | None = None) -> list[Path]:
    """Remove eyeviz's own stale temporary files in ``folder``; return what was removed.

    Only regular files matching eyeviz's naming are touched: with a PID, when older than
    SWEEP_AGE_S and that process no longer exists; without one (earlier versions), when
    older than SWEEP_AGE_LEGACY_S. Errors (a file vanished, no permission) are ignored.
    """
    now = time.time() if now is None else now
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for e in entries:
        if not e.name.startswith(".") or ".part" not in e.name:
            continue
        m = _PART.match(e.name)
        legacy = None if m else _LEGACY.match(e.name)
        if not (m or legacy):
            continue
        try:
            st = e.stat(follow_symlinks=False)
        except OSError:
            continue

        if not stat.S_ISREG(st.st_mode):
            continue
        age = now - st.st_mtime
        if m:
            if age < SWEEP_AGE_S or int(m["pid"]) == os.getpid() or _pid_alive(int(m["pid"])):
                continue
        elif age < SWEEP_AGE_LEGACY_S:
            continue
        with contextlib.suppress(OSError):
            os.unlink(e.path)
            removed.append(Path(e.path))
    return removed


@contextlib.contextmanager
def atomic_output(path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it over ``path`` only on success.

    The temporary name keeps ``path``'s suffix (numpy and matplotlib look at it). On any
    exception, KeyboardInterrupt (and so SIGTERM/SIGHUP under the CLI) included, the
    temporary file is removed and an existing ``path`` is left as it was.

    A symlinked ``path`` is written through: its target is replaced (in the target's
    folder) and the link stays a link (issue 25).
    """
    path = Path(path)
    if path.is_symlink():
        path = Path(os.path.realpath(path))
    d = path.parent if str(path.parent) else Path(".")
    if not d.is_dir():
        raise EyevizError(f"output directory does not exist: {str(d)!r}")
    sweep_stale(d)
    umask = os.umask(0)
    os.umask(umask)
    while True:
        tmp = d / part_name(path)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666 & ~umask)
            break
        except FileExistsError:
            continue
        except OSError as exc:  # no inode left
            full = full_disk_error(path, exc)
            if full is None:
                raise
            raise full from exc
    try:
        os.close(fd)
        yield tmp
        if _interruptions:  # a signal arrived and something swallowed its exception
            raise _interruptions[0]
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        full = full_disk_error(path, exc) if isinstance(exc, OSError) else None
        if full is not None:
            raise full from exc
        raise
