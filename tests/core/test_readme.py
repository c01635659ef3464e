"""Every Python snippet of README.md runs as written, and so do its `gcmh` command lines.

Each ```python block runs alone in a fresh interpreter, in an empty temporary folder
(a reader copies one block, not the page).  In the ```bash blocks, every line that
starts with `gcmh ` runs through bash, except those that need a running scheduler at
an address (`tcp://`); `gcmh-app` lines need a display and are tested in tests/app.
"""

import importlib.util
import os
import re
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


def test_the_readme_has_snippets_and_commands():
    assert len(PYTHON) >= 5
    assert len(COMMANDS) >= 8
    assert any(line.split("#")[0].split() == ["gcmh", "examples"] for line in COMMANDS)


@pytest.mark.parametrize("code", PYTHON, ids=[f"python-{i}" for i in range(len(PYTHON))])
def test_python_snippet_runs(code, tmp_path):
    missing = _needs(code)
    if missing:
        pytest.skip(f"needs {', '.join(missing)}")
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"{code}\n--- stderr:\n{proc.stderr}"
    if "print(" in code:
        assert proc.stdout.strip()


@pytest.mark.parametrize("line", COMMANDS, ids=[f"bash-{i}" for i in range(len(COMMANDS))])
def test_command_line_runs(line, tmp_path):
    missing = _needs(line)
    if missing:
        pytest.skip(f"needs {', '.join(missing)}")
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    proc = subprocess.run(["bash", "-c", line], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"{line}\n--- stderr:\n{proc.stderr}"
    assert proc.stdout.strip()
    for name in re.findall(r"(?:-o|--vtu) (\S+)", line):  # the files it says it writes
        assert (tmp_path / name).stat().st_size > 0, name
