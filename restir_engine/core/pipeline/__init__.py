"""One frame as a pipeline of named stages (see frame.py for the order and ARCHITECTURE.md for the walk)."""
