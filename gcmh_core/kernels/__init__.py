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

The steps run in phases over a whole chunk of cubes, each one compiled function: vertices
and edges (`gcmh._vertices_edges`, or `lazy._vertices_edges_lazy` for n >= 8), then the cells
(`cells.cells_phase`, one function for both kernels), with the chunk's vertices and edges
between them in the arrays of `records.new_chunk`.  numba counts a function's arrays in and out
where it binds them: per call here, where a helper inlined into a loop over cubes counted them
per cube.  No array is rebound inside a phase's loop over cubes (an array rebound in a loop is
counted at every pass): a phase stops before a cube that might not fit, and its driver grows the
arrays and runs it again from there.  Even names move a kernel's speed (numba orders its
reference counts by variable name): a renaming is timed like any other change.

Modules, by step of the paper: candidates (3.1, step 1; continuation's next wave), tables,
solve (the barycentric solve on a Kuhn simplex, 3.1.1), cells (3.1.2: faces, keys, pieces),
gcmh (the tables' phase 1 and the chunk kernel), lazy (n >= 8), cms (Section 4), cell_check,
marching3 (n = 3), records.  The glossary (the paper's terms -> the names here), the modules and the
measurements behind this layout: docs/architecture.md.
"""

from .._config import numba_without_scipy_blas

numba_without_scipy_blas()   # (every kernel module is below this package: numba's np support loads here first)
