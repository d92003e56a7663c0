"""Where the paper's weights live and how they are read and written (never pickled
objects: ``torch.load(weights_only=True)``). Search order: see :mod:`eyeviz.estimators.store`.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import torch
from torch import nn

from eyeviz import EyevizError
from eyeviz.estimators.paper.nets import SPECS, build
from eyeviz.estimators.store import user_models_dir
from eyeviz.resources import assets_dir, models_dir

WEIGHTS_HINT = "eyeviz train paper --budget 600"


def _repo_dir() -> Path:
    return models_dir() / "paper"


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "eyeviz" / "models" / "paper"


def weights_dirs() -> list[Path]:
    """Where the weights are looked for: $EYEVIZ_PAPER_DIR alone when it is set, else
    assets/models/paper/, then <user models>/paper (where ``eyeviz train paper`` writes by
    default), then the old user cache (~/.cache/eyeviz/models/paper)."""
    env = os.environ.get("EYEVIZ_PAPER_DIR")
    if env:
        return [Path(env)]
    return [_repo_dir(), user_models_dir() / "paper", _cache_dir()]


def default_out_dir() -> Path:
    """$EYEVIZ_PAPER_DIR when set, else <user models>/paper; never the shipped assets
    (those take ``eyeviz train paper --into-assets``)."""
    env = os.environ.get("EYEVIZ_PAPER_DIR")
    if env:
        return Path(env)
    return user_models_dir() / "paper"


def shown_dir(d: Path) -> str:
    """``d`` as a message names it, the same on every machine: the shipped assets as
    ``eyeviz/assets/...`` (the installed package's folder), a folder under the home folder
    as ``~/...``, else as given."""
    package = assets_dir().parent
    try:
        return f"{package.name}/{d.relative_to(package).as_posix()}"
    except ValueError:
        pass
    try:
        return f"~/{d.relative_to(Path.home()).as_posix()}"
    except ValueError:
        return str(d)


def find_weights(name: str, path: str | os.PathLike | None = None) -> Path:
    """The ``<name>.pt`` weights file; one-line error naming the command that makes it."""
    dirs = [Path(path)] if path is not None else weights_dirs()
    for d in dirs:
        f = d / f"{name}.pt"
        if f.is_file():
            return f
    where = ", ".join(shown_dir(d) for d in dirs)
    raise EyevizError(
        f"paper network weights {name}.pt not found (looked in {where}); "
        f"make them with `{WEIGHTS_HINT}` (weights are not shipped: ~243 MB + ~133 MB)"
    )


def _atomic_write(path: Path, write) -> None:
    """``write(tmp)`` into a temporary file next to ``path``, then rename it over ``path``."""
    from eyeviz.files.atomic import atomic_output

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        write(str(tmp))


def _save_json(path: Path, obj: dict) -> None:
    def write(tmp):
        with open(tmp, "w", encoding="utf-8") as fh:
            json.dump(obj, fh, indent=2, sort_keys=False)
            fh.write("\n")

    _atomic_write(path, write)


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def load_net(name: str, path=None, device: str = "cpu") -> tuple[nn.Module, dict]:
    """(net, metadata) for "ad" or "dd"; metadata is {} when the JSON is missing."""
    spec = SPECS[name]
    f = find_weights(name, path)
    net = build(spec)
    try:
        state = torch.load(f, map_location=device, weights_only=True)
        net.load_state_dict(state["model"] if "model" in state else state)
    except Exception as exc:  # a truncated or foreign file: say which one
        raise ValueError(f"cannot read paper weights {f}: {type(exc).__name__}: {exc}") from None
    net.to(device).eval()
    meta_f = f.with_suffix(".json")
    meta = json.loads(meta_f.read_text()) if meta_f.is_file() else {}
    return net, meta
