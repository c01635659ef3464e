"""The Manifold tab's names, without Qt: the variables' names as n changes, and free names that look like typos.

:class:`VariableNames`: the variables are x1, ..., xn (the defaults, following n) until the user types their
own; the names a smaller n hid come back when n grows again; in complex mode the real names it made (x, y for
z) give way to typed ones. The panel (:class:`gcmh_studio.qt_formula_panel.QtFormulaPanel`) asks it.

A free name in a formula becomes a parameter with a slider; one edit away from a variable (:func:`did_you_mean`)
it is more likely a typo, held back (:func:`hold_typos`) until the user writes the variable
(:func:`replace_name`) or keeps it as a parameter.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Iterable, Sequence

from .inputs import default_variables


class VariableNames:
    """Which names the variables get; see the module's doc."""

    def __init__(self) -> None:
        self.auto = True                # the names are the defaults: they follow n
        self.kept: list[str] = []       # the names a smaller n hid, to bring back
        self.auto_complex = ""          # the real names complex mode made (replaced while not edited)

    def typed(self, *_) -> None:
        """The user typed names: they no longer follow n."""
        self.auto = False

    def resized(self, names: list[str], n: int) -> list[str]:
        """n names in place of ``names`` (those on show), keeping what was typed (and what an earlier n hid)."""
        if self.auto or not names:
            return default_variables(n)
        self.kept = names + self.kept[len(names):]
        names = (self.kept + [f"x{i + 1}" for i in range(len(self.kept), n)])[:n]
        for i in range(len(names)):   # fill in defaults that would clash
            if names[i] in names[:i]:
                names[i] = f"x{i + 1}"
        return names

    def complex_own(self, text: str) -> bool:
        """Are the names on show (``text``) complex mode's own, or none: to be replaced as the system changes?"""
        return text in (self.auto_complex, "")

    def reset(self, variables: Sequence[str], defaults: list[str], complex_mode: bool) -> None:
        """A new system, named ``variables`` (``defaults``: its default names): what an earlier one hid does not
        come back in it."""
        self.auto = not complex_mode and list(variables) == defaults
        self.auto_complex = ", ".join(defaults) if complex_mode else ""
        self.kept = list(variables)


def one_edit_apart(a: str, b: str) -> bool:
    """``a`` becomes ``b`` by one insertion, deletion, substitution or swap of neighbours."""
    if a == b or abs(len(a) - len(b)) > 1:
        return False
    if len(a) == len(b):
        diff = [i for i, (x, y) in enumerate(zip(a, b)) if x != y]
        return len(diff) == 1 or (len(diff) == 2 and diff[1] == diff[0] + 1
                                  and a[diff[0]] == b[diff[1]] and a[diff[1]] == b[diff[0]])
    short, long = (a, b) if len(a) < len(b) else (b, a)
    return any(long[:i] + long[i + 1:] == short for i in range(len(long)))


def did_you_mean(name: str, variables: Iterable[str]) -> str | None:
    """The variable a free name is probably a typo of ("yy" -> "y", "x12" -> "x1"), or None.

    One edit away, and not two one-letter names (a parameter "a" beside a variable "x" is no typo)."""
    for v in variables:
        if max(len(v), len(name)) >= 2 and one_edit_apart(name, v):
            return v
    return None


def hold_typos(found: Iterable[str], variables: Sequence[str],
               kept: Collection[str]) -> tuple[tuple[str, str] | None, list[str]]:
    """(the first free name of ``found`` that looks like a typo of a variable, with that variable, or None;
    ``found`` without such names). ``kept``: names the user said are parameters, never typos."""
    found = list(found)
    typos = {f: v for f in dict.fromkeys(found) if f not in kept and (v := did_you_mean(f, variables)) is not None}
    return next(iter(typos.items()), None), [f for f in found if f not in typos]


def replace_name(text: str, name: str, variable: str) -> str:
    """``text`` with ``variable`` written for the free name ``name`` (whole names only)."""
    return re.sub(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", variable, text)
