"""alma's own interior-point engine for the associative LP (Eq. 10).

Plain data in, plain data out: the engine sees H (Eq. 3 on cone generators), f₀, f_L and the
normalisation N, and returns the mechanism u, the static field (μ, α) and its iteration
record.  It imports nothing of alma; alma's certificate (``alma.associative._certify``) decides
every status from what it returns.
"""

from .cholesky import PREFERENCE, FactorisationError, available_backends, make_factoriser
from .ipm import solve_eq10
from .normal import NormalPattern, normal_pattern
from .pattern_cache import PatternCache, structure_key
from .types import IPMResult, IPMSettings

__all__ = [
    "PREFERENCE",
    "FactorisationError",
    "IPMResult",
    "IPMSettings",
    "NormalPattern",
    "PatternCache",
    "available_backends",
    "make_factoriser",
    "normal_pattern",
    "solve_eq10",
    "structure_key",
]
