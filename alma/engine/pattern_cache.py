"""Normal-equations patterns kept between solves, keyed by the structure of H.

A :class:`~alma.engine.normal.NormalPattern` (the ordering, the symbolic structure of
K = H D Hᵀ and its gather map) depends on where H's entries are, not on their values: the
frictions of one geometry share it.  A :class:`PatternCache` belongs to its caller (a study keeps
one per geometry); the solver reads it and adds to it, and writes into nothing else.

The key is a digest of H's exact structure (shape, rows of u, CSC indices of its nonzero
entries), so a pattern serves only the structure it was built from, with its values rebuilt
from the H at hand (:meth:`NormalPattern.with_values`): the same K, the same factorisation,
the same answer bit for bit as a pattern built afresh.  Which models were solved before never
changes an answer, only its cost.
"""

from __future__ import annotations

import hashlib
import threading

import numpy as np
import scipy.sparse as sp

from .normal import NormalPattern, canonical


def structure_key(H: sp.spmatrix, n_primary: int) -> bytes:
    """Digest (BLAKE2b, 32 bytes) of the structure of ``H`` as the interior point indexes it:
    shape, ``n_primary`` (rows of u; the rest are eliminated dissipation rows) and the CSC
    indices of its nonzero entries, values excluded."""
    C = canonical(H)
    digest = hashlib.blake2b(digest_size=32)
    digest.update(np.array([*C.shape, n_primary], dtype=np.int64).tobytes())
    digest.update(C.indptr.astype(np.int64).tobytes())
    digest.update(C.indices.astype(np.int64).tobytes())
    return digest.digest()


class PatternCache:
    """The normal-equations patterns of the structures solved so far, by :func:`structure_key`.

    Owned by the caller, who decides how long patterns are kept (each is about 30 MB at 5,000
    blocks); safe to share between threads.  ``hits`` and ``misses`` count the lookups.
    """

    def __init__(self) -> None:
        self._patterns: dict[bytes, NormalPattern] = {}
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def get(self, key: bytes) -> NormalPattern | None:
        """The pattern built for the structure ``key``, or None."""
        with self._lock:
            pattern = self._patterns.get(key)
            if pattern is None:
                self.misses += 1
            else:
                self.hits += 1
            return pattern

    def put(self, key: bytes, pattern: NormalPattern) -> None:
        """Keep ``pattern`` for the structure ``key``."""
        with self._lock:
            self._patterns[key] = pattern

    def __len__(self) -> int:
        return len(self._patterns)
