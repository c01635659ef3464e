"""Your own data in the studio, without Qt: data files opened as F's components, their levels, the runs
at a level (a coarse grid while a slider is held, the full one at rest), results saved as .npz opened
again, and what a session keeps of them.

:class:`DataSource` holds the fields read from the files (memory maps where the format allows:
`gcmh_core.data_files`) and each component's data range; :meth:`DataSource.extract` runs the engine at
the levels given (on every ``stride``-th sample per axis for a coarse step); the names it gives the axes
carry the file's units ("x [mm]").  The window's data panel (:mod:`gcmh_studio.qt_data_panel`) drives it.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

# a coarse step (a level slider held) samples the grid so that it has about this many points at most
COARSE_SAMPLES = 48**3
SESSION_KEY = "data"


def is_result_file(path: str) -> bool:
    """Is ``path`` a cell complex saved by the studio or ``gcmh extract -o`` (a .npz of format
    gcmh-complex/1), not a data archive?"""
    if not str(path).lower().endswith(".npz"):
        return False
    try:
        with np.load(path, allow_pickle=False) as z:
            return "format" in z.files and str(z["format"]).startswith("gcmh-complex/")
    except Exception:  # noqa: BLE001 - unreadable: not a result (the data reader then says why)
        return False


def is_data_file(path: str) -> bool:
    from gcmh_core.data_files import DATA_SUFFIXES

    low = _file_of(path).lower()
    return any(low.endswith(s) for s in DATA_SUFFIXES)


def open_result(path: str):
    """(CellComplex, names, title) of a saved result: the names its meta gives (with units when it
    came from data), the title its file name."""
    from gcmh_core import CellComplex

    cx = CellComplex.load(path)
    units = cx.meta.get("units")
    names = with_units(cx.point_names(), units if isinstance(units, list) else None)
    return cx, names, os.path.basename(str(path))


def with_units(names, units) -> list[str]:
    """Axis names as the view shows them: "x [mm]" where the file gives a unit."""
    units = list(units or [])
    return [f"{n} [{units[i]}]" if i < len(units) and units[i] else str(n) for i, n in enumerate(names)]


@dataclass
class LevelRange:
    """One component of F: where its data come from and the finite range of their values."""

    source: str
    lo: float
    hi: float

    def clamp(self, level: float) -> float:
        return min(max(float(level), self.lo), self.hi)


class DataSource:
    """Data files opened as F's components (one component per field, or a field's trailing components).

    specs: the files as given ("scan.nii.gz", "run.npz:u,v"); levels: the starting levels (default: the
    middle of each component's range); bounds: a box overriding the files'.  Reading errors raise
    gcmh_core.InputError with the file named.
    """

    def __init__(self, specs, levels=None, bounds=None, components: bool | None = None):
        from gcmh_core.data_files import _plan, parse_levels

        self.specs = [os.path.abspath(s) if os.path.exists(s) else s for s in map(str, specs)]
        self.bounds_override = bounds
        self.components = components
        self.changed: list[str] = []   # (what `from_session` found changed since the session was saved)
        # the headers and the fields (memory maps where the format allows), then one pass for the ranges
        self.plan = _plan(self.specs, 0.0, bounds, components)
        self.ranges = self._ranges()
        given = parse_levels(levels)
        k = self.k
        if given is None:
            self.levels = [0.5 * (r.lo + r.hi) for r in self.ranges]
        else:
            self.levels = list(given) * k if len(given) == 1 else list(given)
        if len(self.levels) != k:
            from gcmh_core import InputError

            raise InputError(f"{len(self.levels)} levels for {k} components of F")

    # ------------------------------------------------------------------ what it holds
    @property
    def n(self) -> int:
        return len(self.plan.bounds)

    @property
    def k(self) -> int:
        return int(self.plan.shape[-1])

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.plan.shape[:-1])

    @property
    def variables(self) -> list[str]:
        return list(self.plan.fields[0].axis_names)

    @property
    def units(self) -> list[str | None]:
        return list(self.plan.fields[0].units)

    @property
    def names(self) -> list[str]:
        """The axes as the view names them, with their units: ["x [mm]", "y [mm]", "z [mm]", "t [sec]"]."""
        return with_units(self.variables, self.units)

    @property
    def title(self) -> str:
        return " ; ".join(os.path.basename(s) for s in self.specs)

    @property
    def notes(self) -> list[str]:
        return list(self.plan.notes)

    def _ranges(self) -> list[LevelRange]:
        """Each component's finite data range (one pass over the data, slab by slab)."""
        from gcmh_core.data_files import field_ranges

        out = []
        for f in self.plan.fields:
            for c, (lo, hi) in enumerate(field_ranges(f)):
                name = f.source if f.components == 1 else f"{f.source} (component {c})"
                if not math.isfinite(lo):
                    from gcmh_core import InputError

                    raise InputError(f"{name}: every value is NaN or infinite")
                out.append(LevelRange(name, lo, hi))
        return out

    # ------------------------------------------------------------------ runs
    def stride_for(self, coarse: bool) -> int:
        """Samples skipped per axis: 1 at rest; for a coarse step enough that the grid has about
        `COARSE_SAMPLES` points (and at least 3 samples per axis)."""
        if not coarse:
            return 1
        total = math.prod(self.shape)
        s = max(1, math.ceil((total / COARSE_SAMPLES) ** (1.0 / self.n)))
        while s > 1 and min(self.shape) // s < 3:
            s -= 1
        return s

    def sampled(self, levels=None, stride: int = 1):
        """F's values (a gcmh_core.data_files.SampledData) at ``levels`` on every ``stride``-th sample."""
        from gcmh_core.data_files import _load, _Plan

        levels = list(self.levels if levels is None else levels)
        plan = self.plan
        if stride > 1:
            index = tuple(slice(None, None, stride) for _ in range(self.n))
            fields = []
            for f in plan.fields:
                g = _copy_field(f)
                g.values = f.values[index]
                fields.append(g)
            # the kept samples' own box: the last one kept may stop short of the grid's end
            last = np.array([(d - 1) // stride * stride for d in self.shape], float)
            lo, hi = plan.bounds[:, 0], plan.bounds[:, 1]
            step = (hi - lo) / (np.array(self.shape, float) - 1)
            box = np.stack([lo, lo + step * last], axis=1)
            shape = tuple(fields[0].values.shape[: self.n]) + (self.k,)
            plan = _Plan(fields, levels, box, shape, plan.notes)
        else:
            plan = _Plan(plan.fields, levels, plan.bounds, plan.shape, plan.notes)
        return _load(plan, None)

    def extract(self, levels=None, coarse: bool = False, progress=None, cancel=None, **kwargs):
        """The CellComplex at ``levels`` (default: the current ones); ``coarse``: on a sampled grid
        (`stride_for`).  Its meta names the files, levels, units and the stride."""
        from gcmh_core.data_files import extract_data

        stride = self.stride_for(coarse)
        data = self.sampled(levels, stride)
        cx = extract_data(None, data=data, progress=progress, cancel=cancel, **kwargs)
        cx.meta["data"]["stride"] = stride
        cx.meta["data"]["files"] = list(self.specs)
        return cx

    # ------------------------------------------------------------------ sessions
    def session_entry(self) -> dict:
        """What a session keeps: the files by path (with each file's size and modification time, to tell a
        changed file when opened again), the levels, the box override and the component flag."""
        return {"files": list(self.specs), "levels": [float(v) for v in self.levels],
                "bounds": None if self.bounds_override is None else np.asarray(self.bounds_override).tolist(),
                "components": self.components, "seen": [file_stamp(s) for s in self.specs]}

    @classmethod
    def from_session(cls, entry: dict) -> DataSource:
        """A source from :meth:`session_entry`.  A file no longer where the session says is one InputError
        that says so (moved or deleted) and how to open it again (:func:`moved_file`); a file changed since
        (another size or modification time) opens, with a note in ``changed`` for the window to show."""
        from gcmh_core import InputError

        from .session_schema import SessionError, data_entry

        try:   # (checked whole, as when the session is read: a dropped session file is read here)
            data_entry(entry)
        except SessionError as e:
            raise InputError(f"the session's data entry is not usable: {e}") from None
        problem = moved_file(entry)
        if problem:
            raise InputError(problem)
        source = cls(entry["files"], entry.get("levels"), entry.get("bounds"), entry.get("components"))
        source.changed = changed_files(entry)
        return source


def _file_of(spec) -> str:
    from gcmh_core.data_files import split_spec

    return split_spec(str(spec))[0]


def file_stamp(spec) -> list[int] | None:
    """[size in bytes, modification time in ns] of a spec's file (None if it cannot be read)."""
    try:
        st = os.stat(_file_of(spec))
    except OSError:
        return None
    return [int(st.st_size), int(st.st_mtime_ns)]


def moved_file(entry: dict) -> str | None:
    """The message for the first data file of a session (or a remembered source) that is no longer where
    it says, else None."""
    for spec in entry.get("files") or []:
        path = _file_of(spec)
        if not os.path.exists(path):
            return (f"the session's data file {path} is not there any more (moved or deleted): "
                    "open it again with File \u2192 Open data\u2026")
    return None


def changed_files(entry: dict) -> list[str]:
    """One line per data file whose size or modification time is not what the entry saw (files it saw
    nothing of, e.g. sessions saved before it kept them, are taken as they are)."""
    import time

    out = []
    seen = entry.get("seen") or []
    for spec, then in zip(entry.get("files") or [], seen):
        now = file_stamp(spec)
        if then is None or now is None or list(then) == now:
            continue
        when = time.strftime("%Y-%m-%d %H:%M", time.localtime(now[1] / 1e9))
        size = f", {then[0]:,} -> {now[0]:,} bytes" if then[0] != now[0] else ""
        out.append(f"{_file_of(spec)} has changed since it was saved (modified {when}{size}): "
                   "its data are read as they are now")
    return out


def session_data(path) -> dict | None:
    """The data entry of a session file (None for a session of formulas, or a file that is not JSON: the
    session reader then says what is wrong with it)."""
    import json

    try:
        with open(path, "rb") as f:
            d = json.loads(f.read(1 << 20).decode("utf-8"))
    except (OSError, ValueError):
        return None
    entry = d.get(SESSION_KEY) if isinstance(d, dict) else None
    return entry if isinstance(entry, dict) else None


def _copy_field(f):
    from dataclasses import replace

    return replace(f, notes=list(f.notes), bounds=f.bounds.copy())
