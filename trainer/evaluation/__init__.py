"""Scoring generated gestures against clips: one scorer, clip selection, length flexibility, baselines, real mocap."""
