"""How many CPUs this process may use: its affinity and its cgroup's CPU quota.

A container limited to 2 CPUs on a 64-core host still reports 64 through
``os.cpu_count()``; a local Dask cluster sized from that starts 64 workers that share
2 CPUs and run slower than one (issue 25: on a 2-core machine 2 and 4 workers were
slower than 1). :func:`usable_cpus` takes the smallest of the affinity mask and the
quota (cgroup v2 ``cpu.max``, v1 ``cpu.cfs_quota_us`` / ``cpu.cfs_period_us``), on the
process's own cgroup and its parents.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

__all__ = ["cgroup_quota", "usable_cpus", "workers_warning"]


def _read(path: Path) -> str | None:
    try:
        return path.read_text(encoding="ascii", errors="replace")[:4096].strip()
    except OSError:
        return None


def _own_paths(root: Path) -> tuple[str | None, str | None]:
    """The process's cgroup path in the v2 hierarchy and in v1's cpu controller."""
    text = _read(root / "proc/self/cgroup") or ""
    v2 = v1 = None
    for line in text.splitlines():
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        if parts[0] == "0" and parts[1] == "":
            v2 = parts[2]
        elif "cpu" in parts[1].split(","):
            v1 = parts[2]
    return v2, v1


def _ancestors(base: Path, rel: str | None) -> list[Path]:
    parts = [p for p in (rel or "/").split("/") if p and p != ".."]
    return [base.joinpath(*parts[:i]) for i in range(len(parts), -1, -1)]


def cgroup_quota(root: str | os.PathLike = "/") -> float | None:
    """CPUs the cgroup quota allows (quota / period, the tightest along the path), or
    None when there is no quota. ``root``: the file system root (tests use a fake one)."""
    root = Path(root)
    v2, v1 = _own_paths(root)
    best: float | None = None

    def take(q: float) -> None:
        nonlocal best
        if q > 0 and math.isfinite(q):
            best = q if best is None else min(best, q)

    for d in _ancestors(root / "sys/fs/cgroup", v2):
        fields = (_read(d / "cpu.max") or "").split()
        if len(fields) == 2 and fields[0] != "max":
            try:
                take(int(fields[0]) / int(fields[1]))
            except (ValueError, ZeroDivisionError):
                pass
    for base in (root / "sys/fs/cgroup/cpu", root / "sys/fs/cgroup/cpu,cpuacct"):
        for d in _ancestors(base, v1):
            try:
                quota = int(_read(d / "cpu.cfs_quota_us") or "-1")
                period = int(_read(d / "cpu.cfs_period_us") or "0")
            except ValueError:
                continue
            if quota > 0 and period > 0:
                take(quota / period)
    return best


def usable_cpus(root: str | os.PathLike = "/") -> int:
    """CPUs this process may use: its affinity (``os.sched_getaffinity``), capped by the
    cgroup quota rounded up; at least 1."""
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        n = os.cpu_count() or 1
    q = cgroup_quota(root)
    if q is not None:
        n = min(n, math.ceil(q - 1e-9))
    return max(1, n)


def workers_warning(workers: int, cpus: int | None = None) -> str | None:
    """A one-line warning when ``workers`` local processes exceed the usable CPUs (the
    added workers only share them, each with its own copy of the data), else None."""
    cpus = usable_cpus() if cpus is None else cpus
    if workers <= cpus:
        return None
    return (
        f"--workers {workers} exceeds the {cpus} CPU(s) this process may use (affinity "
        f"and cgroup quota): the extra workers cannot help and may slow the study; "
        f"--workers {cpus} or fewer"
    )
