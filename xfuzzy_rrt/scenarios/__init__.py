"""Scenario families: generators of problems above the planners (they prove solvability by planning)."""
