"""Exact predicates for boundary cases: stable public path ``eyeviz.exact``.

The implementation lives in :mod:`eyeviz.core.exact`; this module only re-exports it.
"""

from eyeviz.core.exact import exact_floor_pair, sign_a_plus_b_sqrt, sign_linear

__all__ = ["exact_floor_pair", "sign_a_plus_b_sqrt", "sign_linear"]
