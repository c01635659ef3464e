"""gcmh_core: Generalized Combinatorial Marching Hypercubes for any n and k.

    >>> from gcmh_core import extract
    >>> M = extract("x1^2 + x2^2 + x3^2 - 1", bounds=(-1.5, 1.5), div=16)

Imports numpy, numba and sympy only; never Qt, VTK or pyvista.
"""

import os

# The candidate pass runs numba `prange` loops on OpenMP threads, and the cube kernels
# right after it run on Python threads.  libgomp's idle threads spin-wait (by default
# for 300,000 rounds) after a parallel loop and held both cores while the kernel threads
# wanted them: the kernel ran at one thread's speed.  A short spin keeps the parallel
# loops' quick hand-over.  Read when OpenMP starts (numba's first parallel loop, after
# this import); a value the user set wins.
os.environ.setdefault("GOMP_SPINCOUNT", "10000")

from .complex import CellComplex  # noqa: E402
from .errors import Cancelled, InputError  # noqa: E402
from .extract import CONTINUATION_METHODS, METHODS, estimate_work, extract  # noqa: E402

__all__ = ["CONTINUATION_METHODS", "CellComplex", "Cancelled", "InputError", "METHODS", "estimate_work", "extract"]
__version__ = "0.1.0"
