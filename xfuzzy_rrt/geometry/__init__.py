"""Scenario model and loader, arm kinematics and certified collision checking.

Knows nothing of fuzzy systems or planners.
"""
