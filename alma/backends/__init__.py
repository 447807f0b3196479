"""One adapter per solver: each builds its solver's settings in one place and maps its statuses
onto :class:`alma.status.Status` in one table, so that a solver is changed in one module.

- :mod:`alma.backends.clarabel_backend` — Clarabel's interior point (Eq. 10 and its relatives);
- :mod:`alma.backends.highs_backend` — HiGHS (simplex, MIP), silenced at the source;
- :mod:`alma.backends.qdldl_backend` — QDLDL's sparse LDLᵀ for the certificate's Gram systems.

CasADi/IPOPT is used by the non-associative polish only (``alma.nonassociative.nlp``).
"""
