"""Figures (matplotlib, Agg backend: files only, no GUI)."""

from geardyn.plotting.bifurcation import plot_bifurcation
from geardyn.plotting.envelope import plot_envelope
from geardyn.plotting.simulation import count_distinct, plot_simulation

__all__ = ["count_distinct", "plot_bifurcation", "plot_envelope", "plot_simulation"]
