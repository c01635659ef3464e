"""Session files a user may hand the app (issue 26, item 2): each one the app cannot use is refused whole, before
anything is built, with one message naming the field; every session the app writes opens.

The file level needs no display; the command line's refusals come before Qt (no display either); the window's
test runs under Xvfb (``--xvfb-backend xvfb``).
"""

import copy
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from gcmh_studio import studio_io
from gcmh_studio.session_schema import MAX_SESSION_BYTES, SessionError, validate_session

BASE = {"format": "gcmh-session/1", "title": "Sphere",
        "system": {"n": 3, "k": 1, "variables": ["x", "y", "z"], "formulas": ["x^2 + y^2 + z^2 - 1"],
                   "bounds": [[-2.0, 2.0]] * 3, "div": 12, "method": "gcmh", "seed": 0, "start": None,
                   "params": {}, "periodic": []},
        "view": {"kind": "coordinates", "axes": [0, 1, 2], "seed": 0, "angles": [0.0, 0.0, 0.0],
                 "mapping": "orthographic", "distance": 3.0, "color": "z", "opacity": 1.0, "show_edges": False,
                 "two_sided": False, "boundary": False, "grid": False},
        "camera": {"position": [1, 2, 3], "focal_point": [0, 0, 0], "up": [0, 0, 1]}, "keep_camera": False}


def _with(path: str, value):
    """BASE with ``value`` at ``path`` ("system.n"; value DELETE drops the key)."""
    d = copy.deepcopy(BASE)
    *head, last = path.split(".")
    at = d
    for key in head:
        at = at[key]
    if value is DELETE:
        del at[last]
    else:
        at[last] = value
    return d


DELETE = object()

# (path, value, what the message names): the cases first, then variants
BAD = [
    ("system.n", 1_000_000_000, "system.n"), ("system.n", -1, "system.n"), ("system.n", 0, "system.n"),
    ("system.formulas", [], "system.formulas"), ("system.formulas", DELETE, "no formulas"),
    ("system.formulas", ["", " "], "system.formulas"),
    ("system.params", {"a": {"value": math.nan}}, "system.params.a.value"),
    ("system.params", {"a": math.inf}, "system.params.a"),
    ("view.angles", [math.nan, 0.0, 0.0], "view.angles[0]"),
    ("view.slice", [1, 2], "view.slice"), ("view.slice", "z", "view.slice"),
    ("view.opacity", "inf", "view.opacity"), ("view.opacity", 7, "view.opacity"),
    ("title", "x" * 100_000, "title"), ("title", 3, "title"),
    ("system.k", 2, "k = 2"), ("system.k", 99, "system.k"), ("system.n", True, "system.n"),
    ("system.n", "3; rm", "system.n"), ("system.n", 2.5, "system.n"),
    ("system.formulas", ["x" * 6000], "system.formulas[0]"), ("system.formulas", "x^2", "system.formulas"),
    ("system.formulas", [1], "system.formulas[0]"), ("system.formulas", ["x"] * 100, "system.formulas"),
    ("system.variables", ["x", "y"], "system.variables"), ("system.variables", ["x", "x", "z"], "twice"),
    ("system.variables", ["x", "y", "1z"], "system.variables[2]"),
    ("system.bounds", [[2, -2]] * 3, "system.bounds[0]"), ("system.bounds", [[0, "nan"]] * 3, "system.bounds[0][1]"),
    ("system.bounds", [[0, "1e999"]] * 3, "system.bounds[0][1]"), ("system.bounds", [[0]] * 3, "system.bounds[0]"),
    ("system.bounds", "wide", "system.bounds"), ("system.bounds", [[-1, 1]] * 100_000, "system.bounds"),
    ("system.div", 0, "system.div"), ("system.div", 10**30, "system.div"), ("system.div", [10, 10], "system.div"),
    ("system.div", -5, "system.div"), ("system.method", "rm -rf", "system.method"), ("system.seed", -1, "system.seed"),
    ("system.start", [0.0, math.nan, 0.0], "system.start[1]"), ("system.start", [0.0], "system.start"),
    ("system.params", {"a": {"value": 0, "min": 1, "max": -1}}, "min is not below max"),
    ("system.params", {f"p{i}": 1.0 for i in range(1000)}, "system.params"),
    ("system.params", {"1a": 1.0}, "system.params"), ("system.params", [1, 2], "system.params"),
    ("system.periodic", ["x" * 1000], "system.periodic[0]"), ("system", [], "system"), ("system", DELETE, "no system"),
    ("system.complex", ["z = w"], "system.complex_variables"),
    ("system.complex", ["z = w"] * 20, "system.complex"),
    ("view", "front", "view"), ("view.kind", "fisheye", "view.kind"), ("view.mapping", 4, "view.mapping"),
    ("view.distance", math.nan, "view.distance"), ("view.distance", 0.5, "view.distance"),
    ("view.axes", [0, 1, 99], "view.axes[2]"), ("view.angles", [0.0] * 10_000, "view.angles"),
    ("view.angles", [0.0, "1", 0.0], "view.angles[1]"), ("view.show_edges", "yes", "view.show_edges"),
    ("view.slice", {"along": "z", "w": -1.0}, "view.slice.w"), ("view.slice", {"c": math.inf}, "view.slice.c"),
    ("format", "gcmh-session/2", "format"),
]


