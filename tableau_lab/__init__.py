"""tableau_lab: exact design and verification of time-stepping methods.

Layers (each imports only from those above it): ``exact`` (grammar, fields,
method objects, JSON tableaux) -> ``analysis`` (symplecticity, order, ...) ->
numeric export -> experiments -> faces (``cli``, reports).
"""
__version__ = "0.1.0"
