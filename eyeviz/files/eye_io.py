"""Reading and writing measured eye pairs: CompoundRay ``.eye`` and OCES glTF (``.gltf``,
``.glb``), chosen by the file's suffix (docs/eye_files.md).

Every reader refuses a hostile file with one :class:`eyeviz.EyevizError` line, reads
nothing outside the file's own folder, and bounds every size the file controls
(:mod:`eyeviz.files.limits`). Writers go through :func:`eyeviz.files.atomic.atomic_output`.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
from eyeviz.files import eye_compoundray, eye_frames
from eyeviz.files.atomic import atomic_output

__all__ = ["SUFFIXES", "eye_path", "load_eyes", "save_eyes", "shipped_eye", "EyeSizeWarning"]

EyeSizeWarning = eye_frames.EyeSizeWarning
#: suffix -> (default units, default frame)
SUFFIXES = {".eye": ("mm", "compoundray"), ".gltf": ("m", "gltf"), ".glb": ("m", "gltf")}


def shipped_eye(name: str) -> Path:
    """Path of an eye file shipped in eyeviz's assets (``assets/eyes``)."""
    from importlib.resources import files

    base = Path(str(files("eyeviz") / "assets" / "eyes"))
    p = base / str(name)
    if "/" in str(name) or "\\" in str(name) or not p.is_file():
        names = sorted(q.name for q in base.glob("*.eye"))
        raise EyevizError(f"no shipped eye named {name!r} (shipped: {', '.join(names)})")
    return p


def eye_path(spec: str | Path) -> Path:
    """An eye file's path, or a shipped eye's name (``AM_60185-real.eye``): what every
    ``--eye`` option takes. A path that names a missing file is refused in one line; a bare
    name that is no file here is looked up among the shipped eyes (an error lists them)."""
    path = Path(spec)
    if path.is_file():
        return path
    if "/" in str(spec) or "\\" in str(spec):
        raise EyevizError(f"eye file {spec} not found")
    return shipped_eye(str(spec))


def _suffix(path) -> str:
    suf = Path(path).suffix.lower()
    if suf not in SUFFIXES:
        raise EyevizError(
            f"{Path(path).name}: unknown eye file type {suf or '(none)'!r}: "
            f"use one of {', '.join(SUFFIXES)}"
        )
    return suf


def _pair(eyes, name: str, source: str) -> MeasuredEyePair:
    built = []
    for (pos, ax, acc, fo), nm in zip(eyes, "AB", strict=True):
        try:
            built.append(MeasuredEye(pos, ax, acc, fo, name=nm))
        except EyevizError as exc:
            raise EyevizError(f"{name}: {exc}") from None
    return MeasuredEyePair(built[0], built[1], name=name, source=source)


def load_eyes(
    path: str | os.PathLike, units: str | None = None, frame: str | None = None
) -> MeasuredEyePair:
    """Load a measured eye pair from a ``.eye``, ``.gltf`` or ``.glb`` file.

    ``units`` ("mm", "m" or "um") defaults to the format's: millimetres for ``.eye``
    (CompoundRay's specification), metres for OCES (glTF's). ``frame`` names the file's
    axes that become eyeviz's x (towards eye B), y (forward) and z (up), e.g. ``"x,-z,y"``,
    or a preset (:data:`eyeviz.files.eye_frames.FRAMES`); it defaults to
    ``"compoundray"`` for ``.eye`` and ``"gltf"`` for OCES. Warns
    (:class:`EyeSizeWarning`) when the eyes' size is implausible for the units."""
    p = Path(path)
    suf = _suffix(p)
    u = SUFFIXES[suf][0] if units is None else units
    scale = eye_frames.check_units(u)
    fr = eye_frames.parse_frame(SUFFIXES[suf][1] if frame is None else frame)
    if suf == ".eye":
        rows, _ = eye_compoundray.read_eye_rows(p)
        eyes = eye_compoundray.split_rows(rows, fr, scale, p.name)
    else:
        from eyeviz.files import eye_oces

        eyes = eye_oces.read_oces(p, fr, scale)
    pair = _pair(eyes, p.stem, str(p))
    eye_frames.warn_if_implausible(
        np.concatenate([pair.eye_a.positions, pair.eye_b.positions]), u, p.name
    )
    return pair


def _as_measured(pair) -> MeasuredEyePair:
    if isinstance(pair, MeasuredEyePair):
        return pair
    from eyeviz.core.measured_from import as_measured

    return as_measured(pair)


def save_eyes(
    pair, path: str | os.PathLike, units: str | None = None, frame: str | None = None
) -> Path:
    """Write an eye pair (measured, or any eyeviz pair through
    :func:`eyeviz.core.measured_from.as_measured`) to ``.eye``, ``.gltf`` or ``.glb``.

    ``units`` and ``frame`` default as in :func:`load_eyes`, so ``load_eyes(save_eyes(p,
    f))`` gives ``p`` back: to the last bit for ``.eye`` in mm, to float32 precision for
    OCES. The write is atomic (a temporary file renamed over ``path``)."""
    p = Path(path)
    suf = _suffix(p)
    m = _as_measured(pair)
    u = SUFFIXES[suf][0] if units is None else units
    scale = eye_frames.check_units(u)
    fr = eye_frames.parse_frame(SUFFIXES[suf][1] if frame is None else frame)
    eyes = [(e.positions, e.axes, e.acceptance, e.focal_offset) for e in (m.eye_a, m.eye_b)]
    if suf == ".eye":
        text = eye_compoundray.format_eye_rows(eyes, fr, scale)
        with atomic_output(p) as tmp:
            tmp.write_text(text, encoding="ascii")
    else:
        from eyeviz.files import eye_oces

        blob = eye_oces.encode_oces(eyes, fr, scale, binary=suf == ".glb", name=m.name)
        with atomic_output(p) as tmp:
            tmp.write_bytes(blob)
    return p


def load_eyes_quiet(path, units=None, frame=None) -> tuple[MeasuredEyePair, list[str]]:
    """:func:`load_eyes` with its warnings returned as one-line texts (for commands)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", EyeSizeWarning)
        pair = load_eyes(path, units=units, frame=frame)
    return pair, [str(w.message) for w in caught if issubclass(w.category, EyeSizeWarning)]
