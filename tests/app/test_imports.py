"""Import structure of ``gcmh_studio`` (the folder app/) and ``gcmh_core``, read with ast (nothing here imports
Qt or the app).

Every import a module makes (top level or inside a function) is an edge; the
graph must have no cycle, nothing may import ``gcmh_studio.__main__``, and the studio's
Qt-free modules must not reach Qt, VTK or pyvista when imported.
"""

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

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


GUI_MODULES = ("PyQt5", "PySide2", "PySide6", "PyQt6", "qtpy", "vtk", "vtkmodules", "pyvista", "pyvistaqt")


def loaded_gui_modules(statement: str) -> list[str]:
    """The GUI modules in sys.modules after running ``statement`` in a fresh interpreter."""
    code = (f"{statement}\nimport sys\n"
            f"print(' '.join(sorted({{m.split('.')[0] for m in sys.modules}} & set({GUI_MODULES!r}))))")
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


@pytest.mark.parametrize("statement", [
    "import gcmh_core",
    "import gcmh_studio.model",
    "import gcmh_studio.studio_io",
    "import gcmh_studio.jobs",
    "import gcmh_studio.inputs",
])
def test_qt_free_modules_load_no_gui(statement):
    assert loaded_gui_modules(statement) == []


def test_headless_loads_no_qt():
    loaded = loaded_gui_modules("import gcmh_studio.headless, gcmh_studio.make_gallery")
    assert not set(loaded) & {"PyQt5", "qtpy", "pyvistaqt"}, loaded
