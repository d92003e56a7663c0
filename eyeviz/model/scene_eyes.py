"""A scene's eyes: the ``[eyes]`` table of a scene file (docs/contract.md, scene files).

Three eye models behind one table (:mod:`eyeviz.core.eyes`, the seam):

- ``h, l, m``: the paper's planar pair (:class:`eyeviz.core.geometry.EyePair`);
- ``h, l, nside``: the HEALPix pair (:class:`eyeviz.core.geometry3d.EyePair3D`,
  docs/spherical.md);
- ``file`` (and optionally ``units`` and ``frame``, by default the format's: millimetres
  and CompoundRay's axes for ``.eye``, metres and glTF's for OCES ``.gltf``/``.glb``): a
  measured pair (:class:`eyeviz.core.measured.MeasuredEyePair`, docs/measured.md) read
  from an eye file by :func:`eyeviz.measured.load_eyes`. A relative path is resolved
  against the scene file's folder (a shipped scene names a shipped eye file:
  ``"../eyes/AM_60185-real.eye"``); a scene written elsewhere writes the path back
  relative to its own folder.

The HEALPix and the measured pairs are the spherical side (:attr:`Eyes.side`): their
features are balls (x, y, z, g) and the app shows them in the 3D view; the measured
pair's units are millimetres. A measured pair is loaded once per (file, units, size,
modification time): a drag recomputes the state every frame, not the file.
"""

from __future__ import annotations

import os
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.core.bounds import check_m, check_nside
from eyeviz.core.eyes import EyeModel, design_kind, eyes_from_design
from eyeviz.core.geometry import EyePair

if TYPE_CHECKING:
    from eyeviz.core.measured import MeasuredEyePair

__all__ = ["EYE_UNITS", "SIDES", "Eyes", "Side", "eyes_doc", "eyes_from_table", "load_measured"]

#: The units an eye file may be given in (``[eyes] units``).
EYE_UNITS = ("mm", "m", "um")
_CACHE: OrderedDict[tuple, MeasuredEyePair] = OrderedDict()
_CACHE_SIZE = 4


def load_measured(
    path: Path, units: str | None = None, frame: str | None = None
) -> MeasuredEyePair:
    """The measured pair in ``path`` (:func:`eyeviz.measured.load_eyes`), loaded once per
    (path, units, frame, size, modification time). EyevizError (one line) for a file that cannot
    be read or is not an eye file."""
    from eyeviz.measured import load_eyes

    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        raise EyevizError(f"{p}: cannot read the eye file: {exc.strerror or exc}") from None
    key = (str(p), units, frame, st.st_size, st.st_mtime_ns)
    hit = _CACHE.get(key)
    if hit is not None:
        _CACHE.move_to_end(key)
        return hit
    if not p.is_file():
        raise EyevizError(f"{p}: not a regular file")
    try:
        pair = load_eyes(p, units=units, frame=frame)
    except EyevizError:
        raise
    except (OSError, ValueError, IndexError, KeyError) as exc:  # the reader's own
        msg = " ".join(str(exc).split())[:200]
        raise EyevizError(f"{p.name}: not a readable eye file: {msg}") from None
    _CACHE[key] = pair
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return pair


@dataclass(frozen=True)
class Side:
    """The half of the app and the pipeline a scene's eyes belong to, and what the scene
    file, the app and the exports decide by it (a lookup in :data:`SIDES` by the eye
    model's kind, not a branch on the kind)."""

    #: ``"planar"`` or ``"spherical"`` (:attr:`eyeviz.model.scene.Scene.kind`)
    name: str
    #: features are balls (x, y, z, g) shown on the app's 3D page and by figure3d; else
    #: discs on z = 0 (a scene file's features have no z), the planar page
    in_space: bool
    #: the ``[predictions] estimators`` of a scene file that names none
    estimators: tuple[str, ...]
    #: a scene file may have a ``[trajectory]`` (Figure 14's are planar)
    trajectory: bool


