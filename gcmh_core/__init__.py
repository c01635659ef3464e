"""gcmh_core: Generalized Combinatorial Marching Hypercubes for any n and k.

    >>> from gcmh_core import extract
    >>> M = extract("x1^2 + x2^2 + x3^2 - 1", bounds=(-1.5, 1.5), div=16)

Imports numpy, numba and sympy; never Qt, VTK, pyvista or dask.
"""

import importlib
import os
from typing import TYPE_CHECKING, Any

# The candidate pass runs numba `prange` loops on OpenMP threads, and the cube kernels
# right after it run on Python threads.  libgomp's idle threads spin-wait (by default
# for 300,000 rounds) after a parallel loop and held both cores while the kernel threads
# wanted them: the kernel ran at one thread's speed.  A short spin keeps the parallel
# loops' quick hand-over.  Read when OpenMP starts (numba's first parallel loop, after
# this import); a value the user set wins.
os.environ.setdefault("GOMP_SPINCOUNT", "10000")

from ._config import compile_notice
from .analysis import boundary_components, orient_2cells, refine_vertices, topology_report
from .complex import CellComplex
from .errors import Cancelled, InputError, TooLargeError
from .extract import CONTINUATION_METHODS, METHODS, SIMPLICIAL_METHODS, estimate_work, extract

if TYPE_CHECKING:
    from .examples import Example, list_examples, load_example
    from .formula import System, evaluate_constant, parse_system

__all__ = [
    "CONTINUATION_METHODS",
    "METHODS",
    "SIMPLICIAL_METHODS",
    "Cancelled",
    "CellComplex",
    "Example",
    "InputError",
    "System",
    "TooLargeError",
    "boundary_components",
    "compile_notice",
    "estimate_work",
    "evaluate_constant",
    "extract",
    "list_examples",
    "load_example",
    "orient_2cells",
    "parse_system",
    "refine_vertices",
    "topology_report",
]

def _installed_version() -> str:
    # One version, written in pyproject.toml and read from the installed metadata.
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("gcmh")
    except PackageNotFoundError:  # run from a source tree that was never installed
        return "0+unknown"


__version__ = _installed_version()

# Loaded on first use (PEP 562): the formula parser brings sympy (a third of a second),
# and `extract` loads the numba engine only when it first runs, so `gcmh --help`, a
# refused run, loading a saved complex and Ctrl-C at start-up answer at once; an
# extraction from sampled values never loads sympy.
_LAZY = {
    "System": "formula",
    "evaluate_constant": "formula",
    "parse_system": "formula",
    "Example": "examples",
    "list_examples": "examples",
    "load_example": "examples",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
