"""Atomic output files and folders: nothing half-written survives an interruption or a
full disk, and nothing but eyeviz's own temporaries is ever removed.

A temporary file is named ``.<name>.eyeviz-<pid>-<token>.part<suffix>`` next to the
target (a staging folder ``.<name>.eyeviz-<pid>-<token>.staging``): hidden, carrying
eyeviz's marker, its writer's PID and 16 random hex digits, a name no user would choose.
Should the writer die without cleaning up (SIGKILL, power loss), the next
:func:`atomic_output` of that same output sweeps its temporaries that are older than
:data:`SWEEP_AGE_S`, owned by this user, and whose writer is gone (:func:`sweep_stale`);
no other file is touched (issue 35: the old sweep deleted ``.thesis.chapter1.part.tex``).
SIGTERM and SIGHUP are turned into an exception by :func:`eyeviz.cli.main`, so they
remove the temporary file like Ctrl-C does. A character device or FIFO target is written
through, never replaced (:mod:`eyeviz.files.target`).
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import shutil
import signal
import stat
import threading
import time
from collections.abc import Iterator
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.files.target import open_through, resolve_output, write_through

#: A temporary file is swept only when older than this (seconds) and its writer is gone.
SWEEP_AGE_S = 600.0

#: Interruptions (SIGINT, SIGTERM, SIGHUP under :func:`eyeviz.cli.main`) since the command
#: began. A library can swallow the exception a signal handler raises (one raised inside
#: numpy's lazy import of ``numpy.random`` was lost, and the whole output was kept):
#: :func:`atomic_output` raises it again rather than keep the file.
_interruptions: list[BaseException] = []


def note_interruption(exc: BaseException) -> None:
    """Remember a signal's exception (called by the signal handler before it raises it)."""
    _interruptions.append(exc)


def pending_interruption() -> BaseException | None:
    """The first signal's exception since the command began, if one arrived (a library,
    or numba's compiled code, may have turned it into another exception or swallowed it)."""
    return _interruptions[0] if _interruptions else None


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


_MARK = "eyeviz"
_PART = re.compile(
    rf"^\.(?P<name>.+)\.{_MARK}-(?P<pid>\d+)-(?P<rand>[0-9a-f]{{16}})\.part(\.[^.]*)?$"
)
_STAGE = re.compile(rf"^\.(?P<name>.+)\.{_MARK}-(?P<pid>\d+)-(?P<rand>[0-9a-f]{{16}})\.staging$")


def part_name(path: Path, pid: int | None = None) -> str:
    """The temporary name of ``path`` written by process ``pid`` (default: this one)."""
    pid = os.getpid() if pid is None else pid
    return f".{path.name}.{_MARK}-{pid}-{secrets.token_hex(8)}.part{path.suffix}"


def stage_name(path: Path, pid: int | None = None) -> str:
    """The staging folder's name for the output folder ``path`` (:func:`atomic_folder`)."""
    pid = os.getpid() if pid is None else pid
    return f".{path.name}.{_MARK}-{pid}-{secrets.token_hex(8)}.staging"


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


def _stale(name: str, st: os.stat_result, target: str | None, now: float) -> bool:
    """True for eyeviz's own temporary (file or staging folder) of output ``target`` (any
    output when None), this user's, older than SWEEP_AGE_S, whose writer is gone."""
    m = _PART.match(name) if stat.S_ISREG(st.st_mode) else None
    if m is None and stat.S_ISDIR(st.st_mode):
        m = _STAGE.match(name)
    if m is None or (target is not None and m["name"] != target):
        return False
    if st.st_uid != os.geteuid() or now - st.st_mtime < SWEEP_AGE_S:
        return False
    pid = int(m["pid"])
    return pid != os.getpid() and not _pid_alive(pid)