PLANAR_SIDE = Side("planar", in_space=False, estimators=("compact",), trajectory=True)
SPACE_SIDE = Side(
    "spherical",
    in_space=True,
    estimators=("analytic3d", "learned3d", "limit3d"),
    trajectory=False,
)
#: The side of each eye model (``Eyes.kind``): the one row a new model adds here.
SIDES: dict[str, Side] = {"planar": PLANAR_SIDE, "spherical": SPACE_SIDE, "measured": SPACE_SIDE}


@dataclass
class Eyes:
    """The scene's eye pair: h origin-to-centre, l eye radius, m ommatidia (Table 3); with
    ``nside`` the HEALPix pair EyePair3D(h, l, nside); with ``file`` a measured pair read
    from that eye file (absolute path) in ``units`` and ``frame`` (None: the format's;
    h and l then the pair's own: half the distance of its eyes' centroids, the largest
    lens distance from its centroid)."""

    h: float = paper.H
    l: float = paper.L
    m: int = paper.M
    nside: int | None = None  # set: spherical eyes, and m is the equator's 4 nside
    file: Path | None = None  # set: measured eyes from this eye file
    units: str | None = None
    frame: str | None = None

    def __post_init__(self) -> None:
        if self.nside is not None:
            self.m = 4 * self.nside
        if self.file is not None:
            self.file = Path(self.file)

    @property
    def kind(self) -> str:
        """The eye model: ``"planar"``, ``"spherical"`` (HEALPix) or ``"measured"``."""
        if self.file is not None:
            return "measured"
        return "planar" if self.nside is None else "spherical"

    @property
    def side(self) -> str:
        """``"planar"`` (discs in the plane) or ``"spherical"`` (balls in space: HEALPix
        or measured eyes): which half of the app and the pipeline shows the scene."""
        return self.spec.name

    @property
    def spec(self) -> Side:
        """The :class:`Side` of the eye model (:data:`SIDES`)."""
        return SIDES[self.kind]

    @property
    def design(self) -> dict[str, Any]:
        """{"h", "l", "m"}, {"h", "l", "nside"}, or the measured pair's design (its
        fingerprint): what a data set or an estimator must match."""
        if self.file is not None:
            return dict(self.model().design)
        if self.nside is None:
            return {"h": self.h, "l": self.l, "m": self.m}
        return {"h": self.h, "l": self.l, "nside": self.nside}

    def pair(self) -> EyePair:
        """The planar EyePair; a spherical scene's eyes are :meth:`model`'s."""
        if self.spec.in_space:
            raise EyevizError(f"the scene's eyes are {self.kind}: use Eyes.model()")
        return EyePair(self.h, self.l, self.m)

    def model(self) -> EyeModel:
        """EyePair, EyePair3D or MeasuredEyePair (the seam, :mod:`eyeviz.core.eyes`)."""
        if self.file is not None:
            return load_measured(self.file, self.units, self.frame)
        return eyes_from_design(self.design)

    def copy(self) -> Eyes:
        e = Eyes.__new__(Eyes)
        e.h, e.l, e.m, e.nside, e.file, e.units, e.frame = (
            self.h, self.l, self.m, self.nside, self.file, self.units, self.frame
        )  # fmt: skip
        return e


def _measured(c, eyes_t: dict, base: Path | None) -> Eyes:
    """``[eyes] file, units, frame``: the eye file, resolved against ``base`` (the scene's
    folder)."""
    for k in eyes_t:
        if k not in ("file", "units", "frame"):
            raise c.fail(f"eyes.{k}", "a scene naming an eye file gives file, units and frame")
    name = c.string(eyes_t, "file", "eyes.")
    if not name.strip():
        raise c.fail("eyes.file", "must not be empty")
    units = c.string(eyes_t, "units", "eyes.") if "units" in eyes_t else None
    if units is not None and units not in EYE_UNITS:
        raise c.fail("eyes.units", f"must be one of {', '.join(EYE_UNITS)}, got {units!r}")
    frame = c.string(eyes_t, "frame", "eyes.") if "frame" in eyes_t else None
    p = Path(name).expanduser()
    if not p.is_absolute():
        p = (base if base is not None else Path.cwd()) / p
    p = Path(os.path.normpath(p.absolute()))
    if not p.exists():
        raise c.fail("eyes.file", f"no such eye file: {p}")
    try:
        pair = load_measured(p, units, frame)
    except EyevizError as exc:
        key = "eyes.frame" if frame is not None and "frame" in str(exc) else "eyes.file"
        raise c.fail(key, str(exc)) from None
    return Eyes(pair.h, pair.l, 0, None, p, units, frame)


