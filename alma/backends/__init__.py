"""One adapter per solver: each builds its solver's settings in one place and returns one result
type, :class:`alma.backends.termination.SolverResult`, whose termination is read from the
solver's status in one table (:mod:`alma.backends.termination`), so that a solver is changed in
one module.

- :mod:`alma.backends.termination` — the result type, the solvers' status tables, and what a
  termination means for a problem in kinematic or static form;
- :mod:`alma.backends.clarabel_backend` — Clarabel's interior point (Eq. 10 and its relatives,
  the search's interior-point LPs and projection QP);
- :mod:`alma.backends.highs_backend` — HiGHS (simplex, interior point, warm re-solves, MIP),
  silenced at the source;
- :mod:`alma.backends.linprog_backend` — the search's HiGHS LPs through scipy's ``linprog``;
- :mod:`alma.backends.ipopt_backend` — IPOPT through CasADi (the non-associative polish);
- :mod:`alma.backends.qdldl_backend`, :mod:`alma.backends.gram_backend` — the certificate's
  sparse LDLᵀ solves;
- :mod:`alma.backends.scip_backend` — SCIP (the optional ``alma[scip]``).
"""
