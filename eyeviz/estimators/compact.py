"""Compact networks: two tiny MLPs on features of the four lit-interval integers.

A bitmap pair is fully described by (LA, RA, LB, RB) (Prop. 2), so instead of the
paper's 720 bits (Appendix A/B, 60 M and 33 M weights) each network reads 11 numbers
derived from them: the edge disparities LB - LA and RB - RA (the stereo cue for distance),
the widths and their logs (the size cue), the mean centre angle, and the analytic
triangulation itself (:mod:`eyeviz.estimators.analytic`). Each network predicts a
correction to the triangulation:

- DD: log r = log r_analytic + f(x), trained on the relative error |r_hat / r - 1|
  (the MAPE of Eq. 34), so it learns the 1/r-weighted posterior median;
- AD: phi = phi_analytic + 1e-3 * f(x), trained on |phi_hat / phi - 1|; its last layer
  starts at zero, so training starts from the triangulation.

Weights: ``assets/models/compact_dd.pt`` and ``compact_ad.pt`` (a few kB each) with
``compact.json`` (data parameters, seed, metrics, training time, command).
This module loads them; the features, the network and the estimator class are
:mod:`eyeviz.estimators.compact_net`, training is :mod:`eyeviz.estimators.compact_training`
(``train`` and ``fit`` are re-exported here). These three and ``paper`` are the only
estimator modules that import torch.
"""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

import torch

from eyeviz import EyevizError
from eyeviz.estimators.base import Domain
from eyeviz.estimators.compact_net import N_FEATURES, CompactEstimator, CompactNet, features
from eyeviz.estimators.compact_training import fit, train
from eyeviz.files import limits
from eyeviz.files.npz import one_line
from eyeviz.resources import models_dir

__all__ = [
    "CompactEstimator",
    "CompactNet",
    "default_dir",
    "features",
    "fit",
    "load",
    "train",
]


def default_dir() -> Path:
    return models_dir()


def _expected_shapes(hidden: int) -> dict[str, tuple[int, ...]]:
    """The state of ``CompactNet(hidden)``: parameter name -> shape."""
    return {
        "net.0.weight": (hidden, N_FEATURES),
        "net.0.bias": (hidden,),
        "net.2.weight": (hidden, hidden),
        "net.2.bias": (hidden,),
        "net.4.weight": (1, hidden),
        "net.4.bias": (1,),
    }


def _check_zip(path: Path) -> None:
    """A torch zip file whose every member matches its CRC-32: torch itself reads the
    records without checking them, so a flipped bit in the weights would load silently."""
    try:
        with zipfile.ZipFile(path) as zf:
            bad = zf.testzip()
    except Exception as exc:  # noqa: BLE001 - BadZipFile, EOFError, zlib.error, ...
        raise EyevizError(
            f"{str(path)!r}: not a torch zip weights file ({one_line(exc, 120)})"
        ) from None
    if bad is not None:
        raise EyevizError(f"{str(path)!r}: member {bad!r} fails its CRC check (corrupted)")