@pytest.mark.parametrize("path,value,named", BAD, ids=[f"{p}={str(v)[:20]}" for p, v, _ in BAD])
def test_a_bad_session_is_refused_whole_with_one_line_naming_the_field(tmp_path, path, value, named):
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(_with(path, value)))   # (json writes NaN and Infinity, and reads them back)
    with pytest.raises(ValueError) as err:
        studio_io.read_session(p)
    msg = str(err.value)
    assert named in msg and "\n" not in msg and len(msg) < 300, msg


@pytest.mark.parametrize("text,named", [
    ("[" * 100_000 + "]" * 100_000, "nested too deeply"), ("{\"format\": 1e999999}", "format"),
    ("{\"n\": " + "9" * 5000 + "}", "digits"), ("\udcff", "not a text"), ("", "Expecting value"),
])
def test_a_file_that_is_no_session_at_all_is_refused(tmp_path, text, named):
    p = tmp_path / "bad.json"
    p.write_bytes(text.encode("utf-8", "surrogateescape"))
    with pytest.raises(ValueError, match=named):
        studio_io.read_session(p)


def test_a_huge_file_is_refused_by_its_size_without_being_read(tmp_path):
    p = tmp_path / "huge.json"
    with open(p, "wb") as f:   # (sparse: 100 MB on the disk's books, nothing written)
        f.truncate(100 << 20)
    with pytest.raises(SessionError, match="larger than"):
        studio_io.read_session(p)
    assert MAX_SESSION_BYTES < os.path.getsize(p)


def test_every_session_the_app_writes_opens(tmp_path):
    """The examples' systems as the window saves them (complex ones too), with slices, hidden axes and texts."""
    from gcmh_core.examples import list_examples
    from gcmh_studio.controller import example_state
    from gcmh_studio.model import StudioModel

    for ex in list_examples():
        m = StudioModel()
        m.set_system(example_state(ex))
        m.set_view_variables(ex.variables, keep=False)
        m.set_slice(on=True)
        d = studio_io.session_dict(m, dict(BASE["camera"]))
        back = studio_io.read_session(studio_io.write_session(tmp_path / f"{ex.name}.json", d))
        assert back["system"] == json.loads(json.dumps(d["system"])), ex.name
    hand = _with("system.bounds", [["-pi", "pi"], [-2, 2], ["-2*3^2", 1]])   # constants as text
    hand["system"]["params"] = "a = 0.5, b = pi/4"                          # (sessions before the sliders)
    hand["system"]["formulas"] = ["x^2 + y^2 + z^2 - 1"]
    assert validate_session(hand) is hand


