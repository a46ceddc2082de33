"""Sampling-based planners (RRT baseline, Fuzzy-RRT) and what they share: RNG, tree, results."""
