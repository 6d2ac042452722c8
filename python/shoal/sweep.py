"""Sweeps from Python: placeholder until the engine's sweep API is wired in."""
