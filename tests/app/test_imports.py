"""Import structure of ``gcmh_studio`` (the folder app/) and ``gcmh_core``, read with ast (nothing here imports
Qt or the app).

Every import a module makes (top level or inside a function) is an edge; the
graph must have no cycle, nothing may import ``gcmh_studio.__main__``, and the layers hold,
lowest first (a module imports its own layer and those below, never one above):

- the engine, ``gcmh_core``: never the studio, never Qt; pyvista and VTK only inside a
  function (``CellComplex.to_pyvista``), so ``import gcmh_core`` loads none of them;
- the studio's Qt-free modules, the ``app/`` files pyproject.toml's ``[tool.mypy]`` checks:
  the engine and each other only, no Qt, VTK or pyvista anywhere in them;
- the rest of the studio (scenes, widgets), then ``gcmh_studio.__main__``.

Every module of the studio that is not a ``qt_`` module and imports no GUI module itself
or through the studio is in that list, so a new Qt-free module is type-checked and kept
Qt-free from its first commit.
"""

import ast
import os
import subprocess
import sys
from pathlib import Path

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

REPO = Path(__file__).resolve().parents[2]
# package name -> its folder: the folder app/ installs as the package gcmh_studio
PACKAGES = {"gcmh_studio": "app", "gcmh_core": "gcmh_core"}


def module_files() -> dict[str, Path]:
    """Dotted module name -> file, for every module of the packages."""
    out = {}
    for pkg, folder in PACKAGES.items():
        for path in sorted((REPO / folder).rglob("*.py")):
            parts = [pkg, *path.relative_to(REPO / folder).with_suffix("").parts]
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


