"""Compiler flags for every numba kernel, in one place.

nogil: a kernel running in a worker thread must not stall the GUI thread.
cache: kernels compile once per machine, not once per process (and never per F:
       kernels only ever see arrays of F's values).
"""

JIT = dict(nogil=True, cache=True, fastmath=False, error_model="numpy")
PARALLEL_JIT = dict(JIT, parallel=True)
# Small helpers called in a kernel's inner loops (_face_key, _face_in_face, ...) are
# inlined and take scalars.  Array arguments of an inlined call get reference-count
# updates (atomic, shared by all threads) that numba does not prune in functions
# as large as the chunk kernels (LLVM's refprune gives up past 1,000 basic blocks):
# they cost more than a cube's work.  (simplex_crosses takes arrays: it is called
# only for the few simplices that pass the sign prune.)  The loop over cubes runs
# inside one kernel function per chunk (`_kernels.cubes_chunk`), with scratch
# buffers it owns.
INLINE_JIT = dict(JIT, inline="always")
# A kernel that calls another compiles the callee for the argument types type inference
# sees first: a counter started as `= 0` is Literal[int](0) there and int64 later, so
# the callee compiled twice (seconds each on a first run).  Counters and indices passed
# to another kernel start as np.int64(0).
