"""Benchmark runner: many seeded runs of each planner on each scenario, as DataFrames."""
