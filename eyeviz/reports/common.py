"""Helpers shared by the reports.

Estimator names from the command line, loading an estimator without crashing on a
missing one, atomic writes of text and figures (one figure in several formats, text kept
as text and no dates, so a second run writes the same bytes), and the accuracy metrics
(MAPE, Eq. 34; MAE, Eq. 33; the standard R^2) over the finite predictions.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np


def parse_names(text: str | None) -> list[str]:
    """Estimator names from "a,b c" (default: all available); ValueError naming unknown ones."""
    from eyeviz import estimators

    avail = estimators.available()
    if text is None:
        return avail
    names = [s for s in str(text).replace(",", " ").split() if s]
    bad = [s for s in names if s not in avail]
    if bad or not names:
        raise ValueError(
            f"unknown estimator(s) {', '.join(bad) or '(none given)'}; available: "
            f"{', '.join(avail)}"
        )
    return list(dict.fromkeys(names))


def try_load(name: str, **kw):
    """(estimator, "") or (None, one-line reason) — never raises for a missing estimator
    (keywords, e.g. ``domain``, go to :func:`eyeviz.estimators.load`)."""
    from eyeviz import estimators

    try:
        return estimators.load(name, **kw), ""
    except (ValueError, OSError, ImportError, RuntimeError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if name == "paper" and "not found" in msg:
            return None, "not trained here (make the weights with `eyeviz train paper`)"
        return None, msg


def write_atomic(path: Path, data: bytes | str) -> None:
    """Write a file via a temporary file in the same directory and ``os.replace``."""
    from eyeviz.files.atomic import atomic_output

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        tmp.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)


#: The figure formats a report can write: PNG for screens, SVG and PDF for papers
FORMATS = ("png", "svg", "pdf")


def parse_formats(text: str) -> tuple[str, ...]:
    """The formats of "png,svg" (or "png svg"), in order, once each; a one-line error
    naming what is not one of :data:`FORMATS`."""
    from eyeviz import EyevizError

    got = tuple(dict.fromkeys(s for s in str(text).replace(",", " ").split() if s))
    bad = [s for s in got if s not in FORMATS]
    if bad or not got:
        raise EyevizError(f"--formats takes png, svg and pdf, got {', '.join(bad) or '(none)'}")
    return got


def add_formats_option(parser, default: tuple[str, ...] = FORMATS) -> None:
    """A ``--formats`` option (parse it with :func:`parse_formats`)."""
    parser.add_argument(
        "--formats",
        default=",".join(default),
        help=f"the figures' formats, of png, svg, pdf (default {','.join(default)})",
    )


def save_formats(
    fig, base: Path, formats: tuple[str, ...] = FORMATS, dpi: int = 300, **savefig
) -> list[Path]:
    """``fig`` written to ``base`` with each of ``formats`` as its suffix, each file
    atomically; SVG and PDF keep text as text, and carry no date."""
    import matplotlib

    written = []
    with matplotlib.rc_context(
        {"svg.fonttype": "none", "svg.hashsalt": "eyeviz", "pdf.fonttype": 42}
    ):
        for fmt in formats:
            buf = io.BytesIO()
            meta = {"svg": {"Date": None}, "pdf": {"CreationDate": None}}.get(fmt, {})
            fig.savefig(buf, format=fmt, dpi=dpi, metadata=meta, **savefig)
            target = base.with_name(f"{base.name}.{fmt}")
            write_atomic(target, buf.getvalue())
            written.append(target)
    return written


def save_figure(fig, path: Path, dpi: int = 150) -> None:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    write_atomic(path, buf.getvalue())


def accuracy_metrics(y, yhat) -> dict[str, float]:
    """MAPE, MAE, R^2 over the rows where the prediction is finite (eyeviz.estimators.metrics)."""
    from eyeviz.estimators import metrics

    y = np.asarray(y, np.float64)
    yhat = np.asarray(yhat, np.float64)
    ok = np.isfinite(yhat)
    if not ok.any():
        return {"mape": math.nan, "mae": math.nan, "r2": math.nan}
    out = {"mape": metrics.mape(y[ok], yhat[ok]), "mae": metrics.mae(y[ok], yhat[ok])}
    try:
        out["r2"] = metrics.r2(y[ok], yhat[ok])
    except ValueError:
        out["r2"] = math.nan
    return out
