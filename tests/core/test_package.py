"""The package's public face: what `import gcmh_core` exports and loads, the examples
as package data, and the benchmark scripts that live outside the library."""

import json
import shutil
import subprocess
import sys
import zipfile
from importlib import resources
from pathlib import Path

import pytest

import gcmh_core

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]


def _python(code: str, cwd: Path = ROOT) -> str:
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def test_import_loads_no_gui_and_no_cluster():
    # a fresh interpreter: this one has imported whatever the other tests needed
    code = ("import json, sys, gcmh_core; "
            "print(json.dumps(sorted(m.split('.')[0] for m in sys.modules)))")
    top = set(json.loads(_python(code)))
    # numpy, numba and sympy come with the first use of a name (lazy), never Qt and friends: `gcmh`
    # installs its Ctrl-C handler before anything heavy loads (issue 26, item 7)
    for heavy in ("numpy", "numba", "sympy", "PyQt5", "qtpy", "vtk", "vtkmodules", "pyvista", "pyvistaqt", "dask",
                  "distributed", "app"):
        assert heavy not in top, heavy
    # an extraction from sampled values loads the numba engine, still no sympy
    code = ("import json, sys, numpy as np; from gcmh_core import extract; "
            "g = np.linspace(-1, 1, 5); v = (g[:, None, None]**2 + g[:, None]**2 + g**2 - 0.5)[..., None]; "
            "assert extract(v, bounds=(-1, 1)).euler_characteristic() == 2; "
            "print(json.dumps(sorted(m.split('.')[0] for m in sys.modules)))")
    top = set(json.loads(_python(code)))
    assert "numba" in top and "sympy" not in top and "PyQt5" not in top


def test_all_names_resolve_and_are_public():
    for name in gcmh_core.__all__:
        assert not name.startswith("_")
        assert getattr(gcmh_core, name) is not None
    assert sorted(dir(gcmh_core)) == sorted(gcmh_core.__all__)
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        gcmh_core.nope  # noqa: B018


def test_readme_names_come_from_their_modules():
    from gcmh_core import analysis, examples, formula
    from gcmh_core import extract as extract_module  # the function: the package re-exports it

    assert extract_module is gcmh_core.extract
    assert gcmh_core.parse_system is formula.parse_system
    assert gcmh_core.evaluate_constant is formula.evaluate_constant
    assert gcmh_core.load_example is examples.load_example and gcmh_core.list_examples is examples.list_examples
    assert gcmh_core.topology_report is analysis.topology_report
    assert set(gcmh_core.METHODS) == {"gcmh", "gcch", "cms", "ccs"}
    assert set(gcmh_core.CONTINUATION_METHODS) | set(gcmh_core.SIMPLICIAL_METHODS) <= set(gcmh_core.METHODS)


def test_star_import_gives_the_public_names():
    namespace: dict = {}
    exec("from gcmh_core import *", namespace)
    assert set(gcmh_core.__all__) <= set(namespace)
    assert not any(name.startswith("_") for name in namespace if name != "__builtins__")


def test_examples_are_package_data():
    from gcmh_core.examples import example_names

    files = {f.name for f in resources.files("gcmh_core.examples").iterdir() if f.name.endswith(".toml")}
    assert {f"{name}.toml" for name in example_names()} == files
    assert len(files) >= 16
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert config["tool"]["setuptools"]["package-data"]["gcmh_core.examples"] == ["*.toml"]
    assert not (ROOT / "assets" / "examples").exists()


def test_examples_dir_env_overrides(tmp_path, monkeypatch):
    monkeypatch.setenv("GCMH_EXAMPLES_DIR", str(tmp_path))
    from gcmh_core.examples import example_names, examples_dir

    assert examples_dir() == tmp_path and example_names() == []
    (tmp_path / "mine.toml").write_text("")
    assert example_names() == ["mine"]


