"""Fixtures for the window tests (pytest-qt; they need a real X server, e.g. Xvfb).

Run:  xvfb-run -a .venv/bin/python -m pytest tests/app -q
  or: .venv/bin/python -m pytest tests/app -q --xvfb-backend xvfb
test_model.py, test_inputs.py and test_imports.py need no display: ``-p no:xvfb`` runs them anywhere.
"""

import os
import tempfile

import pytest

if not os.environ.get("XDG_RUNTIME_DIR"):
    d = os.path.join(tempfile.gettempdir(), f"runtime-{os.getuid()}")
    os.makedirs(d, mode=0o700, exist_ok=True)
    os.environ["XDG_RUNTIME_DIR"] = d


@pytest.fixture
def window(qtbot):
    from app.qt_main_window import QtMainWindow

    w = QtMainWindow(example=None)
    qtbot.addWidget(w)
    w.resize(1200, 800)
    w.show()
    qtbot.waitExposed(w)
    yield w
    w.close()