def _load_net(path: Path) -> CompactNet:
    """One network file, checked before anything it declares is built: a bounded regular
    file, read by ``torch.load(weights_only=True)`` (no code can run), holding
    ``{"hidden": int, "state": {name: finite float tensor}}`` with exactly the shapes of
    ``CompactNet(hidden)``; ``hidden`` at most :data:`limits.MAX_HIDDEN`."""
    name = path.name
    limits.check_file_size(path, limits.MAX_MODEL_FILE_BYTES, "compact weights file")
    _check_zip(path)
    try:
        obj = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - UnpicklingError, EOFError, zip damage, ...
        raise EyevizError(
            f"{str(path)!r}: not a readable weights file ({type(exc).__name__}: "
            f"{one_line(exc, 120)})"
        ) from None
    if not isinstance(obj, dict) or "hidden" not in obj or not isinstance(obj.get("state"), dict):
        raise EyevizError(f"{str(path)!r}: expected {{'hidden': int, 'state': {{...}}}}")
    hidden = limits.check_hidden(name, obj["hidden"])
    state = obj["state"]
    want = _expected_shapes(hidden)
    if set(state) != set(want):
        raise EyevizError(
            f"{str(path)!r}: state has parameters {sorted(map(str, state))[:8]}, "
            f"expected {sorted(want)}"
        )
    for key, shape in want.items():
        t = state[key]
        if not isinstance(t, torch.Tensor) or not t.is_floating_point():
            raise EyevizError(f"{str(path)!r}: {key} is not a float tensor")
        if tuple(t.shape) != shape:
            raise EyevizError(
                f"{str(path)!r}: {key} has shape {tuple(t.shape)}, expected {shape} "
                f"for hidden = {hidden}"
            )
        if not bool(torch.isfinite(t).all()):
            raise EyevizError(f"{str(path)!r}: {key} holds NaN or infinite weights")
    net = CompactNet(hidden)
    try:
        net.load_state_dict(state)
    except (RuntimeError, TypeError, ValueError) as exc:
        raise EyevizError(f"{str(path)!r}: {one_line(exc, 160)}") from None
    return net


def _member(d: Path, files: object, key: str) -> Path:
    """``files[key]`` of compact.json: a relative path inside the model directory."""
    meta_f = d / "compact.json"
    name = files.get(key) if isinstance(files, dict) else None
    if not isinstance(name, str) or not name or "\0" in name:
        raise EyevizError(f"{str(meta_f)!r}: files.{key} must be a file name, got {name!r}")
    rel = Path(name)
    if rel.is_absolute() or ".." in rel.parts:
        raise EyevizError(
            f"{str(meta_f)!r}: files.{key} = {name!r} must stay inside the model directory"
        )
    if not (d / rel).is_file():
        raise EyevizError(f"{str(meta_f)!r}: files.{key} = {name!r} is not a file in {str(d)!r}")
    return d / rel


def load(path: str | os.PathLike | None = None, domain: Domain | None = None) -> CompactEstimator:
    """Weights from ``path`` (a directory with compact.json), default assets/models/.

    Every problem with the directory is one EyevizError line naming the file: compact.json
    (bounded size, a JSON object, ``files.dd`` / ``files.ad`` inside the directory,
    ``data`` a valid domain, m within :data:`eyeviz.core.bounds.MAX_M`) and each weights file
    (:func:`_load_net`). Nothing is unpickled."""
    d = Path(path) if path is not None else default_dir()
    meta_f = d / "compact.json"
    if not meta_f.is_file():
        raise EyevizError(
            f"compact weights not found in {d} (no compact.json); "
            f"train them with `eyeviz train compact -o {d}`"
        )
    raw = limits.read_bounded(meta_f, limits.MAX_MODEL_META_BYTES, "model metadata")
    try:
        meta = json.loads(raw)
    except (ValueError, RecursionError) as exc:
        raise EyevizError(f"{str(meta_f)!r}: not valid JSON ({one_line(exc, 120)})") from None
    if not isinstance(meta, dict):
        raise EyevizError(f"{str(meta_f)!r}: expected a JSON object, got {type(meta).__name__}")
    files = meta.get("files")
    dd = _load_net(_member(d, files, "dd"))
    ad = _load_net(_member(d, files, "ad"))
    if domain is None:
        data = meta.get("data")
        if not isinstance(data, dict):
            raise EyevizError(f"{str(meta_f)!r}: 'data' must be an object with the domain")
        try:
            dom = Domain.from_dict(data)  # EyePair's checks: m <= core.bounds.MAX_M
        except (ValueError, TypeError, OverflowError) as exc:
            raise EyevizError(f"{str(meta_f)!r}: bad data ({one_line(exc, 160)})") from None
    else:
        dom = domain
    return CompactEstimator(dd, ad, dom, meta)