def _healpix_table(c, eyes_t: dict, h: float, l: float) -> Eyes:  # noqa: E741
    """``[eyes] h, l, nside``: the HEALPix pair."""
    try:
        nside = check_nside(eyes_t["nside"])
    except EyevizError as exc:
        raise c.fail("eyes.nside", str(exc)) from None
    try:
        eyes_from_design({"h": h, "l": l, "nside": nside})
    except ValueError as exc:
        first = str(exc).split(" ")[0]
        raise c.fail(f"eyes.{first if first in ('h', 'l') else 'h'}", str(exc)) from None
    return Eyes(h, l, nside=nside)


def _planar_table(c, eyes_t: dict, h: float, l: float) -> Eyes:  # noqa: E741
    """``[eyes] h, l, m``: the paper's planar pair (m = 720 when not given)."""
    try:
        m = check_m(eyes_t.get("m", paper.M))
    except EyevizError as exc:
        raise c.fail("eyes.m", str(exc)) from None
    try:
        EyePair(h, l, m)
    except ValueError as exc:
        first = str(exc).split(" ")[0]
        raise c.fail(f"eyes.{first if first in ('h', 'l', 'm') else 'h'}", str(exc)) from None
    return Eyes(h, l, m)


#: The ``[eyes]`` table of model eyes, read by the kind its design key names (``m``,
#: ``nside``; :func:`eyeviz.core.eyes.design_kind`); a measured pair's names its file.
_MODEL_TABLES = {"planar": _planar_table, "spherical": _healpix_table}


def eyes_from_table(c, eyes_t: dict, base: Path | None) -> Eyes:
    """The :class:`Eyes` of a scene's ``[eyes]`` table; ``c`` the scene's checker (its
    ``fail`` names the file, the key's line and the rule), ``base`` the scene's folder."""
    if "file" in eyes_t:
        return _measured(c, eyes_t, base)
    c.keys(eyes_t, "eyes.", ("h", "l", "m", "nside", "file", "units"))
    if "units" in eyes_t:
        raise c.fail("eyes.units", "units are those of an eye file (give [eyes] file)")
    h = c.number(eyes_t, "h", "eyes.", default=paper.H)
    l = c.number(eyes_t, "l", "eyes.", default=paper.L)
    # no m and no nside: the planar default (m = 720), as before spherical scenes
    kind = "planar"
    if "m" in eyes_t or "nside" in eyes_t:
        try:
            kind = design_kind(eyes_t)
        except EyevizError as exc:
            raise c.fail("eyes.nside", str(exc)) from None
    return _MODEL_TABLES[kind](c, eyes_t, h, l)


def eyes_doc(e: Eyes, base: Path | None) -> dict:
    """The ``[eyes]`` table of ``e``; an eye file's path relative to ``base`` (the folder
    the scene is written to) when given, else absolute."""
    if e.file is not None:
        name = str(e.file)
        if base is not None:
            try:
                name = Path(os.path.relpath(e.file, Path(base).absolute())).as_posix()
            except ValueError:  # another drive (Windows): keep it absolute
                pass
        doc: dict = {"file": name}
        if e.units is not None:
            doc["units"] = e.units
        if e.frame is not None:
            doc["frame"] = e.frame
        return doc
    if e.nside is None:
        return {"h": float(e.h), "l": float(e.l), "m": int(e.m)}
    return {"h": float(e.h), "l": float(e.l), "nside": int(e.nside)}
