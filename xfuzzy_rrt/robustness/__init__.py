"""Stochastic Robustness Analysis of planned paths and planners (issue 18).

- :mod:`.montecarlo`: one path executed under obstacle and joint noise (the vectorised core);
- :mod:`.sweep`: P(collision) vs σ for paths and planners, the clearance a target needs;
- :mod:`.moving`: obstacles drifting while the arm executes, blind or replanning;
- :mod:`.inputs`: the paths to analyse (a plan result JSON, a bench folder);
- :mod:`.figure`: the optional offline HTML page.
"""
