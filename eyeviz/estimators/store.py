"""Where trained models go, and how they get there without breaking the old ones.

Order of places (documented once, here):

- **Training** writes to ``-o DIR`` when given, else to the user models directory
  :func:`user_models_dir` (``$EYEVIZ_HOME/models`` when ``EYEVIZ_HOME`` is set, else
  ``$XDG_DATA_HOME/eyeviz/models``, default ``~/.local/share/eyeviz/models``). It writes
  into the shipped assets (``eyeviz/assets/models``) only with ``--into-assets``.
- **Loading** (``eyeviz predict``, the app, the reports) reads the shipped assets, except
  where the user points elsewhere with ``--weights DIR`` (``path=`` in Python). The paper's
  networks, which are not shipped, are looked for in ``$EYEVIZ_PAPER_DIR`` alone when set,
  else ``assets/models/paper``, then ``<user models>/paper``, then the old cache
  ``~/.cache/eyeviz/models/paper``.

:func:`staged` is the swap: a fit writes every file (weights and metadata) into a fresh
hidden directory next to the target; only when the fit returned are the files moved into
place, metadata last, with SIGINT held during the moves. Ctrl-C (or any exception) before
that removes the staging directory and leaves the previous model untouched and consistent.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Iterator
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.files.atomic import full_disk_error

__all__ = ["user_models_dir", "staged", "resolve_out_dir"]


def user_models_dir() -> Path:
    """``$EYEVIZ_HOME/models``, else ``$XDG_DATA_HOME/eyeviz/models`` (~/.local/share)."""
    home = os.environ.get("EYEVIZ_HOME")
    if home:
        return Path(home) / "models"
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(
        os.path.expanduser("~"), ".local", "share"
    )
    return Path(base) / "eyeviz" / "models"


def resolve_out_dir(out: str | os.PathLike | None, into_assets: bool, subdir: str = "") -> Path:
    """The training output directory: ``out``, the shipped assets (``into_assets``) or the
    user models directory; ``-o`` and ``--into-assets`` together are refused."""
    from eyeviz.resources import models_dir

    if out is not None and into_assets:
        raise EyevizError("give either -o DIR or --into-assets, not both")
    if out is not None:
        return Path(out)
    base = models_dir() if into_assets else user_models_dir()
    return base / subdir if subdir else base


@contextlib.contextmanager
def _sigint_held() -> Iterator[None]:
    """Defer Ctrl-C (main thread only) until the block is done."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list = []
    old = signal.signal(signal.SIGINT, lambda *a: got.append(a))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
        if got:
            raise KeyboardInterrupt


@contextlib.contextmanager
def staged(out_dir: str | os.PathLike) -> Iterator[Path]:
    """Yield a fresh staging directory next to ``out_dir``; on success move its files into
    ``out_dir`` (``*.json`` metadata last), on any exception leave ``out_dir`` as it was."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise EyevizError(f"output {str(out)!r} exists and is not a directory")
    if not out.parent.is_dir() and not out.parent.parent.is_dir():
        out.parent.mkdir(parents=True, exist_ok=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.staging-", dir=out.parent))
    try:
        yield tmp
        files = sorted(
            (p for p in tmp.rglob("*") if p.is_file()), key=lambda p: (p.suffix == ".json", p)
        )
        with _sigint_held():
            out.mkdir(parents=True, exist_ok=True)
            for f in files:
                dest = out / f.relative_to(tmp)
                dest.parent.mkdir(parents=True, exist_ok=True)
                os.replace(f, dest)
    except OSError as exc:  # a full disk while a fit writes its files: name the output
        full = full_disk_error(out, exc)
        if full is None:
            raise
        raise full from exc
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
