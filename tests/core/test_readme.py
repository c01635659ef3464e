"""Every Python snippet of README.md runs as written, and so do its `gcmh` command lines.

Each ```python block runs alone, in an empty temporary folder, with nothing defined
beforehand (a reader copies one block, not the page).  In the ```bash blocks, every
line that starts with `gcmh ` runs, except those that need a running scheduler at an
address (`tcp://`); `gcmh-app` lines need a display and are tested in tests/app.

One child interpreter runs all the snippets (each in a fresh namespace and folder),
and another all the command lines (each split as bash would and given to the
console script's `gcmh_core.cli.main`, its output in files of its own): a fresh
interpreter per block would load numba's kernel cache again every time, about a
second each.  That the installed `gcmh` script runs through bash is checked once.
"""

import importlib.util
import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[2] / "README.md"
TEXT = README.read_text(encoding="utf-8")
BIN = Path(sys.executable).parent  # gcmh is installed beside this interpreter


def _blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```", TEXT, flags=re.S | re.M)


PYTHON = _blocks("python")
COMMANDS = [line.strip() for block in _blocks("bash") for line in block.splitlines()
            if line.startswith("gcmh ") and "tcp://" not in line]


def _needs(code: str) -> list[str]:
    """Optional packages a snippet uses (it may be skipped only when they are missing)."""
    wanted = []
    if "save_vtu" in code or "pyvista" in code:
        wanted.append("pyvista")
    if "scheduler=" in code or "--scheduler" in code:
        wanted.append("distributed")
    return [m for m in wanted if importlib.util.find_spec(m) is None]


# Runs in the child: each snippet in its own folder and a fresh namespace, as `python -c` would run it;
# sys.stdout and sys.stderr are real files (the CLI writes .npz bytes to sys.stdout.buffer).
RUN_SNIPPETS = r"""
import json, os, sys, traceback
jobs = json.load(open(sys.argv[1]))
out = []
for folder, code in jobs:
    os.chdir(folder)
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = open("stdout.txt", "w"), open("stderr.txt", "w")
    status = 0
    try:
        exec(compile(code, "<README snippet>", "exec"), {"__name__": "__main__", "__builtins__": __builtins__})
    except BaseException:
        traceback.print_exc()
        status = 1
    finally:
        sys.stdout.close(), sys.stderr.close()
        sys.stdout, sys.stderr = saved
    os.replace("stdout.txt", os.path.join(os.pardir, os.path.basename(folder) + ".out"))
    os.replace("stderr.txt", os.path.join(os.pardir, os.path.basename(folder) + ".err"))
    out.append(status)
print(json.dumps(out))
"""

RUN_COMMANDS = RUN_SNIPPETS.replace(
    'exec(compile(code, "<README snippet>", "exec"), {"__name__": "__main__", "__builtins__": __builtins__})',
    "from gcmh_core.cli import main\n        status = main(code)")


def _run_all(child: str, jobs: list, root: Path) -> list[dict]:
    """Run ``jobs`` [(name, code)] in one child, each in the empty folder root/name; return
    dict(status, stdout, stderr, folder) per job."""
    folders = []
    for name, _ in jobs:
        (root / name).mkdir()
        folders.append(str(root / name))
    spec = root / "jobs.json"
    spec.write_text(json.dumps([[f, code] for f, (_, code) in zip(folders, jobs)]))
    proc = subprocess.run([sys.executable, "-c", child, str(spec)], cwd=root, capture_output=True, text=True,
                          timeout=1200)
    assert proc.returncode == 0, proc.stderr
    statuses = json.loads(proc.stdout.strip().splitlines()[-1])
    return [dict(status=s, stdout=(root / f"{name}.out").read_text(), stderr=(root / f"{name}.err").read_text(),
                 folder=root / name) for s, (name, _) in zip(statuses, jobs)]


@pytest.fixture(scope="module")
def snippet_runs(tmp_path_factory) -> dict:
    jobs = [(f"python-{i}", code) for i, code in enumerate(PYTHON) if not _needs(code)]
    return dict(zip([j[0] for j in jobs], _run_all(RUN_SNIPPETS, jobs, tmp_path_factory.mktemp("snippets"))))


@pytest.fixture(scope="module")
def command_runs(tmp_path_factory) -> dict:
    jobs = []
    for i, line in enumerate(COMMANDS):
        argv = shlex.split(line, comments=True)   # as bash splits it: quotes, and the comment dropped
        assert argv[0] == "gcmh", line
        if not _needs(line):
            jobs.append((f"bash-{i}", argv[1:]))
    return dict(zip([j[0] for j in jobs], _run_all(RUN_COMMANDS, jobs, tmp_path_factory.mktemp("commands"))))


def test_the_readme_has_snippets_and_commands():
    assert len(PYTHON) >= 5
    assert len(COMMANDS) >= 8
    assert any(line.split("#")[0].split() == ["gcmh", "examples"] for line in COMMANDS)


@pytest.mark.parametrize("i", range(len(PYTHON)), ids=[f"python-{i}" for i in range(len(PYTHON))])
def test_python_snippet_runs(i, snippet_runs):
    code = PYTHON[i]
    missing = _needs(code)
    if missing:
        pytest.skip(f"needs {', '.join(missing)}")
    run = snippet_runs[f"python-{i}"]
    assert run["status"] == 0, f"{code}\n--- stderr:\n{run['stderr']}"
    if "print(" in code:
        assert run["stdout"].strip()


@pytest.mark.parametrize("i", range(len(COMMANDS)), ids=[f"bash-{i}" for i in range(len(COMMANDS))])
def test_command_line_runs(i, command_runs):
    line = COMMANDS[i]
    missing = _needs(line)
    if missing:
        pytest.skip(f"needs {', '.join(missing)}")
    run = command_runs[f"bash-{i}"]
    assert run["status"] == 0, f"{line}\n--- stderr:\n{run['stderr']}"
    assert run["stdout"].strip()
    for name in re.findall(r"(?:-o|--vtu) (\S+)", line):  # the files it says it writes
        assert (run["folder"] / name).stat().st_size > 0, name


def test_the_installed_gcmh_runs_through_bash(tmp_path):
    """The console script beside this interpreter, on PATH, as a reader types the README's lines."""
    line = next(line for line in COMMANDS if line.split("#")[0].split() == ["gcmh", "examples"])
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    proc = subprocess.run(["bash", "-c", line], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"{line}\n--- stderr:\n{proc.stderr}"
    assert "klein-bottle" in proc.stdout
