"""Experiments: quick runs, convergence studies, scenes, plots (layer 4: above the numeric export)."""
