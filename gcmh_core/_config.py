"""Compiler flags for every numba kernel, in one place.

nogil: a kernel running in a worker thread must not stall the GUI thread.
cache: kernels compile once per machine, not once per process (and never per F:
       kernels only ever see arrays of F's values).
"""

JIT = dict(nogil=True, cache=True, fastmath=False, error_model="numpy")
PARALLEL_JIT = dict(JIT, parallel=True)
