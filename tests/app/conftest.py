"""Fixtures for the window tests (pytest-qt; they need a real X server, e.g. Xvfb).

Run:  xvfb-run -a .venv/bin/python -m pytest tests/app -q
  or: .venv/bin/python -m pytest tests/app -q --xvfb-backend xvfb
test_model.py, test_inputs.py and test_imports.py need no display: ``-p no:xvfb`` runs them anywhere.
"""

import os
import tempfile

import pytest

from app_helpers import open_window

if not os.environ.get("XDG_RUNTIME_DIR"):
    d = os.path.join(tempfile.gettempdir(), f"runtime-{os.getuid()}")
    os.makedirs(d, mode=0o700, exist_ok=True)
    os.environ["XDG_RUNTIME_DIR"] = d


@pytest.fixture(autouse=True)
def slow_pictures_are_not_hangs(monkeypatch):
    """A still picture may take longer than the worker's hang limit (20 s) on a loaded machine; the tests that
    expect the worker to draw must not see it ended and the window draw instead. (test_still_process.py sets the
    limit where it tests it.)"""
    monkeypatch.setattr("gcmh_studio.still_process.HANG_S", 600.0)


@pytest.fixture
def window(qtbot):
    w = open_window(qtbot, (1200, 800))
    yield w
    w.close()


@pytest.fixture
def small_window(qtbot):
    """The window at 900 x 600, for tests that look at what is drawn, not at its size: software rendering
    under Xvfb costs by the pixel (a 3-torus' picture: 1.4 s at 1200 x 800, 0.9 s here)."""
    w = open_window(qtbot, (900, 600))
    yield w
    w.close()
