"""The names of the four methods, in a module that imports nothing (numba stays unloaded)."""

METHODS = ("gcmh", "gcch", "cms", "ccs")
# continuation methods start from points and follow M; the others sweep the whole grid
CONTINUATION_METHODS = ("gcch", "ccs")
# the simplicial baselines (paper Section 4): marching simplices over the CFK triangulation
SIMPLICIAL_METHODS = ("cms", "ccs")
