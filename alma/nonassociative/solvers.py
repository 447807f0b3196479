"""A re-export for :mod:`alma.certify`, which still creates its HiGHS objects by this name; the
search's own solver calls go through :mod:`alma.backends`."""
from __future__ import annotations

from alma.backends.highs_backend import quiet_highs

__all__ = ["quiet_highs"]
