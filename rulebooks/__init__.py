"""The shipped rulebooks, installed as package data (``xfuzzy_rrt.rulebooks``).

This folder stays at the top of the project, where people read and diff the rulebooks;
pyproject.toml maps it into the package so that an installed wheel carries every ``.fis`` and
``rulebook.toml``. Code finds it through :func:`xfuzzy_rrt.fuzzy.rulebook.rulebooks_dir`.
"""
