"""Compiled (numba) kernels of the core's hot paths (docs/kernels.md).

Each kernel has a numpy reference it must agree with element by element; ``EYEVIZ_JIT=0``
runs the reference everywhere. :func:`enabled` says whether the kernels may be used.
"""

from __future__ import annotations

import importlib.util
import os

import numpy as np

__all__ = ["arg", "enabled", "use", "warm", "warm_in_background", "defer_until_warm", "mark_ready"]

_STATE: dict[str, bool | None] = {"ready": False, "defer": False, "found": None}
#: Calls of fewer items than this do not load cold kernels (see :func:`use`)
COLD_WORK = 64


def enabled() -> bool:
    """The compiled kernels are in use: numba imports and EYEVIZ_JIT is not 0."""
    if os.environ.get("EYEVIZ_JIT", "1").strip() in ("0", "false", "no", "off"):
        return False
    # found, not imported: importing numba takes a second, which a caller on a GUI
    # thread must not pay (the kernel modules import it when first used)
    found = _STATE["found"]
    if found is None:  # looked up once: find_spec costs more than a one-ball call's kernel
        found = _STATE["found"] = importlib.util.find_spec("numba") is not None
    return bool(found)


def use(work: int = 1 << 30) -> bool:
    """Call the kernels now for ``work`` items (balls). Yes once they are warm. Before: no
    in an app that defers them to a background warm-up; else yes for calls of at least
    ``COLD_WORK`` items (the caller loads them from numba's cache, about a second, or
    compiles them once), and no for smaller ones, which the reference answers sooner
    (``eyeviz snapshot`` of one scene stays within its time)."""
    if not enabled():
        return False
    if _STATE["ready"]:
        return True
    return not _STATE["defer"] and work >= COLD_WORK


#: The kernel modules, each with a ``warm()`` (scripts/setup.sh compiles the healpix_*
#: ones in one process and the others in another: about equal halves of the cold compile,
#: each half's modules sharing their helpers)
KERNELS = (
    "healpix_lit",
    "healpix_match",
    "limit3d_region",
    "measured_lit",
    "healpix_cells",
    "measured_limit",
    "healpix_boundary",
    "limit3d_affine",
    "limit3d_locate",
    "limit3d_draws",
)


def warm(names: tuple[str, ...] = KERNELS) -> None:
    """Compile (or load from numba's cache) the kernels of the modules ``names`` (of
    :data:`KERNELS`, default all) by running them on small inputs."""
    if not enabled():
        return
    unknown = sorted(set(names) - set(KERNELS))
    if unknown:
        raise ValueError(f"no kernel module {unknown[0]!r}; known: {', '.join(KERNELS)}")
    for name in names:
        importlib.import_module(f"eyeviz.core.kernels.{name}").warm()
    _STATE["ready"] = True


def defer_until_warm() -> None:
    """Use the numpy reference until the kernels are warm (see :func:`warm_in_background`)."""
    _STATE["defer"] = True


def warm_in_background():
    """Start warming the kernels on a daemon thread; returns the thread (or None)."""
    if not enabled() or _STATE["ready"]:
        return None
    import threading

    defer_until_warm()
    t = threading.Thread(target=warm, name="eyeviz-kernels-warm", daemon=True)
    t.start()
    return t


def mark_ready() -> None:
    """A kernel ran: it is loaded, later calls of any size use it."""
    _STATE["ready"] = True


def arg(a, dtype=None) -> np.ndarray:
    """``a`` as a kernel takes it: C-contiguous and writable (numba types a read-only
    array, e.g. a broadcast view, apart: it would compile a new signature at run time)."""
    if type(a) is np.ndarray and (dtype is None or a.dtype == dtype):  # as it is: no copy
        f = a.flags
        if f.c_contiguous and f.writeable:
            return a
    return np.require(a, dtype, ("C", "W"))
