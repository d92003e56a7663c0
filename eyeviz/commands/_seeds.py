"""Seeds of the random commands (``generate``, ``train``): a fresh one unless one is given,
never one the shipped models were trained or validated on.

Two runs without ``--seed`` used to write the same "train" and "test" files (seed 0), and
the shipped compact weights were trained on seed 0 with the paper's parameters: a "test"
set made that way was their training set. A drawn seed is printed (and stored in an NPZ's
metadata and a model's metadata); an explicit seed that draws a shipped model's training
or validation set (the same seed, parameters and mode) is warned about.
"""

from __future__ import annotations

import json
import math
import secrets
from dataclasses import dataclass
from pathlib import Path

from eyeviz.resources import models_dir

__all__ = ["ShippedSeed", "fresh_seed", "same_sets", "shipped_seeds"]

SEED_BITS = 32  # a drawn seed is < 2^32: short enough to type back
_DOMAIN_KEYS = {
    "planar": ("h", "l", "m", "r_min", "r_max", "g_max"),
    "spherical": ("h", "l", "nside", "r_min", "r_max", "g_max", "el_max"),
}
_META_MAX = 1 << 20  # bytes of a shipped metadata file read here


@dataclass(frozen=True)
class ShippedSeed:
    """One data set a shipped model was fitted on: its seed, parameters and where said."""

    seed: int
    domain: tuple[float, ...]  # h, l, m, r_min, r_max, g_max (spherical: _DOMAIN_KEYS)
    mode: str
    what: str  # "the compact weights' training set (models/compact.json)"
    kind: str = "planar"  # or "spherical" (a 3D data set)


def _domain(d: dict, kind: str = "planar") -> tuple[float, ...] | None:
    try:
        return tuple(float(d[k]) for k in _DOMAIN_KEYS[kind])
    except (KeyError, TypeError, ValueError):
        return None


def _json(path: Path) -> dict:
    try:
        if path.stat().st_size > _META_MAX:
            return {}
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return doc if isinstance(doc, dict) else {}


def _bayes_meta(path: Path) -> dict:
    import numpy as np

    try:
        with np.load(path, allow_pickle=False) as z:
            if "meta" not in z.files:
                return {}
            doc = json.loads(str(z["meta"])[:_META_MAX])
    except (OSError, ValueError, KeyError):
        return {}
    return doc if isinstance(doc, dict) else {}


def shipped_seeds(root: Path | None = None) -> list[ShippedSeed]:
    """The data sets the shipped models were fitted on, read from their metadata: the
    compact weights' training and validation seeds, the bayes table's sampling seed and the
    paper networks' data seeds."""
    root = models_dir() if root is None else root
    out: list[ShippedSeed] = []
    doc = _json(root / "compact.json").get("data", {})
    dom = _domain(doc) if isinstance(doc, dict) else None
    if dom is not None:
        for key, what in (("train_seed", "training"), ("val_seed", "validation")):
            if isinstance(doc.get(key), int):
                out.append(
                    ShippedSeed(
                        doc[key],
                        dom,
                        str(doc.get("mode", "single")),
                        f"the compact weights' {what} set (models/compact.json)",
                    )
                )
    meta = _bayes_meta(root / "bayes.npz")
    dom = _domain(meta.get("domain", {}) or {})
    if dom is not None and isinstance(meta.get("seed"), int):
        out.append(
            ShippedSeed(
                meta["seed"],
                dom,
                str(meta.get("mode", "single")),
                "the bayes table's samples (models/bayes.npz)",
            )
        )
    doc = _json(root / "learned3d" / "learned3d.json").get("data", {})
    dom = _domain(doc, "spherical") if isinstance(doc, dict) else None
    if dom is not None:
        for key, what in (("train_seed", "training"), ("val_seed", "validation")):
            if isinstance(doc.get(key), int):
                out.append(
                    ShippedSeed(
                        doc[key],
                        dom,
                        str(doc.get("mode", "single")),
                        f"the learned3d weights' {what} set (models/learned3d/learned3d.json)",
                        "spherical",
                    )
                )
    for path in sorted((root / "paper").glob("*.json")):
        data = _json(path).get("data", {})
        dom = _domain(data) if isinstance(data, dict) else None
        if dom is not None and isinstance(data.get("seed"), int):
            out.append(
                ShippedSeed(
                    data["seed"],
                    dom,
                    str(data.get("mode", "single")),
                    f"the paper networks' data (models/paper/{path.name})",
                )
            )
    return out


def fresh_seed(avoid: set[int] | None = None) -> int:
    """A seed drawn from the OS's entropy, below 2^32, none of ``avoid`` (default: every
    shipped model's seed)."""
    avoid = {s.seed for s in shipped_seeds()} if avoid is None else avoid
    while True:
        seed = secrets.randbits(SEED_BITS)
        if seed not in avoid:
            return seed


def same_sets(seed: int, domain: dict, mode: str, kind: str = "planar") -> list[str]:
    """What shipped models were fitted on the set that ``seed`` draws with these parameters
    (``domain``: h, l, m, r_min, r_max, g_max; spherical: h, l, nside, r_min, r_max, g_max,
    el_max) and ``mode``; empty when none."""
    dom = _domain(domain, kind)
    if dom is None:
        return []
    return [
        s.what
        for s in shipped_seeds()
        if s.seed == seed
        and s.kind == kind
        and s.mode == mode
        and all(math.isclose(a, b, rel_tol=1e-12) for a, b in zip(s.domain, dom, strict=True))
    ]
