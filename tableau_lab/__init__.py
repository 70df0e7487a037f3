"""tableau_lab: exact design and verification of time-stepping methods.

The public API is the names below, all at the package top (``import tableau_lab as tl``) and all
loaded on first use: ``import tableau_lab`` itself imports nothing heavy (no sympy analysis,
numba, scipy, matplotlib or dask; tests/test_latency.py checks it).

>>> import tableau_lab as tl
>>> m = tl.load("gauss:3")            # a file, a library name, a family, JSON text, a NodePy method
>>> int(m.order())                    # the same as int(tl.order(m))
6
>>> tl.load("rk4").imaginary_stability_interval()
2*sqrt(2)

Layers (each imports only from those above it): ``exact`` (grammar, fields,
method objects, JSON tableaux) -> ``analysis`` (symplecticity, order, ...) ->
numeric export -> experiments -> faces (``cli``, reports).  The one exception
is deliberate: the methods of a method object (``m.order()``) look their
function up here, by name, at call time (``exact/queries.py``).
"""
__version__ = "0.1.0"

#: public name -> the module that defines it (imported on first use)
_LAZY = {
    # methods: reading, writing, the library
    "load": "tableau_lab.exact.catalog",
    "save": "tableau_lab.exact.catalog",
    "list_methods": "tableau_lab.analysis.catalog",
    "RungeKutta": "tableau_lab.exact.methods",
    "PartitionedRungeKutta": "tableau_lab.exact.methods",
    "GeneralLinearMethod": "tableau_lab.exact.methods",
    # analyses
    "verify": "tableau_lab.analysis.verify",
    "order": "tableau_lab.analysis.order",
    "stability": "tableau_lab.analysis.stability",
    "stability_report": "tableau_lab.analysis.stability_report",
    "g_symplectic": "tableau_lab.analysis.symplectic",
    "parasitism": "tableau_lab.analysis.parasitism",
    "imaginary_stability_interval": "tableau_lab.analysis.front",
    "principal_error_norm": "tableau_lab.analysis.front",
    "stability_function": "tableau_lab.analysis.front",
    "BSeries": "tableau_lab.analysis.bseries",
    "modified_equation": "tableau_lab.analysis.modified",
    "modified_hamiltonian": "tableau_lab.analysis.front",
    # design
    "solve": "tableau_lab.analysis.design",
    "design": "tableau_lab.experiments.design_search",
    "error_constant": "tableau_lab.analysis.error_constant",
    "ssp_coefficient": "tableau_lab.analysis.ssp",
    "reconstruct": "tableau_lab.analysis.reconstruct",
    "trees_of_order": "tableau_lab.analysis.trees",
    # running: the user's own problem, built-in problems by name
    "integrate": "tableau_lab.experiments.user",
    "problem": "tableau_lab.experiments.user",
    "Solution": "tableau_lab.experiments.user",
    "warm_up": "tableau_lab.experiments.shared_loops",
    # plots, inline (matplotlib Axes)
    "plot_stability_region": "tableau_lab.experiments.inline_plots",
    "plot_order_star": "tableau_lab.experiments.inline_plots",
    "plot_imaginary_axis": "tableau_lab.experiments.inline_plots",
    # faces
    "report": "tableau_lab.proofs.latex",
    "audit": "tableau_lab.proofs.audit",
}

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str):
    """The public name ``name`` from its module (:data:`_LAZY`), imported now and kept."""
    path = _LAZY.get(name)
    if path is None:
        raise AttributeError(f"module 'tableau_lab' has no attribute {name!r}")
    import importlib
    module = importlib.import_module(path)
    value = getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
