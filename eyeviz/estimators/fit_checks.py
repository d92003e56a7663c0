"""The numeric options of the learning estimators' ``fit``, checked without torch.

``eyeviz train NAME`` checks them before it imports the fit (torch: 1.5-4 s), so a bad
value is refused at once, in one line. The fits check the same bounds again (for callers
in Python); the messages are theirs (:mod:`eyeviz.core.validation`).
"""

from __future__ import annotations

from typing import Any

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_LR, MAX_THREADS
from eyeviz.core.validation import check_int, check_real
from eyeviz.files import limits

#: The batch of ``compact_training.train`` (its one-cycle schedule needs one whole batch).
COMPACT_BATCH = 4096


def check(name: str, options: dict[str, Any], data_given: bool) -> None:
    """Raise the fit's EyevizError for a bad numeric option of estimator ``name`` (the
    keywords ``eyeviz train`` passes; missing ones take the fit's defaults, which are
    good). ``data_given``: a data file is given (the fit then generates no ``n`` rows)."""
    o = options
    if name == "paper":
        if o.get("ad_lr") is not None:
            check_real("ad_lr", o["ad_lr"], gt=0, le=MAX_LR)
        if o.get("dd_momentum") is not None:
            check_real("dd_momentum", o["dd_momentum"], ge=0, lt=1)
        if o.get("budget") is not None:
            check_real("budget", o["budget"], gt=0)
        if o.get("threads") is not None:
            check_int("threads", o["threads"], ge=1, le=MAX_THREADS)
        if not data_given and o.get("n") is not None:
            check_int("n", o["n"], ge=10)
    elif name == "compact":
        for k in ("hidden", "hidden_ad"):
            if o.get(k) is not None:
                check_int(k, o[k], ge=1, le=limits.MAX_HIDDEN)
        if o.get("patience") is not None:
            check_int("patience", o["patience"], ge=1)
        if o.get("threads") is not None:
            check_int("threads", o["threads"], ge=1, le=MAX_THREADS)
        if o.get("epochs") is not None:
            check_int("epochs", o["epochs"], ge=1)
        if o.get("n") is not None:
            n = check_int("n_train", o["n"], ge=1, le=limits.MAX_ROWS)
            if not data_given and n < COMPACT_BATCH:
                raise EyevizError(
                    f"-n must be >= {COMPACT_BATCH} (one batch of the one-cycle schedule), got {n}"
                )
    elif name == "bayes":
        if o.get("n") is not None:
            check_int("n", o["n"], ge=1, le=limits.MAX_ROWS)