def sweep_stale(folder, target: str | None = None, now: float | None = None) -> list[Path]:
    """Remove eyeviz's own stale temporaries in ``folder``; return what was removed.

    With ``target`` (an output's file name), only that output's temporaries are touched.
    Only names of eyeviz's marked form are candidates (:func:`part_name`,
    :func:`stage_name`), and only regular files and real folders among them, owned by
    this user, older than SWEEP_AGE_S and whose writer no longer exists. Errors (a file
    vanished, no permission) are ignored.
    """
    now = time.time() if now is None else now
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for e in entries:
        if f".{_MARK}-" not in e.name:
            continue
        try:
            st = e.stat(follow_symlinks=False)
        except OSError:
            continue
        if not _stale(e.name, st, target, now):
            continue
        with contextlib.suppress(OSError):
            if stat.S_ISDIR(st.st_mode):
                shutil.rmtree(e.path)
            else:
                os.unlink(e.path)
            removed.append(Path(e.path))
    return removed


@contextlib.contextmanager
def atomic_output(path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; put it in place only on success.

    The temporary name keeps ``path``'s suffix (numpy and matplotlib look at it). On any
    exception, KeyboardInterrupt (and so SIGTERM/SIGHUP under the CLI) included, the
    temporary file is removed and an existing ``path`` is left as it was.

    A regular file is replaced by a rename. A symlinked ``path`` is written through: its
    target is replaced (in the target's folder) and the link stays a link (issue 25). A
    character device or a FIFO is opened on entry (a FIFO with no reader is refused) and
    the finished file's bytes are written into it: it is never replaced (issue 35). A
    folder, block device, socket or link loop is refused in one line.
    """
    target = resolve_output(path)
    path, d = target.path, target.folder
    sweep_stale(d, path.name)
    fd_through = open_through(target) if target.through else None
    try:
        with _temporary(path, d) as tmp:
            yield tmp
            if _interruptions:  # a signal arrived and something swallowed its exception
                raise _interruptions[0]
            if fd_through is None:
                os.replace(tmp, path)
            else:
                write_through(tmp, fd_through, target)
    finally:
        if fd_through is not None:
            os.close(fd_through)


@contextlib.contextmanager
def _temporary(path: Path, d: Path) -> Iterator[Path]:
    """A fresh empty temporary file in ``d`` for ``path``, removed unless renamed away."""
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
    except BaseException as exc:
        full = full_disk_error(path, exc) if isinstance(exc, OSError) else None
        if full is not None:
            raise full from exc
        raise
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Defer SIGINT, SIGTERM and SIGHUP (main thread only) until the block is done, then
    deliver them as they would have been."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    old = {}
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None:
            old[sig] = signal.signal(sig, lambda s, _f: got.append(s))
    try:
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
        for sig in dict.fromkeys(got):
            signal.raise_signal(sig)


@contextlib.contextmanager
def atomic_folder(path) -> Iterator[Path]:
    """Yield a fresh staging folder beside the output folder ``path``; on success move
    its contents into ``path`` with signals held, on any exception remove it.

    An interrupted report leaves ``path`` as it was, never half old and half new (issue
    35). A folder that does not exist yet is created by one rename; into an existing one
    the files are moved one by one, replacing those of the same name (other files there
    are the user's and are left alone). A link to a folder is followed; any other
    existing ``path`` is refused in one line.
    """
    path = Path(path)
    if path.is_symlink():
        path = Path(os.path.realpath(path))
    if path.exists() and not path.is_dir():
        raise EyevizError(f"output {str(path)!r} exists and is not a directory")
    parent = path.parent if str(path.parent) else Path(".")
    parent.mkdir(parents=True, exist_ok=True)
    sweep_stale(parent, path.name)
    stage = parent / stage_name(path)
    stage.mkdir()
    try:
        yield stage
        if _interruptions:
            raise _interruptions[0]
        with _signals_held():
            _move_in(stage, path)
    except OSError as exc:
        full = full_disk_error(path, exc)
        if full is None:
            raise
        raise full from exc
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _move_in(stage: Path, path: Path) -> None:
    if not path.exists():
        os.rename(stage, path)
        return
    for src in sorted(stage.rglob("*")):
        dest = path / src.relative_to(stage)
        if src.is_dir() and not src.is_symlink():
            dest.mkdir(exist_ok=True)
        else:
            os.replace(src, dest)