def test_writing_a_session_leaves_the_old_file_when_it_fails(tmp_path, monkeypatch):
    p = studio_io.write_session(tmp_path / "s.json", BASE)
    before = p.read_bytes()
    real_open = open

    def full(file, mode="r", *a, **k):   # a full disk: the write fails after the temporary was made
        f = real_open(file, mode, *a, **k)
        if "w" in mode and ".tmp" in str(file):
            def write(_):
                raise OSError(28, "No space left on device")
            f.write = write
        return f

    import builtins

    monkeypatch.setattr(builtins, "open", full)
    with pytest.raises(OSError, match="No space"):
        studio_io.write_session(p, dict(BASE, title="new"))
    monkeypatch.undo()
    assert p.read_bytes() == before and sorted(os.listdir(tmp_path)) == ["s.json"]


def _app(*args, timeout=60):
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")   # (no window is made: refused before Qt)
    return subprocess.run([sys.executable, "-m", "gcmh_studio", *args], capture_output=True, text=True,
                          timeout=timeout, env=env)


@pytest.mark.parametrize("path,value", [("system.n", -1), ("system.formulas", []), ("view.opacity", "inf"),
                                        ("system.n", 10**9)])
def test_the_command_line_refuses_a_bad_session_in_one_line(tmp_path, path, value):
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(_with(path, value)))
    out = tmp_path / "x.png"
    r = _app("--session", str(p), "--screenshot", str(out))
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("gcmh-app: error: cannot open") and path in lines[0], r.stderr
    assert not out.exists() and sorted(os.listdir(tmp_path)) == ["bad.json"]


def test_the_window_says_why_a_session_cannot_open_and_keeps_its_system(qtbot, small_window, tmp_path):
    w = small_window
    with qtbot.waitSignal(w.runFinished, timeout=60_000):
        w.load_example("sphere", div=8)
    before = copy.deepcopy(w.model.system)
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(_with("system.n", 10**9)))
    assert not w.controller.open_session(p)
    assert "system.n" in w.last_status and w.model.system == before
    assert w.isVisible()


# ---------------------------------------------------------------- pictures that are never black (item 5)
def _scene(size=(160, 120)):
    from gcmh_core import extract
    from gcmh_studio.headless import offscreen_scene
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Style

    cx = extract(["x^2 + y^2 + z^2 - 1"], variables="x,y,z", bounds=[-1.5, 1.5], div=6)
    m = ProjectionModel(n=3)
    m.set_vertices(cx.vertices)
    ctx = offscreen_scene(size, anti_aliasing="ssaa")
    sc = ctx.__enter__()
    sc.set_complex(cx, ["x", "y", "z"], m.view(), Style(title="t"))
    return ctx, sc


def test_a_picture_the_renderer_cannot_make_super_sampled_is_drawn_again_with_fxaa(monkeypatch):
    from gcmh_studio import offscreen

    ctx, sc = _scene()
    try:
        real, tries = offscreen._attempt, []

        def attempt(pl, transparent):   # the super-sampled frame buffer cannot be made (as at 8192 x 4096)
            img, failed = real(pl, transparent)
            tries.append(sc.anti_aliasing)
            return (np.zeros_like(img), True) if sc.anti_aliasing == "ssaa" else (img, failed)

        monkeypatch.setattr(offscreen, "_attempt", attempt)
        img = offscreen.checked_screenshot(sc)
        assert tries == ["ssaa", "fxaa"] and img.any() and not offscreen._blank(sc.plotter, img, False)
    finally:
        ctx.__exit__(None, None, None)


