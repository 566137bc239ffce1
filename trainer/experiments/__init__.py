"""Experiments, each run from a frozen dataclass of its settings: one training run (run.py), the paper's
Section 4 (paper.py), the agent ablation and the real-capture experiments."""
