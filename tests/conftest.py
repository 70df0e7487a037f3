"""Test-suite settings.

The compiled loops (numba) cost 25–45 s of compilation per problem on a cold cache, once; the
suite runs the pure loop by default (TABLEAU_LAB_KERNEL=python: the same algorithm) and
compiles only where a test asks for ``kernel="compiled"`` or precision dd — tests/test_kernels.py
proves the two loops agree to round-off.  Set TABLEAU_LAB_KERNEL=auto to run everything compiled.
"""
import os

os.environ.setdefault("TABLEAU_LAB_KERNEL", "python")
