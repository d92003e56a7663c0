"""The numeric options of the learning estimators' ``fit``, checked without torch.

``eyeviz train NAME`` checks them before it imports the fit (torch: 1.5-4 s), so a bad
value is refused at once, in one line. The fits check the same bounds again (for callers
in Python); the messages are theirs (:mod:`eyeviz.core.validation`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_LR, MAX_THREADS
from eyeviz.core.validation import check_int, check_real
from eyeviz.files import limits

#: The batch of ``compact_training.train`` (its one-cycle schedule needs one whole batch).
COMPACT_BATCH = 4096

#: Per estimator, in the fit's order: (option, the name its message gives, check, bounds).
#: ``n`` is checked only when the fit generates its rows (no data file).
_RULES: dict[str, tuple[tuple[str, str, Callable[..., Any], dict[str, Any]], ...]] = {
    "paper": (
        ("ad_lr", "ad_lr", check_real, {"gt": 0, "le": MAX_LR}),
        ("dd_momentum", "dd_momentum", check_real, {"ge": 0, "lt": 1}),
        ("budget", "budget", check_real, {"gt": 0}),
        ("threads", "threads", check_int, {"ge": 1, "le": MAX_THREADS}),
        ("n", "n", check_int, {"ge": 10}),
    ),
    "compact": (
        ("hidden", "hidden", check_int, {"ge": 1, "le": limits.MAX_HIDDEN}),
        ("hidden_ad", "hidden_ad", check_int, {"ge": 1, "le": limits.MAX_HIDDEN}),
        ("patience", "patience", check_int, {"ge": 1}),
        ("threads", "threads", check_int, {"ge": 1, "le": MAX_THREADS}),
        ("epochs", "epochs", check_int, {"ge": 1}),
        ("n", "n_train", check_int, {"ge": 1, "le": limits.MAX_ROWS}),
    ),
    "bayes": (("n", "n", check_int, {"ge": 1, "le": limits.MAX_ROWS}),),
}


def check_compact_rows(n_train: int, batch: int = COMPACT_BATCH) -> None:
    """Refuse fewer generated training rows than one batch of the one-cycle schedule."""
    if n_train < batch:
        raise EyevizError(
            f"-n must be >= {batch} (one batch of the one-cycle schedule), got {n_train}"
        )


def check(name: str, options: dict[str, Any], data_given: bool) -> None:
    """Raise the fit's EyevizError for a bad numeric option of estimator ``name`` (the
    keywords ``eyeviz train`` passes; missing ones take the fit's defaults, which are
    good). ``data_given``: a data file is given (the fit then generates no ``n`` rows)."""
    for key, label, rule, bounds in _RULES.get(name, ()):
        value = options.get(key)
        if value is None or (key == "n" and data_given and name == "paper"):
            continue
        value = rule(label, value, **bounds)
        if key == "n" and name == "compact" and not data_given:
            check_compact_rows(value)
