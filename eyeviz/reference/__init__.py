"""Report-only references: an 80-digit mpmath reference, the paper's literal formulas and
the stability case classes. Nothing outside the reports and tests imports this package."""

from eyeviz.reference.digits80 import reference_interval, reference_intervals

__all__ = ["reference_interval", "reference_intervals"]
