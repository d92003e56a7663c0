"""Run a study on Dask (``dask.distributed``): one task per design point.

The only module of :mod:`eyeviz.study` that imports dask, and only inside
:func:`run_study` (``import eyeviz.study`` stays light). By default a LocalCluster with
one worker *process* per usable CPU (affinity and cgroup quota, ``threads_per_worker=1``);
``scheduler="tcp://HOST:8786"`` runs the same study on an existing cluster
(``dask scheduler`` / ``dask worker``, or dask-jobqueue on an HPC machine). Workers
receive the :class:`DesignPoint` (a few numbers), evaluate it
(:func:`eyeviz.study.point.evaluate`) and return its rows; results stream back with
``as_completed`` and each finished point is appended to the table at once (whole points
only, :class:`~eyeviz.study.table.StudyTable`).

A worker that dies mid-study loses only the point it was computing: the scheduler
reschedules it on another worker (``allowed-failures`` raised for the local cluster), and
should a cluster give up on it (``KilledWorker``) the point is submitted again, up to
:data:`RESUBMITS` times. Ctrl-C closes the cluster and keeps every finished point.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import secrets
import time
import warnings
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.core.validation import num
from eyeviz.study.cpus import usable_cpus
from eyeviz.study.kinds import POINT_TYPES, Point, columns_of, evaluate3d, open_table
from eyeviz.study.point import DesignPoint, evaluate

__all__ = ["CONNECT_TIMEOUT_S", "RESUBMITS", "StudyFailed", "StudySummary", "run_study"]

#: Seconds to wait for a user's scheduler before giving up with a one-line error.
CONNECT_TIMEOUT_S = 5.0
#: The same for the worker processes of a local cluster (they start on this machine).
LOCAL_CONNECT_S = 60.0
#: How many times a point whose workers kept dying is submitted again.
RESUBMITS = 3
#: The local scheduler's ``allowed-failures``: workers that may die running one point.
ALLOWED_FAILURES = 10
#: Most local worker processes.
MAX_WORKERS = 1024


@dataclass(frozen=True)
class StudySummary:
    """What :func:`run_study` did: points computed now, skipped (already in the table),
    failed (with the first error), the workers used and the wall time."""

    path: str
    points: int
    computed: int
    skipped: int
    workers: int
    seconds: float
    scheduler: str | None = None
    failures: tuple[str, ...] = field(default=())
    #: Points submitted again after the cluster gave them up (their workers kept dying).
    resubmitted: int = 0

    def __str__(self) -> str:
        where = f"on {self.scheduler}" if self.scheduler else f"{self.workers} local worker(s)"
        if self.workers == 0 and not self.computed and not self.failures:
            where = "nothing to compute"
        fails = f", {len(self.failures)} failed" if self.failures else ""
        return (
            f"{self.path}: {self.computed} point(s) computed, {self.skipped} skipped "
            f"(already there){fails}; {self.points} in the grid; {self.seconds:.1f} s, {where}"
        )


class StudyFailed(EyevizError):
    """Some design points failed; the finished ones are in the table (``.summary``)."""

    def __init__(self, summary: StudySummary):
        first = summary.failures[0] if summary.failures else "?"
        super().__init__(
            f"{len(summary.failures)} design point(s) failed, the other "
            f"{summary.computed + summary.skipped} are in {summary.path}; first: {first}"
        )
        self.summary = summary


def _describe(p: Point) -> str:
    res = f"nside={p.nside}" if hasattr(p, "nside") else f"m={p.m}"
    return f"h={num(p.h)}, l={num(p.l)}, {res}, n={p.n}, seed={p.seed}, prior={p.prior}"


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text[:300]


def _cores() -> int:
    """CPUs this process may use (affinity and cgroup quota, :mod:`eyeviz.study.cpus`)."""
    return usable_cpus()


def check_scheduler(scheduler: str) -> None:
    """Refuse, in one line, an address no Dask client can reach: no scheme:host:port, an
    unknown scheme, ``inproc://`` but for a scheduler in this process, an unclosed IPv6
    bracket.
    Dask's own parsers, before any Client exists (a failed Client's ``__del__`` printed
    a 9-line traceback and held the exit for 10 s)."""
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.comm.registry import get_backend

    example = "an address such as tcp://host:8786"
    try:
        scheme, loc = parse_address(scheduler)
        if scheme == "inproc":  # valid only for a scheduler inside this very process
            from distributed.comm.inproc import global_manager

            try:
                listener = global_manager.get_listener_for(loc)
            except ValueError:  # not even inproc's ip/pid/n form
                listener = None
            if listener is None:
                raise ValueError("no scheduler of this process; inproc:// stays in-process")
            return
        get_backend(scheme)
        parse_host_port(loc)
    except (ValueError, TypeError) as exc:
        raise EyevizError(
            f"scheduler must be {example}, got {scheduler!r} ({_one_line(exc)})"
        ) from None


def _probe(scheduler: str, timeout: float) -> None:
    """Open and close one connection to the scheduler within ``timeout`` s (no Client:
    nothing left to clean up when it fails)."""
    import asyncio
    import socket

    from distributed.comm import connect
    from distributed.comm.addressing import parse_address, parse_host_port

    scheme, loc = parse_address(scheduler)
    if scheme in ("tcp", "tls", "ws", "wss"):  # a refused port fails now, not after retries
        socket.create_connection(parse_host_port(loc), timeout=timeout).close()

    async def once() -> None:
        comm = await asyncio.wait_for(connect(scheduler, timeout=timeout), timeout)
        await comm.close()

    asyncio.run(once())


def _connect(scheduler: str | None, workers: int | None, timeout: float):
    """A Client (and the LocalCluster it owns, or None on a user's cluster)."""
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            _probe(scheduler, timeout)
            client = Client(scheduler, timeout=timeout, set_as_default=False)
        except Exception as exc:  # OSError, TimeoutError, ValueError (a bad address)...
            raise EyevizError(
                f"cannot reach the Dask scheduler at {scheduler!r} within {timeout:g} s "
                f"({_one_line(exc)})"
            ) from None
        return client, None
    n = workers if workers is not None else _cores()
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.CRITICAL,
        preload=["eyeviz.study._worker"],  # workers ignore Ctrl-C, restarted ones too
    )
    try:
        client = Client(cluster, set_as_default=False)
    except BaseException:
        cluster.close()
        raise
    return client, cluster


