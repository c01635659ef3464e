"""Compiler flags for every numba kernel, in one place.

nogil: a kernel running in a worker thread must not stall the GUI thread.
cache: kernels compile once per machine, not once per process (and never per F:
       kernels only ever see arrays of F's values).
"""

JIT = dict(nogil=True, cache=True, fastmath=False, error_model="numpy")
PARALLEL_JIT = dict(JIT, parallel=True)
# Small helpers called per simplex (simplex_crosses, _find, _face_key, ...) are
# inlined: a call would increment and decrement the reference count of every
# array argument, and those atomic counters are shared by all threads.  The
# per-cube functions are plain calls (numba refuses to inline them), made once
# per cube from a chunk loop that owns its scratch buffers.
INLINE_JIT = dict(JIT, inline="always")
