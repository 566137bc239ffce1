"""Figures and tables from results: training curves, Figure 3, contact sheets, markdown tables."""
