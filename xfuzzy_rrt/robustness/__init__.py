"""Stochastic Robustness Analysis of planned paths and planners (issue 18)."""
