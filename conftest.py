"""Hypothesis profiles for the whole suite (tests/ and verification/).

``ci`` is loaded by default: every property test draws the same examples on every run (seeded
from the test itself), so a red ``make test`` means a change broke something, not that a new
random example was drawn.  ``explore`` draws fresh random examples and keeps the failures it
finds in ``.hypothesis/``: ``make explore``.  Each failure found that way becomes an
``@example`` of its test (see verification/test_certify.py).
"""

try:
    from hypothesis import settings
except ImportError:  # pragma: no cover - hypothesis is a test dependency
    pass
else:
    settings.register_profile("ci", derandomize=True)
    settings.register_profile("explore", derandomize=False)
    settings.load_profile("ci")