@pytest.mark.parametrize("script", ["bench.py", "bench_cluster.py"])
def test_benchmark_scripts_start_from_the_repository_root(script):
    proc = subprocess.run([sys.executable, f"tests/bench/{script}", "--help"], capture_output=True, text=True,
                          cwd=ROOT, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert f"python tests/bench/{script}" in proc.stdout
    assert not (ROOT / "gcmh_core" / script).exists()


def _source_files(folder: str, pattern: str) -> set[str]:
    return {p.relative_to(ROOT / folder).as_posix() for p in (ROOT / folder).rglob(pattern)
            if "__pycache__" not in p.parts}


def test_the_wheel_holds_both_packages_and_their_data(tmp_path):
    # Built from a copy (a build in the repository would leave build/ behind) with this
    # environment's setuptools (no download); its file list is what `pip install .` installs.
    src = tmp_path / "src"
    skip = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc")
    for folder in ("gcmh_core", "app"):
        shutil.copytree(ROOT / folder, src / folder, ignore=skip)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, src / name)
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index",
                           "-q", "-w", str(tmp_path / "dist"), str(src)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    (wheel,) = (tmp_path / "dist").glob("gcmh-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    tops = {name.split("/")[0] for name in names}
    dist_info = {t for t in tops if t.endswith(".dist-info")}
    assert tops - dist_info == {"gcmh_core", "gcmh_studio"}  # no top-level "app"
    # every module and data file of both folders, so a package missing from pyproject's list fails here
    for package, folder in (("gcmh_core", "gcmh_core"), ("gcmh_studio", "app")):
        for pattern in ("*.py", "*.toml", "*.png", "py.typed"):
            for rel in _source_files(folder, pattern):
                assert f"{package}/{rel}" in names, f"{folder}/{rel} is not in the wheel as {package}/{rel}"
    assert "gcmh_core/py.typed" in names and "gcmh_studio/py.typed" in names
    assert len([n for n in names if n.startswith("gcmh_studio/resources/gallery/") and n.endswith(".png")]) >= 10
    assert len([n for n in names if n.startswith("gcmh_core/examples/") and n.endswith(".toml")]) >= 16
    (info,) = dist_info
    scripts = (zipfile.ZipFile(wheel).read(f"{info}/entry_points.txt")).decode()
    assert "gcmh = gcmh_core.cli:main" in scripts and "gcmh-app = gcmh_studio.__main__:main" in scripts


def test_every_package_folder_is_in_the_package_list():
    # the list in pyproject.toml is explicit (a folder app/ cannot be found by name): a new
    # package folder must be added to it, or it is silently left out of the installed package
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    folders = {package: folder for package, folder in config["package-dir"].items()}
    found = set()
    for package, folder in folders.items():
        for init in (ROOT / folder).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT / folder).parts
            found.add(".".join([package, *rel]))
    assert sorted(config["packages"]) == sorted(found)


def test_the_command_line_module_loads_nothing_heavy():
    # `gcmh` imports gcmh_core.cli, whose main() installs the SIGINT/SIGTERM handlers: until then a
    # Ctrl-C is Python's KeyboardInterrupt with a traceback, so nothing slow may load before it
    code = ("import json, sys, gcmh_core.cli; "
            "print(json.dumps(sorted(m.split('.')[0] for m in sys.modules)))")
    top = set(json.loads(_python(code)))
    for heavy in ("numpy", "numba", "sympy", "importlib_metadata", "tqdm"):
        assert heavy not in top, heavy
    assert not any(m.startswith("importlib.metadata") for m in json.loads(
        _python("import json, sys, gcmh_core.cli; print(json.dumps(list(sys.modules)))")))


def test_shadowed_names_stay_functions():
    # gcmh_core.extract, .homology and .section are functions named as their modules: importing the
    # module (as the app and the engine do) must not replace the package's function
    code = ("import gcmh_core.extract, gcmh_core.homology, gcmh_core.section, gcmh_core, inspect; "
            "from gcmh_core.extract import METHODS; "
            "print(all(inspect.isfunction(getattr(gcmh_core, n)) for n in ('extract', 'homology', 'section')))")
    assert _python(code).strip() == "True"


def test_all_is_the_errors_and_the_lazy_names():
    assert sorted(gcmh_core.__all__) == sorted(["Cancelled", "InputError", "TooLargeError", *gcmh_core._LAZY])
