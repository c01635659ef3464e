"""gcmh_core: Generalized Combinatorial Marching Hypercubes for any n and k.

    >>> from gcmh_core import extract
    >>> M = extract("x1^2 + x2^2 + x3^2 - 1", bounds=(-1.5, 1.5), div=16)

Imports numpy, numba and sympy; never Qt, VTK, pyvista or dask.
"""

import importlib
import os
import sys
import types
from typing import TYPE_CHECKING, Any

# The candidate pass runs numba `prange` loops on OpenMP threads, and the cube kernels
# right after it run on Python threads.  libgomp's idle threads spin-wait (by default
# for 300,000 rounds) after a parallel loop and held both cores while the kernel threads
# wanted them: the kernel ran at one thread's speed.  A short spin keeps the parallel
# loops' quick hand-over.  Read when OpenMP starts (numba's first parallel loop, after
# this import); a value the user set wins.
os.environ.setdefault("GOMP_SPINCOUNT", "10000")

from .errors import Cancelled, InputError, TooLargeError

if TYPE_CHECKING:
    from ._config import compile_notice
    from .analysis import boundary_components, orient_2cells, refine_vertices, topology_report
    from .complex import CellComplex
    from .curvature import gauss_bonnet, gaussian_curvature
    from .data_files import extract_data, load_components, read_data
    from .examples import Example, list_examples, load_example
    from .extract import CONTINUATION_METHODS, METHODS, SIMPLICIAL_METHODS, estimate_work, extract
    from .formula import System, evaluate_constant, parse_system
    from .homology import Homology, homology
    from .section import section, section_profile

# Every name but the errors is loaded on first use (PEP 562): `import gcmh_core` costs
# milliseconds, so `gcmh` installs its Ctrl-C handler before numpy, sympy or numba load
# (a Ctrl-C in the first half second printed a traceback), and `gcmh --help`, a refused
# run and loading a saved complex answer at once.
_LAZY = {
    "compile_notice": "_config",
    "boundary_components": "analysis",
    "orient_2cells": "analysis",
    "refine_vertices": "analysis",
    "topology_report": "analysis",
    "CellComplex": "complex",
    "gauss_bonnet": "curvature",
    "gaussian_curvature": "curvature",
    "extract_data": "data_files",
    "load_components": "data_files",
    "read_data": "data_files",
    "Example": "examples",
    "list_examples": "examples",
    "load_example": "examples",
    "CONTINUATION_METHODS": "extract",
    "METHODS": "extract",
    "SIMPLICIAL_METHODS": "extract",
    "estimate_work": "extract",
    "extract": "extract",
    "System": "formula",
    "evaluate_constant": "formula",
    "parse_system": "formula",
    "Homology": "homology",
    "homology": "homology",
    "section": "section",
    "section_profile": "section",
}

__all__ = [  # (written out for the linters; the same names as the errors and _LAZY: test_package)
    "Cancelled",
    "InputError",
    "TooLargeError",
    "compile_notice",
    "boundary_components",
    "orient_2cells",
    "refine_vertices",
    "topology_report",
    "CellComplex",
    "gauss_bonnet",
    "gaussian_curvature",
    "extract_data",
    "load_components",
    "read_data",
    "Example",
    "list_examples",
    "load_example",
    "CONTINUATION_METHODS",
    "METHODS",
    "SIMPLICIAL_METHODS",
    "estimate_work",
    "extract",
    "System",
    "evaluate_constant",
    "parse_system",
    "Homology",
    "homology",
    "section",
    "section_profile",
]


def _installed_version() -> str:
    # One version, written in pyproject.toml and read from the installed metadata
    # (importlib.metadata takes a tenth of a second to load: read on first use).
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("gcmh")
    except PackageNotFoundError:  # run from a source tree that was never installed
        return "0+unknown"


def __getattr__(name: str) -> Any:
    if name == "__version__":
        globals()[name] = _installed_version()
        return globals()[name]
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)


class _Package(types.ModuleType):
    """``gcmh_core.extract``, ``.homology`` and ``.section`` are functions named as the modules
    that define them.  Importing such a module binds the module as the package's attribute
    (the import system's setattr), which would hide the function; the package keeps the
    function (the module stays in ``sys.modules``: ``from gcmh_core.extract import METHODS``)."""

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, types.ModuleType) and _LAZY.get(name) == name:
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
