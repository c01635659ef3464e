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

The three steps stay in one function.  Tried as three functions called per cube, each
taking some 20 arrays, they cost 0.5 to 1.6 us more per cube, where a sphere's whole cube
takes 0.6 us.  Even names move this function's speed (numba orders its reference
counts by variable name): a renaming is timed like any other change to it.

Glossary: the paper's terms -> the names here and in `tables`
--------------------------------------------------------------
F = (F_1..F_k), its values    `values[row, j]`: F_j at a grid vertex.  Corner c of cube i
                              is row `cube_row[i] + corner_row[c]`
hypercube H, its corners      a cube; a corner is a bit mask c (bit a: +1 along axis a)
r-face of H (Def. 2.9)        `CubeTables` row f: free axes `face_free[f]`, anchor corner
                              `face_fixed[f]`; the r-faces are rows face_start[r]:face_start[r+1]
face label l(f) (Def. 3.1)    `_face_key`: f's anchor grid vertex and the rank of its free axes
CFK triangulation of a k-face `ksimplex_*`: the k! Kuhn k-simplices of each k-face (a chain of
                              corners, one per permutation of the face's axes)
lambda_0..lambda_k (3.1.1)    `lam`, found by `simplex_crosses`
sign of F_j at the corners    `corner_signs[c]` (bit j: F_j >= 0 at c) and
                              `positive_corners[j]` (bit c: the same), for the sign prune
vertex of M_H                 a crossed k-simplex s: `vertex_of_ksimplex[s]` >= 0; the vertex
                              v sits on the k-face `vertex_face[v]`, global key `vertex_key[v]`
edge of M_H on a (k+1)-face   `edge_a[e]`, `edge_b[e]` (vertices) on the face `edge_face[e]`
the walk (3.1.1, Fig. 3)      `walk_*`: a (k+1)-face's CFK (k+1)-simplices; the walk's nodes are
                              their k-facets, boundary nodes (the face's own k-simplices) first,
                              then interior ones; `walk_next0/1[node]` link the crossed nodes
graph G_H (step 2.1)          the cube's vertices and edges
r-cell of M_H (step 2.2)      a connected piece (union-find `parent`) of G_H in an (r+k)-face
                              of H, keyed by the face and its smallest vertex code `_local_code`
its (r-1)-faces (Alg. 1)      the (r-1)-cells in the faces of that (r+k)-face: incidence rows
crossed facets (Sec. 5.2)     `crossed_facets[i]`, bit 2a + side: where continuation goes next
"""
