"""The numba kernels of GCMH.  They see only arrays: F's values at grid vertices,
the grid lines, and the cube tables of `tables`.  Nothing here depends on F.

Per candidate cube H, `cubes_chunk` follows paper Section 3.1, in the cube's own frame:
  1. vertices of M_H on the CFK k-simplices of its k-faces (barycentric solve);
  2. edges of M_H on its (k+1)-faces: two vertices are joined; more are paired by
     the walk of Section 3.1.1 (Fig. 3) through the face's CFK (k+1)-simplices;
  3. cells (Section 3.1.2): for r = 2..n-k, the r-cells are the connected pieces of
     the vertex-edge graph G_H restricted to each (r+k)-face of H, written with their
     (r-1)-faces.
Where the tables list no Kuhn simplices (`tables.lazy_tables`: n >= 8, large k), `cubes_chunk`
runs `cubes_chunk_lazy`, which finds the ones it needs by a pruned walk over permutations:
the same records, bit for bit.
Everything is emitted with global keys computed from grid indices alone, so
the same vertex, edge or cell produced by two neighbouring cubes is recognised
in the global assembly (`runner.assemble_records`).  `simplices_chunk` does the same
for the simplicial baselines CMS and CCS (Section 4).

A chunk of cubes returns its records in cube order, and chunks are joined in
order: the output does not depend on the number of threads.

The three steps stay in one function (`gcmh.cubes_chunk`, and `lazy.cubes_chunk_lazy` for
n >= 8).  Tried as three functions called per cube, each taking some 20 arrays, they cost
0.5 to 1.6 us more per cube, where a sphere's whole cube takes 0.6 us; as two phases over
the whole chunk (the cells step shared by both kernels) 10-20% more on surfaces in R^4 and
R^5.  Even names move this function's speed (numba orders its reference counts by variable
name): a renaming is timed like any other change to it.

Modules, by step of the paper: candidates (3.1, step 1; continuation's next wave), tables,
solve (the barycentric solve on a Kuhn simplex, 3.1.1), cells (3.1.2: faces, keys, pieces),
gcmh (the chunk kernel), lazy (n >= 8), cms (Section 4), cell_check, marching3 (n = 3),
records.  The glossary (the paper's terms -> the names here), the modules and the
measurements behind this layout: docs/architecture.md.
"""

from .._config import numba_without_scipy_blas

numba_without_scipy_blas()   # (every kernel module is below this package: numba's np support loads here first)
