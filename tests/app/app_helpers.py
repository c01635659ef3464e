"""Helpers for the window tests (a module name that cannot clash with tests/core)."""

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


def wait_run(qtbot, window, timeout=120_000):
    """Wait for the current run to end; return "done", "cancelled" or "failed"."""
    with qtbot.waitSignal(window.runFinished, timeout=timeout) as blocker:
        pass
    return blocker.args[0]


def run_and_wait(qtbot, window, timeout=120_000):
    with qtbot.waitSignal(window.runFinished, timeout=timeout) as blocker:
        assert window.run(), window.last_status
    return blocker.args[0]


def picture_stats(img):
    """(distinct colours, fraction of pixels that differ from the corner background)."""
    import numpy as np

    rgb = img[..., :3].reshape(-1, 3)
    distinct = len(np.unique(rgb, axis=0))
    return distinct
