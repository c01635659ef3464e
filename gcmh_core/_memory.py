"""What this machine can hold: the memory a run may use, and sizes and durations in words.

A leaf module (it imports only `errors`), so that `complex` (bounded loads) and
`budget` (run estimates) can both use it without importing each other.
"""

from __future__ import annotations

import math
import os

from .errors import InputError

__all__ = ["available_memory", "format_bytes", "format_seconds"]


def format_bytes(b: float) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if b >= size:
            return f"{b / size:.3g} {unit}"
    return f"{int(b)} B"


def format_seconds(s: float) -> str:
    """A duration said the way a person would: 0.3 s, 12 s, 4 min, 2.5 h, 5 days."""
    s = float(s)
    if s < 1:
        return f"{s:.1g} s"
    if s < 90:
        return f"{s:.0f} s"
    if s < 5400:
        return f"{s / 60:.0f} min"
    if s < 2 * 86400:
        return f"{s / 3600:.1f} h"
    return f"{s / 86400:.0f} days"


def _parse_size(text: str) -> int:
    text = text.strip().upper().removesuffix("B")
    scale = {"K": 1e3, "M": 1e6, "G": 1e9, "T": 1e12}.get(text[-1:], 1)
    try:
        value = float(text[:-1] if scale != 1 else text) * scale
    except ValueError:
        raise InputError(f"GCMH_MEMORY_LIMIT: expected a size such as 8G or 500M, got {text!r}") from None
    if not value > 0 or not math.isfinite(value):
        raise InputError(f"GCMH_MEMORY_LIMIT must be positive, got {text!r}")
    return int(value)


def available_memory() -> int:
    """Bytes a run may use: $GCMH_MEMORY_LIMIT if set, else MemAvailable of /proc/meminfo
    (os.sysconf's free pages where there is none), never more than RLIMIT_AS allows."""
    limit = os.environ.get("GCMH_MEMORY_LIMIT")
    if limit:
        return _parse_size(limit)
    avail = None
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError, IndexError):
        pass
    if avail is None:
        try:
            avail = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):
            avail = 1 << 62  # unknown: don't refuse on memory
    try:
        import resource  # (POSIX only)

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY:
            avail = min(avail, soft)
    except (ImportError, OSError, ValueError):
        pass
    return int(avail)
