"""gcmh_core: Generalized Combinatorial Marching Hypercubes for any n and k.

    >>> from gcmh_core import extract
    >>> M = extract("x1^2 + x2^2 + x3^2 - 1", bounds=(-1.5, 1.5), div=16)

Imports numpy, numba and sympy only; never Qt, VTK or pyvista.
"""

from .complex import CellComplex
from .errors import Cancelled, InputError
from .extract import CONTINUATION_METHODS, METHODS, estimate_work, extract

__all__ = ["CONTINUATION_METHODS", "CellComplex", "Cancelled", "InputError", "METHODS", "estimate_work", "extract"]
__version__ = "0.1.0"
