"""Write docs/examples.md from the example files, gcmh_core/examples/*.toml.

    python docs/make_examples.py > docs/examples.md

The page is generated so that it cannot drift from the examples: tests/core/test_docs.py
checks that the committed page is what this script prints.  It describes the shipped
examples ($GCMH_EXAMPLES_DIR is ignored here).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
GALLERY = ROOT / "app" / "resources" / "gallery"   # the app's thumbnails (python -m gcmh_studio.make_gallery)
COMMAND = "python docs/make_examples.py > docs/examples.md"

INTRO = f"""\
# Examples

Each example is one TOML file in [`gcmh_core/examples/`](../gcmh_core/examples/) (formulas, domain,
division, a point on M, the default view, and a few sentences on what to look at), installed
with the package. `load_example(name)` reads one, `list_examples()` all; `gcmh examples` lists
them, `gcmh extract --example NAME` and `gcmh-app --example NAME` run one. Set
`GCMH_EXAMPLES_DIR` to a folder of your own TOML files to use those instead. The file format is
described at the top of [`gcmh_core/examples/__init__.py`](../gcmh_core/examples/__init__.py).

An example whose coordinates are angles may glue its domain, `periodic = ["s:flip=t", "t"]`
(see [identified axes](identified-axes.md)); its description says which version, cut open or
glued, it shows. An example may have parameters, a `[params]` table with each one's value and
range (`a = {{ value = 0.5, min = -1, max = 1 }}`), and may be written over C^m:
`complex = ["z = cos(w)"]` with `complex_variables = ["w", "z"]` (see
[parameters and complex equations](parameters.md)).

This page is generated from the files themselves (edit them, not the page): `{COMMAND}`.
"""


def _text(value: object) -> str:
    """A TOML number or constant text as it is written in the file."""
    return value if isinstance(value, str) else repr(value)


def _domain(raw: list, variables: list[str]) -> str:
    pairs = [f"[{_text(lo)}, {_text(hi)}]" for lo, hi in raw]
    if len(pairs) == 1 or len(set(pairs)) == 1:
        return f"{pairs[0]} on every axis"
    return ", ".join(f"{v} in {p}" for v, p in zip(variables, pairs))


def _div(div: int | list[int]) -> str:
    return str(div) if isinstance(div, int) else " x ".join(map(str, div))


def _comment(text: str) -> str:
    """The file's opening comment (where the example comes from, how the formulas were found)."""
    lines = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    return " ".join(lines)


def _features(ex) -> str:
    said = []
    if ex.complex:
        said.append("complex")
    if ex.params:
        said.append("parameter " + ", ".join(ex.params))
    if ex.periodic:
        said.append("glued: " + ", ".join(f"`{p}`" for p in ex.periodic))
    return "; ".join(said)


def _section(ex) -> str:
    text = Path(str(ex.path)).read_text(encoding="utf-8")
    raw = tomllib.loads(text)
    out = [f"## {ex.name}", ""]
    if (GALLERY / f"{ex.name}.png").is_file():
        out += [f'<img src="../app/resources/gallery/{ex.name}.png" width="240" align="right" alt="{ex.title}">', ""]
    out += [f"**{ex.title}**: a manifold of dimension {ex.dim} in R^{ex.n} (n = {ex.n}, k = {ex.k}).", "",
            ex.description, ""]
    note = _comment(text)
    if note:
        out += [f"*From the file:* {note}", ""]
    if ex.complex:
        out.append(f"- equations over C^{len(ex.complex_variables)} in {', '.join(ex.complex_variables)}: "
                   + "; ".join(f"`{e}`" for e in ex.complex))
        out.append("- split into the real system F = 0, " + ", ".join(
            f"{v} ({ex.labels[v]})" if v in ex.labels else v for v in ex.variables) + ":")
    else:
        out.append(f"- F = 0 in {', '.join(ex.variables)}:")
    out += [f"  - `{f}`" for f in ex.formulas]
    out.append(f"- domain: {_domain(raw['bounds'], ex.variables)}")
    div = f"- div: {_div(ex.div)}"
    if ex.paper_div is not None:
        div += f" (the paper's: {_div(ex.paper_div)})"
    out.append(div)
    for name in ex.params:
        got = raw["params"][name]
        out.append(f"- parameter {name} = {_text(got['value'])}, from {_text(got['min'])} to {_text(got['max'])}")
    if ex.periodic:
        out.append(f"- glued axes: `periodic = {ex.periodic!r}`".replace("'", '"'))
    view = ex.view
    out.append(f"- view: ({', '.join(view['project'])}) as 3D axes, coloured by {view['color']}, "
               f"{view['mapping']} mapping")
    out.append(f"- a point on M (continuation's start): ({', '.join(_text(v) for v in raw['start'])})")
    out += ["", f"Run it: `gcmh extract --example {ex.name}`; see it: `gcmh-app --example {ex.name}`.", ""]
    return "\n".join(out)


def markdown() -> str:
    """The whole page, as the files in gcmh_core/examples/ give it."""
    os.environ.pop("GCMH_EXAMPLES_DIR", None)
    from gcmh_core.examples import list_examples  # (after the folder is settled)

    examples = list_examples()
    rows = ["| name | n | k | title | |", "|---|---|---|---|---|"]
    rows += [f"| [`{ex.name}`](#{ex.name}) | {ex.n} | {ex.k} | {ex.title} | {_features(ex)} |" for ex in examples]
    return "\n".join([INTRO, *rows, "", *(_section(ex) for ex in examples)]).rstrip("\n") + "\n"


if __name__ == "__main__":
    sys.stdout.write(markdown())
