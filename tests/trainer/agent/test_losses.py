"""The training objective's total: each term times its scale, a term without a scale counted once."""
import torch

from trainer.agent import losses


def test_a_term_without_a_scale_counts_once_in_the_total():
    terms = {"pose": torch.tensor(2.0), "kl": torch.tensor(4.0), "new_term": torch.tensor(3.0)}
    total = losses.weighted_total(terms, {"pose": 0.5, "kl": 0.0})
    assert float(total) == 2.0 * 0.5 + 4.0 * 0.0 + 3.0 * 1.0
