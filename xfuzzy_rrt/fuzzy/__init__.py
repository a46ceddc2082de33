"""Fuzzy inference for Fuzzy-RRT: rulebook model, text format, FLL interop, compiled TSK engine.

This package knows nothing of geometry or planners. The planner sees only the compiled arrays
(``knots`` float64[n_out, 4, 5] and ``consts`` float64[n_out, 625]; ``n_out`` = 6 at 2 DOF,
``2N + 2`` for a paper rulebook of N joints) produced by
:meth:`xfuzzy_rrt.fuzzy.rulebook.Rulebook.arrays` and evaluated by
:func:`xfuzzy_rrt.fuzzy.engine.infer`.

Submodules are imported lazily by their users: importing :mod:`xfuzzy_rrt.fuzzy` does not pull
in numba (only :mod:`xfuzzy_rrt.fuzzy.engine` does).
"""