def test_a_picture_that_cannot_be_drawn_at_all_is_refused_not_written_black(monkeypatch, tmp_path):
    from gcmh_studio import offscreen

    ctx, sc = _scene()
    try:
        monkeypatch.setattr(offscreen, "_attempt", lambda pl, t: (np.zeros((120, 160, 3), np.uint8), True))
        with pytest.raises(offscreen.RenderError, match="could not draw a"):
            offscreen.render_image(sc, tmp_path / "x.png", size=(160, 120))
        assert list(tmp_path.iterdir()) == []
        black = np.zeros((120, 160, 3), np.uint8)
        assert offscreen._blank(sc.plotter, black, False) and offscreen._blank(sc.plotter, black, True)
    finally:
        ctx.__exit__(None, None, None)


# ---------------------------------------------------------------- autosave (item 8: a crash loses little)
def _dead_pid() -> int:
    p = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(p.stdout)


def test_the_autosave_is_atomic_and_a_crashed_one_is_found(tmp_path, monkeypatch):
    from gcmh_studio import autosave

    monkeypatch.setenv("GCMH_STATE_DIR", str(tmp_path / "state"))
    assert autosave.recoverable() is None                     # (no folder yet)
    assert autosave.save(BASE) == autosave.own_path()
    assert autosave.recoverable() is None                     # this process's own: alive, not offered
    assert autosave.save(_with("system.n", -1)) is None       # not a session that would open: not written
    assert studio_io.read_session(autosave.own_path())["title"] == "Sphere"
    crashed = autosave.own_path(_dead_pid())
    crashed.write_text(json.dumps(_with("title", "crashed")))
    broken = autosave.own_path(_dead_pid())
    broken.write_text("{")
    os.utime(broken, (1e10, 1e10))                            # the newest, but it does not open
    assert autosave.recoverable() == crashed and not broken.exists()
    autosave.restored(crashed)
    assert autosave.recoverable() is None
    autosave.discard()
    assert list((tmp_path / "state").iterdir()) == []


def test_the_window_offers_the_crashed_session_back(qtbot, small_window, tmp_path, monkeypatch):
    from qtpy.QtWidgets import QApplication, QMessageBox

    from gcmh_studio import autosave
    from gcmh_studio.__main__ import keep_autosaving

    monkeypatch.setenv("GCMH_STATE_DIR", str(tmp_path))
    saved = _with("system.div", 6)
    saved["title"] = "Sphere"
    autosave.own_path(_dead_pid()).write_text(json.dumps(saved))
    w = small_window
    keep_autosaving(QApplication.instance(), w, offer=True)
    box = w.autosave_offer
    qtbot.waitUntil(box.isVisible, timeout=10_000)
    with qtbot.waitSignal(w.runFinished, timeout=120_000) as b:
        box.button(QMessageBox.Yes).click()
    assert b.args[0] == "done" and w.model.system["formulas"] == saved["system"]["formulas"]
    assert autosave.recoverable() is None                     # answered: not offered again
    with qtbot.waitSignal(w.runFinished, timeout=120_000):
        w.run()
    assert autosave.own_path().exists()                        # saved after the run


# ---------------------------------------------------------------- a full disk (item 4): the PNG and GIF writers
@pytest.mark.parametrize("args,name", [(["--screenshot"], "x.png"), (["--animate", "rotate:x-y", "--frames", "3",
                                                                     "--gif"], "x.gif")])
def test_a_picture_on_a_full_disk_is_one_line_and_leaves_nothing(full_disk, fill_disk, args, name):
    fill_disk(full_disk)
    env = dict(os.environ)
    env.pop("QT_QPA_PLATFORM", None)
    r = subprocess.run([sys.executable, "-m", "gcmh_studio", "--example", "sphere", "--div", "6", "--size",
                        "320x240", *args, str(full_disk / name)], capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 1, r.stderr
    assert r.stderr.strip().splitlines()[-1] == f"gcmh-app: error: cannot write {str(full_disk / name)!r}: " \
                                                "No space left on device", r.stderr
    assert "Traceback" not in r.stderr and sorted(os.listdir(full_disk)) == ["ballast"]
