"""Verdicts: measured versus models and baselines, trends."""
