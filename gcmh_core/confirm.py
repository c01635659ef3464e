"""A topology that says how sure it is (issue 25, item 6): the run repeated on a second grid.

Every method sees M only through F's values at the grid's vertices, so what is thinner than a
cube (a thin tube, two sheets closer than a cube, a tangency) may vanish, split or merge, and the
same run says nothing of it.  `confirm` extracts M again on a second grid, another perturbation
seed and `factor` times the divisions, and compares what does not depend on the grid: the Euler
characteristic, the connected pieces and the boundary's components.  Where they differ, the result
is below the grid's resolution, and a finer div is suggested.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .complex import CellComplex
from .errors import InputError

__all__ = ["Confirmation", "confirm", "invariants"]

# the second grid: this many times the divisions (rounded up), the next perturbation seed
FACTOR = 1.5
# a finer div suggested where the two grids disagree: this many times the finer of the two
SUGGEST_FACTOR = 2

_NAMES = {"euler_characteristic": "Euler characteristic", "pieces": "pieces", "boundary": "boundary components"}


def invariants(cx: CellComplex) -> dict:
    """What `confirm` compares: {"euler_characteristic", "pieces", "boundary"} (the boundary's
    connected components; 0 for a closed M)."""
    from .analysis import boundary_components

    return {"euler_characteristic": int(cx.euler_characteristic()), "pieces": int(cx.connected_components()),
            "boundary": int(boundary_components(cx))}


@dataclass
class Confirmation:
    """The outcome of `confirm`.

    agree: chi, pieces and boundary components are the same on both grids.
    first, second: `invariants` of the first run and of the second.
    div, seed: the second grid's divisions (n ints) and perturbation seed.
    suggested_div: where they disagree, a finer div to try (n ints), else None.
    message: one sentence for a person (the CLI prints it, the app shows it).
    complex: the second run's CellComplex.
    """

    agree: bool
    first: dict
    second: dict
    div: list[int]
    seed: int
    suggested_div: list[int] | None
    message: str
    complex: CellComplex | None = field(default=None, repr=False)

    def as_dict(self) -> dict:
        """The JSON-ready fields (not the complex)."""
        return {"agree": self.agree, "first": dict(self.first), "second": dict(self.second), "div": list(self.div),
                "seed": self.seed, "suggested_div": self.suggested_div, "message": self.message}


def _div_text(div: Sequence[int]) -> str:
    return str(div[0]) if len(set(div)) == 1 else ",".join(map(str, div))


def _count(number: int, what: str) -> str:
    return f"{number} {what}" if number == 1 else f"{number} {what}s"


def _message(agree, first, second, div, seed, suggested) -> str:
    where = f"a second grid (div {_div_text(div)}, seed {seed})"
    if agree:
        return (f"confirmed on {where}: Euler characteristic {first['euler_characteristic']}, "
                f"{_count(first['pieces'], 'piece')}, {_count(first['boundary'], 'boundary component')}, "
                "as on the first")
    changed = ", ".join(f"{_NAMES[key]} {second[key]} (was {first[key]})" for key in _NAMES
                        if first[key] != second[key])
    return (f"not confirmed: on {where} {changed}. The result is below the grid's resolution (a part of M "
            f"thinner than a cube, or two parts closer than one, vanishes, splits or merges): try a finer "
            f"grid, div {_div_text(suggested)}")


def confirm(F, bounds=None, div=None, *, result: CellComplex | None = None, factor: float = FACTOR,
            **kwargs) -> Confirmation:
    """Repeat an extraction on a second grid and say whether its topology holds.

    F, bounds, div and kwargs are `extract`'s (formulas: sampled values exist on one grid only).
    result: the first run's CellComplex, if done already (its meta gives div and seed); else it
    is run here.  The second grid has `factor` (> 1) times the divisions, rounded up (even where an
    axis is glued with a flip), and the seed after the first's.

    Returns a `Confirmation`.

    >>> c = confirm("x1^2 + x2^2 + x3^2 - 1", (-1.5, 1.5), 8)
    >>> c.agree, c.div
    (True, [12, 12, 12])
    """
    from .extract import extract

    if isinstance(F, np.ndarray):
        raise InputError("confirm repeats the run on a finer grid: it needs F as formulas (sampled values "
                         "exist on their own grid only)")
    if not (isinstance(factor, (int, float)) and math.isfinite(factor) and factor > 1):
        raise InputError(f"factor must be a number above 1, got {factor!r}")
    first = result if result is not None else extract(F, bounds, div, **kwargs)
    meta = first.meta
    if "div" not in meta or "bounds" not in meta:
        raise InputError("result must come from extract (its meta gives the grid: div, bounds, seed)")
    div1 = [int(d) for d in meta["div"]]
    seed = int(meta.get("seed", kwargs.get("seed", 0))) + 1
    div2 = [math.ceil(factor * d) for d in div1]
    if meta.get("periodic"):  # (a flipped axis needs an even div: every axis made even)
        div2 = [d + d % 2 for d in div2]
    kw = {key: value for key, value in kwargs.items() if key not in ("seed", "div", "bounds")}
    if "params" not in kw and meta.get("params"):
        kw["params"] = dict(meta["params"])
    second = extract(F, meta["bounds"], div2, seed=seed, **kw)
    a, b = invariants(first), invariants(second)
    agree = a == b
    suggested = None if agree else [SUGGEST_FACTOR * max(x, y) for x, y in zip(div1, div2)]
    return Confirmation(agree, a, b, div2, seed, suggested, _message(agree, a, b, div2, seed, suggested), second)