@contextlib.contextmanager
def _signals_deferred():
    """Hold Ctrl-C, SIGTERM and SIGHUP while a cluster starts, then deliver them.

    Interrupted half-way, distributed can neither close the cluster nor stop its worker
    processes (they outlive eyeviz). A signal arriving meanwhile is noted and raised
    again on leaving, when the cluster is whole and the caller's ``finally`` closes it.
    (Ignoring SIGINT instead would let the worker processes inherit the ignoring, but a
    Ctrl-C could then be lost: multiprocessing unblocks signals in the spawning thread.)
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    names = ("SIGINT", "SIGTERM", "SIGHUP")
    sigs = [getattr(signal, n) for n in names if hasattr(signal, n)]
    got: list[int] = []
    old = {s: signal.signal(s, lambda signum, _frame: got.append(signum)) for s in sigs}
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
        if got:
            signal.raise_signal(got[0])


def _close(client, cluster) -> None:
    with contextlib.suppress(Exception):
        client.close(timeout=10)
    if cluster is not None:
        with contextlib.suppress(Exception):
            cluster.close(timeout=20)


def _check_rows(p: Point, rows) -> list[dict]:
    if not isinstance(rows, list) or not rows:
        raise EyevizError(f"a worker returned no rows for {_describe(p)}")
    for r in rows:
        if not isinstance(r, dict) or tuple(r) != columns_of(p):
            raise EyevizError(f"a worker returned malformed rows for {_describe(p)}")
        if (r["h"], r["l"], r["m"], r["n"], r["seed"], r["prior"]) != (
            p.h, p.l, p.m, p.n, p.seed, p.prior,
        ):  # fmt: skip
            raise EyevizError(f"a worker returned the rows of another point for {_describe(p)}")
    return rows


_MALLOC_TUNED = False
# glibc's mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def tune_malloc() -> bool:
    """Let glibc keep the limit's temporary arrays on the heap (once per process).

    Dask's nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which pins glibc's
    mmap threshold at 128 kB: every temporary array of the integration is then a fresh
    mmap, page-faulted afresh (measured: a point 2.5 s -> 6.5 s, sys time 0.1 -> 3.0 s,
    250x the page faults). Raising both thresholds (mmap 32 MiB, trim 256 MiB) undoes it
    on any worker, the user's cluster too. Returns False where there is no glibc.
    """
    global _MALLOC_TUNED
    if _MALLOC_TUNED:
        return True
    try:
        import ctypes
        import ctypes.util

        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        ok = bool(libc.mallopt(_M_MMAP_THRESHOLD, 32 << 20))
        ok &= bool(libc.mallopt(_M_TRIM_THRESHOLD, 256 << 20))
    except (OSError, AttributeError):
        return False
    _MALLOC_TUNED = ok
    return ok


def evaluate_on_worker(point: Point) -> list[dict]:
    """The task a worker runs: :func:`~eyeviz.study.point.evaluate` after
    :func:`tune_malloc`."""
    tune_malloc()
    return evaluate(point) if isinstance(point, DesignPoint) else evaluate3d(point)


def connect_timeout_for(scheduler: str | None, connect_timeout: float) -> float:
    """Dask's connect timeout for a study: the short one for a user's scheduler, which may
    not exist; at least :data:`LOCAL_CONNECT_S` for a local cluster, whose processes start
    on this machine, which may be busy (a nanny took over 5 s in a loaded test run)."""
    return connect_timeout if scheduler else max(connect_timeout, LOCAL_CONNECT_S)


def dask_config(connect_timeout: float = CONNECT_TIMEOUT_S) -> dict:
    """The dask settings a study runs under (``dask.config.set``)."""
    return {
        "distributed.scheduler.allowed-failures": ALLOWED_FAILURES,
        "distributed.comm.timeouts.connect": f"{connect_timeout}s",
        # points take seconds: a worker holds only the point it computes (no prefetch),
        # so the last points spread over every worker and a killed worker loses just one
        "distributed.scheduler.worker-saturation": 1.0,
    }


@contextlib.contextmanager
def _exclusive(path):
    """Hold ``.NAME.lock`` beside the table: a second study into the same file is refused
    at once (one line) instead of both appending to the table and losing points. The lock is
    the kernel's (``flock``): a crashed study leaves none held.

    It acts on the resolved file (issue 25): a symlinked ``-o`` is locked beside its
    target, and an existing table is also locked itself (its inode), so the same file
    under another name (a hard link) is refused too."""
    try:
        import fcntl
    except ImportError:  # no flock (Windows): no protection, as before
        yield
        return
    target = Path(os.path.realpath(path))
    lock = target.with_name(f".{target.name}.lock")
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise EyevizError(f"cannot create the study's lock file {str(lock)!r}: {exc}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise EyevizError(
                f"another study is writing {str(target)!r} (its lock {lock.name} is held); "
                "wait for it or write to another -o"
            ) from None
        try:  # the file we locked may have been removed by a study that just finished
            same = os.path.samestat(os.fstat(fd), os.stat(lock))
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        held = _lock_inode(fcntl, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(lock)
        os.close(fd)
        raise
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            os.unlink(lock)
        os.close(fd)
        if held is not None:
            os.close(held)


def _lock_inode(fcntl, target: Path) -> int | None:
    """flock the existing table itself (shared by all its hard links); its descriptor,
    or None when there is no table yet (or it cannot be opened: the reader says why)."""
    try:
        fd = os.open(target, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise EyevizError(
            f"another study is writing {str(target)!r} under another name (a hard link to "
            "the same file); wait for it or write to another -o"
        ) from None
    except OSError:
        os.close(fd)
        return None
    return fd


def run_study(
    path,
    points: Iterable[Point],
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    *,
    connect_timeout: float = CONNECT_TIMEOUT_S,
) -> StudySummary:
    """Evaluate every design point not yet in the table at ``path``, on Dask.

    ``workers``: local worker processes (default: one per usable CPU, affinity and cgroup
    quota, :mod:`eyeviz.study.cpus`); ``scheduler``: the
    address of an existing Dask scheduler instead (then ``workers`` must be None).
    Points (planar or 3D, :mod:`eyeviz.study.kinds`) already in the table (same
    ``key``) are skipped; each finished point is appended as it arrives (in place, whole
    points only: :class:`~eyeviz.study.table.StudyTable`).
    Returns a
    :class:`StudySummary`; raises :class:`StudyFailed` when some points failed (the
    others are kept), :class:`EyevizError` for an unreadable table, a bad worker count
    or an unreachable scheduler, and lets KeyboardInterrupt through after closing the
    cluster (the finished points are kept).
    """
    with _exclusive(path):
        return _run(path, points, workers, scheduler, progress, connect_timeout)


# long: the study's run loop inside one try/finally that owns the cluster, the signals and the
# partial table
def _run(path, points, workers, scheduler, progress, connect_timeout) -> StudySummary:
    t0 = time.perf_counter()
    unique: dict[tuple, Point] = {}
    for p in points:
        if not isinstance(p, POINT_TYPES):
            raise EyevizError(f"a study point must be a DesignPoint, got {type(p).__name__}")
        unique.setdefault(p.key, p)
    # a bad or foreign file is refused before any work
    table = open_table(path, list(unique.values()))
    # largest first (the cost grows with n and m, and h): the last points to finish are
    # small ones, so no worker waits long at the end of the study
    todo = sorted(
        (p for p in unique.values() if p.key not in table.keys), key=lambda p: (-p.n * p.m, -p.h)
    )
    skipped = len(unique) - len(todo)
    if scheduler is not None and workers is not None:
        raise EyevizError("--workers sets up a local cluster; with --scheduler leave it out")
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= MAX_WORKERS
    ):
        raise EyevizError(f"workers must be an integer in [1, {MAX_WORKERS}], got {workers!r}")
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler.strip()):
        msg = f"scheduler must be an address such as tcp://host:8786, got {scheduler!r}"
        raise EyevizError(msg)
    if scheduler is not None:
        check_scheduler(scheduler)

    def summary(
        computed: int, n_workers: int, failures: list[str], resubmitted: int = 0
    ) -> StudySummary:
        return StudySummary(
            str(path),
            len(unique),
            computed,
            skipped,
            n_workers,
            time.perf_counter() - t0,
            scheduler,
            tuple(failures),
            resubmitted,
        )

    if not todo:
        return summary(0, 0, [])

    import dask
    from distributed import as_completed
    from tqdm import tqdm

    config = dask_config(connect_timeout_for(scheduler, connect_timeout))
    computed = 0
    failures: list[str] = []
    resubmitted = 0
    bar = None
    client = cluster = None
    n_workers = 0
    try:
        with dask.config.set(config), _signals_deferred(), warnings.catch_warnings():
            # the scheduler's HTTP routes move off a busy port 8787: no reason to warn
            warnings.filterwarnings("ignore", r"Port \d+ is already in use", UserWarning)
            client, cluster = _connect(scheduler, workers, connect_timeout)
        n_workers = len(client.scheduler_info(n_workers=-1).get("workers", {}))
        tag = secrets.token_hex(4)
        owner: dict = {}
        attempts: dict[tuple, int] = {}
        serial = itertools.count()  # a resubmitted point gets a key of its own

        def submit(p: Point):
            attempts[p.key] = attempts.get(p.key, 0) + 1
            key = f"eyeviz-study-h{p.h:g}-l{p.l:g}-m{p.m}-{tag}-{next(serial)}"
            fut = client.submit(evaluate_on_worker, p, key=key, pure=False, retries=1)
            owner[fut.key] = p
            return fut

        bar = tqdm(total=len(todo), unit="point", desc="study", disable=not progress)
        ac = as_completed([submit(p) for p in todo], loop=client.loop, with_results=False)
        for fut in ac:
            p = owner.pop(fut.key)
            if fut.status == "finished":
                table.append(_check_rows(p, fut.result()))
                computed += 1
                bar.update(1)
            else:
                exc = fut.exception() if fut.status == "error" else None
                killed = type(exc).__name__ == "KilledWorker" or fut.status == "cancelled"
                if killed and attempts[p.key] <= RESUBMITS:
                    ac.add(submit(p))
                    resubmitted += 1
                else:
                    hint = ""
                    if isinstance(exc, ModuleNotFoundError):
                        hint = " (is eyeviz installed on the workers?)"
                    msg = _one_line(exc) if exc is not None else fut.status
                    failures.append(f"{_describe(p)}: {msg}{hint}")
            fut.release()
    finally:
        if bar is not None:
            bar.close()
        if client is not None:
            _close(client, cluster)
    result = summary(computed, n_workers, failures, resubmitted)
    if failures:
        raise StudyFailed(result)
    return result
