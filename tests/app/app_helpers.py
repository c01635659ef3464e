"""Helpers for the app tests (a module name that cannot clash with tests/core); no Qt imported at module level.

``torus_complex`` is also the test surface of ``tests/bench/bench_view.py``.
"""

import numpy as np

# a small, fast div for every example (the window tests check pictures and counts, not resolution)
SMALL_CUBES = 60_000


def small_div(ex):
    divs = ex.div_list() if hasattr(ex, "div_list") else ([ex.div] * ex.n if isinstance(ex.div, int) else list(ex.div))
    cubes = 1
    for d in divs:
        cubes *= d
    if cubes <= SMALL_CUBES:
        return divs
    f = (SMALL_CUBES / cubes) ** (1.0 / ex.n)
    return [max(4, int(d * f)) for d in divs]


def settle(qtbot, panel, timeout=20_000):
    """Wait until the formula panel's checks (done in a worker thread) have answered."""
    qtbot.waitUntil(lambda: not panel.checking(), timeout=timeout)


def wait_run(qtbot, window, timeout=120_000):
    """Wait for the current run to end; return "done", "cancelled" or "failed"."""
    with qtbot.waitSignal(window.runFinished, timeout=timeout) as blocker:
        pass
    return blocker.args[0]


def run_and_wait(qtbot, window, timeout=120_000):
    with qtbot.waitSignal(window.runFinished, timeout=timeout) as blocker:
        assert window.run(), window.last_status
    return blocker.args[0]


def app_in_process(capsys, monkeypatch, *args):
    """``gcmh-app ARGS`` in this process (the command line's own code, without a new interpreter that loads
    VTK and numba's kernels again): (exit status, stdout, stderr).  For refusals, which come before any
    work; other tests run the real ``python -m gcmh_studio``."""
    import gcmh_studio.qt_main_window
    from gcmh_studio.__main__ import _main

    def no_window(*a, **kw):
        raise AssertionError("gcmh-app would open its window here, not refuse")

    monkeypatch.setattr(gcmh_studio.qt_main_window, "QtMainWindow", no_window)
    capsys.readouterr()
    code = _main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def picture_stats(img):
    """The number of distinct colours in an image (a blank frame has few)."""
    rgb = img[..., :3].reshape(-1, 3)
    distinct = len(np.unique(rgb, axis=0))
    return distinct


def torus_complex(side: int, n: int, seed: int = 0):
    """A torus with side*side vertices and quads: a ring torus for n = 3, else a flat torus turned into R^n."""
    from gcmh_core.complex import CellComplex

    u = np.linspace(0, 2 * np.pi, side, endpoint=False)
    U, W = np.meshgrid(u, u, indexing="ij")
    if n == 3:  # a ring torus in R^3
        X = np.stack([(2 + np.cos(W)) * np.cos(U), (2 + np.cos(W)) * np.sin(U), np.sin(W)], -1).reshape(-1, 3)
    else:
        X4 = np.stack([np.cos(U), np.sin(U), np.cos(W), np.sin(W)], axis=-1).reshape(-1, 4)
        Q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((n, n)))
        X = X4 @ Q[:4]
    idx = np.arange(side * side).reshape(side, side)
    right = np.roll(idx, -1, axis=0)
    up = np.roll(idx, -1, axis=1)
    e_h = np.stack([idx.ravel(), right.ravel()], 1)       # edge id i
    e_v = np.stack([idx.ravel(), up.ravel()], 1)          # edge id V + i
    edges = np.concatenate([e_h, e_v])
    Vn = side * side
    i = idx.ravel()
    # quad (a, a+u, a+u+w, a+w): edges h(a), v(a+u), h(a+w), v(a)
    faces = np.stack([i, Vn + right.ravel(), up.ravel(), Vn + i], 1).ravel()
    offsets = np.arange(0, 4 * Vn + 1, 4, dtype=np.int64)
    return CellComplex(n, n - 2, X, edges.astype(np.int64), {2: (offsets, faces.astype(np.int64))},
                       meta={"variables": [f"x{j + 1}" for j in range(n)]})


def open_window(qtbot, size=(900, 700)):
    """A new main window with no example, shown at ``size`` and exposed (closed by the caller)."""
    from gcmh_studio.qt_main_window import QtMainWindow

    w = QtMainWindow(example=None)
    qtbot.addWidget(w)
    w.resize(*size)
    w.show()
    qtbot.waitExposed(w)
    return w
