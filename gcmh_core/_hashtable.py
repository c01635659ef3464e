"""A growing table of non-negative int64 keys, each given a dense slot 0, 1, 2, ...
in the order keys are first seen.  Continuation uses it for the cubes it has
visited and the grid vertices where it has evaluated F: a wave's keys go in as one
array, in one numba call, instead of one Python set operation per key.
"""

import numba as nb
import numpy as np

from ._config import JIT

_EMPTY = -1
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)  # Fibonacci hashing: consecutive keys spread out


@nb.njit(**JIT)
def _insert(table_keys, table_slots, size, keys, slots, is_new, shift):
    """Open addressing with linear probing; returns the new size.

    The table's length is 2**(64 - shift).  slots[i]: the slot of keys[i]; is_new[i]:
    keys[i] was not in the table before (only its first occurrence in `keys` is new).
    """
    mask = table_keys.shape[0] - 1
    for i in range(keys.shape[0]):
        key = keys[i]
        h = np.int64((np.uint64(key) * _GOLDEN) >> shift)
        while True:
            found = table_keys[h]
            if found == _EMPTY:
                table_keys[h] = key
                table_slots[h] = size
                slots[i] = size
                is_new[i] = True
                size += 1
                break
            if found == key:
                slots[i] = table_slots[h]
                is_new[i] = False
                break
            h = (h + 1) & mask
    return size


class IntTable:
    """keys -> slots; `insert` adds a batch and tells which keys are new."""

    def __init__(self, capacity: int = 1 << 12):
        cap = 1 << max(4, int(capacity - 1).bit_length())
        self._keys = np.full(cap, _EMPTY, np.int64)
        self._slots = np.empty(cap, np.int64)
        self._by_slot = np.empty(cap // 2, np.int64)  # the keys, in slot order
        self.size = 0

    def __len__(self) -> int:
        return self.size

    def keys(self) -> np.ndarray:
        """Every key, in the order first inserted (slot order)."""
        return self._by_slot[: self.size].copy()

    def insert(self, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(slots, is_new) of int64 keys >= 0; new keys get the next slots in order."""
        keys = np.ascontiguousarray(keys, np.int64)
        if len(keys) and keys.min() < 0:
            raise ValueError("IntTable keys must be >= 0")
        need = self.size + len(keys)
        if 2 * need > len(self._keys):  # keep the load at most one half
            self._grow(need)
        slots = np.empty(len(keys), np.int64)
        is_new = np.empty(len(keys), np.bool_)
        old = self.size
        self.size = _insert(self._keys, self._slots, self.size, keys, slots, is_new, self._shift())
        self._by_slot[old : self.size] = keys[is_new]
        return slots, is_new

    def _shift(self) -> np.uint64:
        return np.uint64(64 - (len(self._keys).bit_length() - 1))

    def _grow(self, need: int) -> None:
        cap = len(self._keys)
        while 2 * need > cap:
            cap *= 2
        kept = self._by_slot[: self.size]
        self._keys = np.full(cap, _EMPTY, np.int64)
        self._slots = np.empty(cap, np.int64)
        by_slot = np.empty(cap // 2, np.int64)
        by_slot[: self.size] = kept
        self._by_slot = by_slot
        # re-inserting in slot order gives every key its old slot back
        unused_slots, unused_new = np.empty(len(kept), np.int64), np.empty(len(kept), np.bool_)
        _insert(self._keys, self._slots, 0, kept, unused_slots, unused_new, self._shift())
