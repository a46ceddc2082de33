"""xfuzzy-rrt: Fuzzy-RRT motion planning for a small surgical arm, made inspectable.

The package is layered (see DESIGN.md in the shared folder): ``geometry`` and ``fuzzy`` know
nothing of each other; ``planners`` use both; ``bench``/``training``/``report`` sit above; the
``cli`` is the only place that prints. Heavy modules (numba, pandas, plotly) are imported
lazily so that ``xfuzzy-rrt --help`` answers at once.
"""

__version__ = "0.1.0"