def imported_modules(name: str, path: Path, known) -> set[str]:
    """The modules of the packages that module ``name`` imports (relative imports resolved)."""
    is_pkg = path.name == "__init__.py"
    package = name if is_pkg else name.rpartition(".")[0]
    found = set()

    def add(target: str) -> None:
        # "from .x import y": y may be a module (app.x.y) or a name in app.x
        while target and target not in known:
            target = target.rpartition(".")[0]
        if target and target != name:
            found.add(target)

    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            for a in node.names:
                add(a.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            for a in node.names:
                add(f"{mod}.{a.name}")
    return found


def import_graph() -> dict[str, set[str]]:
    files = module_files()
    return {name: imported_modules(name, path, files) for name, path in files.items()}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of the graph as a list of modules (first == last), or None."""
    state: dict[str, int] = {}     # 1: on the current path, 2: done
    stack: list[str] = []

    def visit(u):
        state[u] = 1
        stack.append(u)
        for v in sorted(graph.get(u, ())):
            if state.get(v) == 1:
                return stack[stack.index(v):] + [v]
            if v not in state:
                cyc = visit(v)
                if cyc:
                    return cyc
        stack.pop()
        state[u] = 2
        return None

    for u in sorted(graph):
        if u not in state:
            cyc = visit(u)
            if cyc:
                return cyc
    return None


def test_the_graph_is_read():
    g = import_graph()
    assert "gcmh_studio.qt_main_window" in g and "gcmh_core.extract" in g
    assert "gcmh_studio.model" in g["gcmh_studio.qt_main_window"]
    assert "gcmh_studio.headless" in g["gcmh_studio.make_gallery"]


def test_find_cycle_finds_one():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set(), "c": {"a"}}) is None


def test_no_import_cycle_in_app_or_gcmh_core():
    cycle = find_cycle(import_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_nothing_imports_the_command_line():
    g = import_graph()
    users = sorted(m for m, deps in g.items() if "gcmh_studio.__main__" in deps)
    assert users == [], f"{users} import gcmh_studio.__main__"


def test_gcmh_core_never_imports_the_app():
    g = import_graph()
    bad = sorted(m for m, deps in g.items()
                 if m.startswith("gcmh_core") and any(d.startswith("gcmh_studio") for d in deps))
    assert bad == []


# Qt and its bindings; with VTK and pyvista, what draws
QT_MODULES = ("PyQt5", "PySide2", "PySide6", "PyQt6", "qtpy", "pyvistaqt")
GUI_MODULES = (*QT_MODULES, "vtk", "vtkmodules", "pyvista")


def external_imports(path: Path) -> list[tuple[str, int, bool]]:
    """(top-level package, line, inside a function or class) for each absolute import of the file."""
    out = []

    def walk(node, nested):
        for child in ast.iter_child_nodes(node):
            inner = nested or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
            if isinstance(child, ast.Import):
                out.extend((a.name.split(".")[0], child.lineno, nested) for a in child.names)
            elif isinstance(child, ast.ImportFrom) and not child.level and child.module:
                out.append((child.module.split(".")[0], child.lineno, nested))
            walk(child, inner)

    walk(ast.parse(path.read_text(encoding="utf-8"), str(path)), False)
    return out


def qt_free_modules() -> set[str]:
    """The studio's Qt-free modules: the app/ files of pyproject.toml's [tool.mypy] files."""
    files = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["mypy"]["files"]
    out = set()
    for f in files:
        path = Path(f)
        if path.parts[0] == PACKAGES["gcmh_studio"]:
            name = ".".join(["gcmh_studio", *path.with_suffix("").parts[1:]])
            out.add(name.removesuffix(".__init__"))
    return out


def layer_violations(graph: dict[str, set[str]], externals: dict[str, list[tuple[str, int, bool]]],
                     qt_free: set[str]) -> list[str]:
    """Each import that breaks a layer (see the module's doc), as "module: what"."""
    bad = []
    for m, deps in sorted(graph.items()):
        if m.startswith("gcmh_core"):
            bad += [f"{m}: imports the studio module {d}" for d in sorted(deps) if d.startswith("gcmh_studio")]
            for top, line, nested in externals[m]:
                if top in QT_MODULES or (top in GUI_MODULES and not nested):
                    bad.append(f"{m}: imports {top} (line {line}){'' if nested else ' at its top level'}")
        elif m in qt_free:
            bad += [f"{m}: a Qt-free module imports {d}" for d in sorted(deps)
                    if d.startswith("gcmh_studio") and d not in qt_free]
            bad += [f"{m}: a Qt-free module imports {top} (line {line})"
                    for top, line, _ in externals[m] if top in GUI_MODULES]
    return bad


def gui_free_studio_modules(graph, externals) -> set[str]:
    """Studio modules, qt_ ones aside, that import no GUI module, themselves or through the studio."""
    def draws(m, seen):
        if m in seen:
            return False
        seen.add(m)
        return (any(top in GUI_MODULES for top, _, _ in externals[m])
                or any(draws(d, seen) for d in graph[m] if d.startswith("gcmh_studio")))

    return {m for m in graph if m.startswith("gcmh_studio") and not m.rpartition(".")[2].startswith("qt_")
            and not draws(m, set())}


def all_external_imports() -> dict[str, list[tuple[str, int, bool]]]:
    return {name: external_imports(path) for name, path in module_files().items()}


def test_the_layers_hold():
    assert layer_violations(import_graph(), all_external_imports(), qt_free_modules()) == []


def test_a_broken_layer_is_found(tmp_path):
    graph, externals, qt_free = import_graph(), all_external_imports(), qt_free_modules()
    assert {"gcmh_studio.model", "gcmh_studio.jobs"} <= qt_free
    # the engine importing the studio; a Qt-free module importing a widget module, or Qt itself
    graph["gcmh_core.extract"].add("gcmh_studio.model")
    graph["gcmh_studio.model"].add("gcmh_studio.qt_viewer")
    externals["gcmh_studio.jobs"].append(("qtpy", 1, True))
    # the engine importing pyvista at its top level (inside a function it may)
    path = tmp_path / "mod.py"
    path.write_text("import pyvista\n\ndef f():\n    from pyvista import PolyData\n    import qtpy.QtCore\n")
    assert external_imports(path) == [("pyvista", 1, False), ("pyvista", 4, True), ("qtpy", 5, True)]
    externals["gcmh_core.complex"] = external_imports(path)
    assert layer_violations(graph, externals, qt_free) == [
        "gcmh_core.complex: imports pyvista (line 1) at its top level",
        "gcmh_core.complex: imports qtpy (line 5)",
        "gcmh_core.extract: imports the studio module gcmh_studio.model",
        "gcmh_studio.jobs: a Qt-free module imports qtpy (line 1)",
        "gcmh_studio.model: a Qt-free module imports gcmh_studio.qt_viewer",
    ]


def test_every_qt_free_module_is_type_checked():
    graph, externals, qt_free = import_graph(), all_external_imports(), qt_free_modules()
    assert qt_free <= set(graph), sorted(qt_free - set(graph))  # (a file listed in pyproject.toml is gone)
    missing = sorted(gui_free_studio_modules(graph, externals) - qt_free)
    assert missing == [], f"add them to [tool.mypy] files in pyproject.toml: {missing}"


def loaded_gui_modules(statement: str) -> list[str]:
    """The GUI modules in sys.modules after running ``statement`` in a fresh interpreter."""
    code = (f"{statement}\nimport sys\n"
            f"print(' '.join(sorted({{m.split('.')[0] for m in sys.modules}} & set({GUI_MODULES!r}))))")
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


def test_qt_free_modules_load_no_gui():
    # one interpreter for all: the static check above says which module it would be
    assert loaded_gui_modules("import gcmh_core") == []
    assert loaded_gui_modules("; ".join(f"import {m}" for m in sorted(qt_free_modules()))) == []


def test_headless_loads_no_qt():
    loaded = loaded_gui_modules("import gcmh_studio.headless, gcmh_studio.make_gallery")
    assert not set(loaded) & {"PyQt5", "qtpy", "pyvistaqt"}, loaded
