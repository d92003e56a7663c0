"""The estimator registry: one entry per estimator, read by everything that lists, loads or
trains estimators (:func:`eyeviz.estimators.available`, ``eyeviz train``, ``eyeviz
predict``, the app's picker, the reports).

An :class:`Entry` says, once: the name, a one-line help, whether the estimator answers
for any eye design (``any_design``: it takes ``domain=Domain(...)``) or for the design its
weights were made for (``design``), whether it needs torch, how to load it, how to fit it
(``fit(data, out_dir, **options) -> path``, staged then swapped in; see
:mod:`eyeviz.estimators.store`) and its command-line options for predict and train.

>>> from eyeviz.estimators import registry
>>> registry.get("bayes").help
'the information limit: posterior median of r and phi per bitmap pair (a lookup table)'
>>> est = registry.load("analytic", domain=Domain(m=360))

Estimators of the spherical side (docs/spherical.md) are entries of ``kind="spherical"``,
answering for the HEALPix eyes and, where ``models`` says so, for measured ones
(docs/measured.md; :func:`available_for`),
loaded with a :class:`~eyeviz.core.domain.Domain3D` and named with a ``3d`` suffix
(``analytic3d``, ``limit3d``, ``learned3d``); :func:`entries` and :func:`available` list
one kind at a time (planar by default, so every planar list is as it was):

>>> registry.available("spherical")
['analytic3d', 'learned3d', 'limit3d']
>>> est3 = registry.load("analytic3d", domain=Domain3D(nside=16))

A plug-in registers its own entry (see ``examples/add_an_estimator.py``)::

    registry.register(Entry("nearest", "nearest sector centres", load=my_load, any_design=True))

Importing this module imports neither torch nor any estimator module; ``load`` and ``fit``
import the estimator's module on first use.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from eyeviz import EyevizError
from eyeviz.core.domain import DEFAULTS, FIELDS, PAPER_DOMAIN, RECORDS, Domain, Domain3D
from eyeviz.estimators.fit_checks import COMPACT_BATCH

__all__ = [
    "KINDS",
    "Entry",
    "Option",
    "DOMAIN_OPTIONS",
    "register",
    "unregister",
    "get",
    "entries",
    "available",
    "available_for",
    "load",
    "fit",
    "add_options",
    "options_from_args",
    "domain_from_args",
]


@dataclass(frozen=True)
class Option:
    """One command-line option: argparse ``flags`` and keywords; ``dest`` is the keyword
    passed to ``load``/``fit``."""

    flags: tuple[str, ...]
    kwargs: Mapping[str, Any] = field(default_factory=dict)

    @property
    def dest(self) -> str:
        if "dest" in self.kwargs:
            return str(self.kwargs["dest"])
        long = [f for f in self.flags if f.startswith("--")] or list(self.flags)
        return long[0].lstrip("-").replace("-", "_")


def _domain_options() -> tuple[Option, ...]:
    kinds = {"m": int}
    return tuple(
        Option(
            (f"--{k.replace('_', '-')}",),
            {
                "type": kinds.get(k, float),
                "default": None,
                "metavar": k.upper(),
                "help": f"default {DEFAULTS[k]:g} (Table {3 if k in ('h', 'l', 'm') else 4})",
            },
        )
        for k in FIELDS
    )


#: ``--h --l --m --r-min --r-max --g-max`` (default None = Tables 3-4, see DEFAULTS).
DOMAIN_OPTIONS: tuple[Option, ...] = _domain_options()


def _resolve(target: str | Callable | None) -> Callable | None:
    """``"module:attr"`` imported on first use, or a callable as is."""
    if target is None or callable(target):
        return target
    mod, _, attr = target.partition(":")
    return getattr(importlib.import_module(mod), attr)


#: What an entry estimates from: the planar eyes' half bitmaps (``Domain``) or the
#: spherical eyes' lit facets (``Domain3D``).
KINDS = ("planar", "spherical")


@dataclass(frozen=True)
class Entry:
    """Everything the rest of eyeviz needs to know about one estimator."""

    name: str
    help: str
    load: str | Callable[..., Any]  # "module:function" or a callable returning an Estimator
    fit: str | Callable[..., Path] | None = None  # fit(data, out_dir, **options) -> path
    any_design: bool = False  # True: load(domain=Domain(...)) answers for any eyes
    design: Domain | None = PAPER_DOMAIN  # fixed-design estimators: what the shipped one is
    needs_torch: bool = False
    load_options: tuple[Option, ...] = ()  # eyeviz predict options (besides --weights)
    fit_options: tuple[Option, ...] = ()  # eyeviz train NAME options (besides -o, data)
    weights_hint: str = ""  # command that makes its weights ("" when it has none)
    weights_subdir: str = ""  # sub-folder of the models directory its files go in
    fit_takes_data: bool = True  # False: fit samples its own data (bayes)
    module: str = ""  # module to look for when deciding if the entry is installed
    kind: str = "planar"  # "planar" (Domain, half bitmaps) or "spherical" (Domain3D, lit sets)
    #: the eye models a spherical entry answers for (Domain3D.kind: "spherical" for
    #: HEALPix, "measured"); empty: its kind's own model only
    models: tuple[str, ...] = ()

    @property
    def eye_models(self) -> tuple[str, ...]:
        """The eye models (:attr:`eyeviz.core.eyes.EyeModel.kind`) it answers for."""
        return self.models or (self.kind,)

    @property
    def learns(self) -> bool:
        return self.fit is not None

    @property
    def installed(self) -> bool:
        mod = self.module or (self.load.partition(":")[0] if isinstance(self.load, str) else "")
        if not mod:
            return True
        try:
            return importlib.util.find_spec(mod) is not None
        except (ImportError, ValueError):
            return False

    def load_estimator(self, **kw):
        """The estimator (``load(**kw)`` of its module). EyevizError when ``domain`` is of
        the other kind (a Domain for a spherical entry, a Domain3D for a planar one)."""
        dom = kw.get("domain")
        want = RECORDS[self.kind]
        if dom is not None and not isinstance(dom, want):
            hint = (
                f"; for the spherical eyes use {self.name}3d"
                if isinstance(dom, Domain3D) and f"{self.name}3d" in _REGISTRY
                else ""
            )
            raise EyevizError(
                f"estimator {self.name!r} is {self.kind}: domain must be a {want.__name__}, "
                f"got {type(dom).__name__}{hint}"
            )
        if isinstance(dom, Domain3D) and dom.kind not in self.eye_models:
            others = available_for(dom.kind)
            raise EyevizError(
                f"estimator {self.name!r} answers for {' and '.join(self.eye_models)} eyes only, "
                f"not {dom.kind} ones; for those use {', '.join(others) or 'no estimator yet'}"
            )
        loader = _resolve(self.load)
        assert loader is not None
        return loader(**kw)

    def fit_estimator(self, data=None, out_dir=None, **options) -> Path:
        """Train into ``out_dir`` (default: the user models directory); returns the path
        to give ``load(path=...)``. EyevizError for estimators that do not learn."""
        if self.fit is None:
            raise EyevizError(f"estimator {self.name!r} does not learn: nothing to train")
        fitter = _resolve(self.fit)
        assert fitter is not None
        return Path(fitter(data, out_dir, **options))


_REGISTRY: dict[str, Entry] = {}


def register(entry: Entry, *, replace: bool = False) -> Entry:
    """Add ``entry``; EyevizError if the name is taken (unless ``replace``)."""
    if not entry.name or not entry.name.replace("_", "").isalnum():
        raise EyevizError(f"estimator name must be a word, got {entry.name!r}")
    if entry.kind not in KINDS:
        raise EyevizError(f"estimator kind must be one of {KINDS}, got {entry.kind!r}")
    if entry.name in _REGISTRY and not replace:
        raise EyevizError(f"estimator {entry.name!r} is already registered")
    _REGISTRY[entry.name] = entry
    return entry


def unregister(name: str) -> None:
    _REGISTRY.pop(name, None)


def get(name: str) -> Entry:
    """The entry called ``name``; EyevizError naming the available ones otherwise."""
    e = _REGISTRY.get(name)
    if e is None or not e.installed:
        raise EyevizError(f"unknown estimator {name!r}; available: {', '.join(available(None))}")
    return e


def _check_kind(kind: str | None) -> None:
    if kind is not None and kind not in KINDS:
        raise EyevizError(f"kind must be one of {KINDS} or None, got {kind!r}")


def entries(kind: str | None = "planar") -> list[Entry]:
    """Installed entries of ``kind`` (None: every kind), sorted by name."""
    _check_kind(kind)
    return [
        e
        for e in (_REGISTRY[k] for k in sorted(_REGISTRY))
        if e.installed and (kind is None or e.kind == kind)
    ]


def available(kind: str | None = "planar") -> list[str]:
    """Names of ``kind`` (None: every kind) accepted by :func:`load`, sorted."""
    return [e.name for e in entries(kind)]


def available_for(model: str) -> list[str]:
    """Names of the installed entries that answer for eyes of ``model`` (an
    :attr:`eyeviz.core.eyes.EyeModel.kind`: "planar", "spherical", "measured"), sorted."""
    return [e.name for e in entries(None) if model in e.eye_models]


def load(name: str, **kw):
    """The estimator called ``name`` (keywords go to its ``load``)."""
    return get(name).load_estimator(**kw)


def fit(name: str, data=None, out_dir=None, **options) -> Path:
    """Train estimator ``name``: ``fit(data, out_dir, **options) -> path``."""
    return get(name).fit_estimator(data, out_dir, **options)


# --- command line -------------------------------------------------------------------------


def add_options(
    parser: argparse.ArgumentParser | argparse._ArgumentGroup, options: tuple[Option, ...]
) -> None:
    """Add ``options`` to ``parser``, skipping flags it already has."""
    have = set()
    for action in getattr(parser, "_actions", getattr(parser, "_group_actions", [])):
        have.update(action.option_strings)
    for opt in options:
        if not set(opt.flags) & have:
            parser.add_argument(*opt.flags, **dict(opt.kwargs))
            have.update(opt.flags)


def domain_from_args(ns: argparse.Namespace, base: Domain | None = None) -> Domain:
    """A Domain from ``--h ... --g-max`` (None = the value of ``base``, default Tables 3-4)."""
    base = PAPER_DOMAIN if base is None else base
    vals = {k: getattr(ns, k, None) for k in FIELDS}
    return Domain(**{k: (getattr(base, k) if v is None else v) for k, v in vals.items()})


def domain_given(ns: argparse.Namespace) -> bool:
    """Whether any of ``--h ... --g-max`` was given."""
    return any(getattr(ns, k, None) is not None for k in FIELDS)


def options_from_args(options: tuple[Option, ...], ns: argparse.Namespace) -> dict[str, Any]:
    """The keywords for ``load``/``fit`` from parsed options (None values left out)."""
    out = {}
    for opt in options:
        v = getattr(ns, opt.dest, None)
        if v is not None:
            out[opt.dest] = v
    return out


# --- the built-in estimators --------------------------------------------------------------
# Option types are plain int/float: the estimator's fit/load checks values (NaN, <= 0, too
# small) with one-line EyevizError messages (eyeviz.core.validation), never argparse.


def _opt(*flags: str, **kw: Any) -> Option:
    return Option(tuple(flags), kw)


_SEED = _opt("--seed", type=int, default=None, help="random seed")
_THREADS = _opt("--threads", type=int, default=None, help="torch CPU threads")

for _entry in (
    Entry(
        "analytic",
        "triangulation of the two eyes' centre rays (no weights, any eye design)",
        "eyeviz.estimators.analytic:load",
        any_design=True,
        design=None,
    ),
    Entry(
        "bayes",
        "the information limit: posterior median of r and phi per bitmap pair (a lookup table)",
        "eyeviz.estimators.bayes:load",
        fit="eyeviz.estimators.bayes:fit",
        load_options=(
            _opt(
                "--target",
                choices=("mape", "mae"),
                default=None,
                help="bayes: the posterior median for MAPE (weighted) or MAE (default mape)",
            ),
        ),
        fit_options=(
            _opt("-n", dest="n", type=int, default=None, help="sample size (default 3*10^7)"),
            _SEED,
        ),
        weights_hint="eyeviz train bayes",
        fit_takes_data=False,
    ),
    Entry(
        "compact",
        "small networks on the four lit-interval ends (a few thousand weights)",
        "eyeviz.estimators.compact:load",
        fit="eyeviz.estimators.compact:fit",
        needs_torch=True,
        fit_options=(
            _opt(
                "-n",
                "--n-train",
                dest="n",
                type=int,
                default=None,
                help=f"training elements (default 10^6; at least one batch, {COMPACT_BATCH})",
            ),
            _opt("--n-val", type=int, default=None, help="validation elements (10^5)"),
            _opt("--epochs", type=int, default=None, help="at most this many (12)"),
            _opt("--hidden", type=int, default=None, help="DD hidden width (32)"),
            _opt("--hidden-ad", type=int, default=None, help="AD hidden width (8)"),
            _opt("--patience", type=int, default=None, help="early stopping (3)"),
            _SEED,
            _THREADS,
        ),
        weights_hint="eyeviz train compact",
    ),
    Entry(
        "paper",
        "the paper's AD and DD networks (Appendix A/B; weights not shipped)",
        "eyeviz.estimators.paper:load",
        fit="eyeviz.estimators.paper:fit",
        needs_torch=True,
        load_options=(_opt("--device", default=None, help="paper: cpu or cuda"),),
        fit_options=(
            _opt(
                "-n",
                dest="n",
                type=int,
                default=None,
                help="elements to generate when no data file is given (10^5)",
            ),
            _opt("--mode", choices=("single", "multi"), default=None),
            _opt("--budget", type=float, default=None, help="seconds per network (600)"),
            _opt("--device", default=None, help="cpu or cuda"),
            _opt("--nets", default=None, help="comma-separated subset of ad,dd"),
            _opt(
                "--ad-lr",
                type=float,
                default=None,
                help="AD learning rate (default 0.003 as Appendix A; Table 5 says 0.004)",
            ),
            _opt(
                "--dd-momentum",
                type=float,
                default=None,
                help="DD Nesterov momentum in [0, 1) (default 0 = Keras default)",
            ),
            _opt("--tag", default=None, help="suffix of the output files (ad<TAG>.pt)"),
            _SEED,
            _THREADS,
        ),
        weights_hint="eyeviz train paper",
        weights_subdir="paper",
    ),
    Entry(
        "limit",
        "the information limit for any eye design (exact posterior over the cell of the "
        "bitmap pair)",
        "eyeviz.estimators.limit:load",
        any_design=True,
        design=None,
        load_options=(
            _opt(
                "--prior",
                choices=("single", "multi"),
                default=None,
                help="limit: prior over features, single or multi pass (default single)",
            ),
        ),
        module="eyeviz.estimators.limit",
    ),
    Entry(
        "analytic3d",
        "spherical and measured eyes: triangulation of the two lit caps' centres, or of the "
        "lit facets' mean rays (no weights, any design)",
        "eyeviz.estimators.analytic3d:load",
        any_design=True,
        design=None,
        kind="spherical",
        models=("spherical", "measured"),
    ),
    Entry(
        "limit3d",
        "spherical and measured eyes: the information limit (posterior under the 3D "
        "Algorithm 1 prior, importance-sampled with the exact lit sets)",
        "eyeviz.estimators.limit3d:load",
        any_design=True,
        design=None,
        load_options=(
            _opt(
                "--prior",
                choices=("single", "multi"),
                default=None,
                help="limit: prior over features, single or multi pass (default single)",
            ),
            _opt(
                "--accuracy",
                type=float,
                default=None,
                help="limit3d: target Monte-Carlo error of r per key, relative; draws are "
                "added until it is met, at most --max-batches batches (default 0.01)",
            ),
            _opt(
                "--max-batches",
                type=int,
                default=None,
                help="limit3d: the most batches of draws per key (default 16)",
            ),
        ),
        module="eyeviz.estimators.limit3d",
        kind="spherical",
        models=("spherical", "measured"),
    ),
    Entry(
        "learned3d",
        "spherical eyes: a small network correcting the triangulation (weights for one design)",
        "eyeviz.estimators.learned3d:load",
        fit="eyeviz.estimators.learned3d_training:fit",
        design=None,
        needs_torch=False,
        weights_hint="eyeviz train learned3d",
        weights_subdir="learned3d",
        module="eyeviz.estimators.learned3d",
        kind="spherical",
        fit_options=(
            _opt(
                "-n",
                "--n-train",
                dest="n",
                type=int,
                default=None,
                help="training elements to generate (default 500,000)",
            ),
            _opt("--n-val", type=int, default=None, help="validation elements (50,000)"),
            _opt("--epochs", type=int, default=None, help="at most this many (40)"),
            _opt("--hidden", type=int, default=None, help="hidden width (128)"),
            _opt("--patience", type=int, default=None, help="early stopping (5)"),
            _opt("--nside", type=int, default=None, help="learned3d: HEALPix nside (m / 4)"),
            _opt("--el-max", type=float, default=None, help="learned3d: degrees (30)"),
            _SEED,
            _THREADS,
        ),
    ),
):
    register(_entry)
del _entry
