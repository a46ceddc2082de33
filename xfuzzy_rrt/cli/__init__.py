"""Thin typer front end: parse arguments, call the library, render. No planning logic here."""
