"""Colours shared by the app, the figures and the reports (Qt-, VTK- and matplotlib-free).

Features take the Okabe-Ito colours (colour-blind safe) in order; each estimator has one
fixed colour by *name* (never by its position in a list), chosen outside the Okabe-Ito set
so a prediction is never confused with a feature: every estimator colour is at least
:data:`MIN_DELTA_E` (CIE76 Delta E in L*a*b*) from every feature colour and from each
other (tests/model/test_frame.py checks it).
"""

from __future__ import annotations

import math

__all__ = [
    "ESTIMATOR_COLORS",
    "FALLBACK_ESTIMATOR",
    "FEATURE_COLORS",
    "MIN_DELTA_E",
    "delta_e",
    "estimator_color",
    "estimator_colors",
    "feature_color",
    "POSTERIOR_COLOR",
    "posterior_rgba",
]

# Okabe & Ito (2008), in the order new features take them (same as eyeviz.model.scene)
FEATURE_COLORS = ("#D55E00", "#0072B2", "#009E73", "#E69F00", "#CC79A7", "#56B4E9", "#F0E442")

# fixed per estimator name; dark, saturated and away from the Okabe-Ito hues
ESTIMATOR_COLORS = {
    "analytic": "#332288",  # indigo
    "limit": "#7F3B08",  # brown
    "bayes": "#882255",  # wine
    "compact": "#999933",  # olive
    "paper": "#757575",  # mid grey
}
#: the posterior layer: the limit's colour (it is the limit's posterior), shaded by density
POSTERIOR_COLOR = ESTIMATOR_COLORS["limit"]
POSTERIOR_FLOOR = 0.06  # opacity of the faintest cell
POSTERIOR_TOP = 0.9  # opacity of the densest cell
FALLBACK_ESTIMATOR = "#000000"  # an estimator not named above (a plug-in)
MIN_DELTA_E = 30.0


def feature_color(i: int) -> str:
    """The i-th feature's default colour."""
    return FEATURE_COLORS[i % len(FEATURE_COLORS)]


def estimator_color(name: str) -> str:
    """The fixed colour of estimator ``name`` (black for one not in the table)."""
    return ESTIMATOR_COLORS.get(name, FALLBACK_ESTIMATOR)


def estimator_colors(names) -> dict[str, str]:
    """name -> fixed colour, for each of ``names`` (independent of their order)."""
    return {n: estimator_color(n) for n in names}


def _lab(color: str) -> tuple[float, float, float]:
    c = color.lstrip("#")
    rgb = [int(c[i : i + 2], 16) / 255.0 for i in (0, 2, 4)]
    lin = [v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4 for v in rgb]
    x = (0.4124 * lin[0] + 0.3576 * lin[1] + 0.1805 * lin[2]) / 0.95047
    y = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]
    z = (0.0193 * lin[0] + 0.1192 * lin[1] + 0.9505 * lin[2]) / 1.08883

    def f(t: float) -> float:
        return t ** (1 / 3) if t > 216 / 24389 else (24389 / 27 * t + 16) / 116

    fx, fy, fz = f(x), f(y), f(z)
    return 116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)


def delta_e(c1: str, c2: str) -> float:
    """CIE76 colour difference between two '#RRGGBB' colours."""
    return math.dist(_lab(c1), _lab(c2))


def posterior_rgba(density) -> list[tuple[float, float, float, float]]:
    """Shades (0..1 RGBA) for posterior densities in [0, 1]: :data:`POSTERIOR_COLOR` with
    opacity from :data:`POSTERIOR_FLOOR` (faintest) to :data:`POSTERIOR_TOP` (densest), so
    what lies under a faint cell (the BFV, a feature's disc) shows through."""
    c = POSTERIOR_COLOR.lstrip("#")
    r, g, b = (int(c[i : i + 2], 16) / 255.0 for i in (0, 2, 4))
    span = POSTERIOR_TOP - POSTERIOR_FLOOR
    return [(r, g, b, POSTERIOR_FLOOR + span * min(max(float(d), 0.0), 1.0)) for d in density]
