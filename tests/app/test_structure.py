"""The app's structure as issue 24 left it (it drifted back once, unseen): no class in app/ over 400 lines,
and the main window only lays out and wires (at most 300)."""

import ast
from pathlib import Path

APP = Path(__file__).resolve().parents[2] / "app"


def _classes():
    for path in sorted(APP.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef):
                yield path.name, node.name, node.end_lineno - node.lineno + 1


def test_no_class_in_the_app_is_over_400_lines():
    sizes = list(_classes())
    assert len(sizes) > 50
    assert [(f, c, n) for f, c, n in sizes if n > 400] == []


def test_the_main_window_only_lays_out_and_wires():
    (n,) = [n for f, c, n in _classes() if c == "QtMainWindow"]
    assert n <= 300, n


def test_signals_are_blocked_with_a_blocker_not_in_pairs():
    # (a blockSignals(True) whose (False) an exception skips leaves the widget deaf for the rest of the session)
    paired = [f"{p.name}:{i}" for p in sorted(APP.glob("*.py"))
              for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if ".blockSignals(" in line]
    assert paired == []
