"""One-line notes on an estimator for the scene (issue 10 item 4): made for other eyes
than the scene's, or a feature outside its declared r and g range."""

from __future__ import annotations

from eyeviz.model.app_model import AppModel
from eyeviz.model.predictor import num, trained_for  # the model words its numbers

ANY_DESIGN = frozenset({"analytic", "limit"})  # answer for any h, l, m (no training)


def design_note(model: AppModel, name: str) -> str | None:
    """One short line when estimator ``name`` was made for other eyes than the scene's
    ("trained for h = 40, l = 20, m = 720"), else None (issue 10 item 4). Reads the
    estimator's declared ``domain``; analytic and limit answer for any eyes."""
    if name in ANY_DESIGN or model.predictor is None:
        return None
    est = model.predictor.peek(name)  # never loads here: loading runs on a worker
    d = getattr(est, "domain", None)
    if isinstance(est, str) or d is None or getattr(est, "any_design", False):
        return None
    e = model.scene.eyes
    if (float(d.h), float(d.l), int(d.m)) == (float(e.h), float(e.l), int(e.m)):
        return None
    return trained_for(est)


def range_note(model: AppModel, name: str, r: float, g: float) -> str | None:
    """Why feature (r, g) lies outside estimator ``name``'s declared r and g range, or None."""
    est = model.predictor.peek(name) if model.predictor is not None else None
    d = getattr(est, "domain", None)
    if d is None or isinstance(est, str):
        return None
    out = []  # short lines: each fits the narrowest readout (issue 24)
    if not d.r_min <= r <= d.r_max:
        out.append(f"r outside [{num(d.r_min)}, {num(d.r_max)}]")
    if g > d.g_max:
        out.append(f"g above its {num(d.g_max)}")
    return "\n".join(out) or None


def design_skips(model: AppModel) -> set[str]:
    """Estimators made for other eyes: they draw no ring."""
    if not model.scene.shows("predictions"):
        return set()
    return {n for n in model.scene.estimators if design_note(model, n) is not None}
