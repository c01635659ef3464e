"""Slow, obviously correct twins of the newer kernels of gcmh_core._homology_kernels
(the older ones' twins are in naive_homology.py), compared on random inputs in
tests/core/test_homology_kernels.py."""

from __future__ import annotations

from collections import deque


def orient_top(off, fac, sign, n_faces):
    """Twin of ``_orient_top``: (eps list of +-1, sorted list of conflicting faces).

    Each face's entries are listed; a face on two entries joins their cells.  Walk from
    the lowest cell not reached yet, breadth first, faces in their order; the other cell
    of a face gets the sign that makes the face cancel."""
    entries: dict = {}
    for c in range(len(off) - 1):
        for j in range(off[c], off[c + 1]):
            entries.setdefault(int(fac[j]), []).append((c, int(sign[j])))
    eps = [0] * (len(off) - 1)
    for start in range(len(eps)):
        if eps[start]:
            continue
        eps[start] = 1
        todo = deque([start])
        while todo:
            c = todo.popleft()
            for j in range(off[c], off[c + 1]):
                pair = entries[int(fac[j])]
                if len(pair) != 2:
                    continue
                (_, s), (d, t) = pair if pair[0][0] == c else pair[::-1]
                if eps[d] == 0:
                    eps[d] = -eps[c] * s * t
                    todo.append(d)
    bad = [f for f in range(n_faces) if len(entries.get(f, [])) == 2
           and sum(eps[c] * s for c, s in entries[f]) != 0]
    return eps, bad
