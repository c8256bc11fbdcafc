"""Figures (matplotlib, Agg backend: files only, no GUI)."""

from geardyn.plotting.simulation import count_distinct, plot_simulation

__all__ = ["count_distinct", "plot_simulation"]
