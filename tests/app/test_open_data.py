"""Data files in the window: File -> Open data, drops, the level as a live slider (coarse while held, full
at rest), axes named in the file's units, saved results opened again, and sessions' data sources."""

import numpy as np
import pytest
from qtpy.QtCore import QMimeData, QPoint, Qt, QUrl
from qtpy.QtGui import QDropEvent

from gcmh_core import InputError

SEMI = np.array([1.0, 0.7, 0.45])


def ellipsoid(side=41):
    t = np.linspace(-1.2, 1.2, side)
    X = np.meshgrid(t, t, t, indexing="ij")
    return sum((X[a] / SEMI[a]) ** 2 for a in range(3)).astype(np.float32)


@pytest.fixture(autouse=True)
def state(monkeypatch, tmp_path):
    """The user's state folder (the data sources the window remembers) kept out of the tests."""
    monkeypatch.setenv("GCMH_STATE_DIR", str(tmp_path / "state"))


@pytest.fixture
def volume(tmp_path):
    path = tmp_path / "e.npy"
    np.save(path, ellipsoid())
    return str(path)


def open_and_wait(qtbot, window, specs, levels=None):
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000) as blocker:
        assert window.open_data(specs, levels), window.last_status
    return blocker.args[0]


def test_open_data_shows_the_surface_with_a_data_tab(qtbot, window, volume):
    assert open_and_wait(qtbot, window, [volume], levels=1.0) == "full"
    cx = window.result
    assert (cx.n, cx.k) == (3, 1) and cx.euler_characteristic() == 2
    assert cx.meta["data"]["stride"] == 1 and cx.meta["data"]["files"] == [volume]
    assert window.result_names == ["x", "y", "z"]
    assert window.tabs.tabText(window.tabs.currentIndex()) == "Data"
    assert "vertices" in window.last_status


def test_level_slider_is_coarse_while_held_and_full_at_rest(qtbot, window, volume, monkeypatch):
    monkeypatch.setattr("gcmh_studio.data_source.COARSE_SAMPLES", 20**3)   # (41^3 samples: every 2nd while held)
    open_and_wait(qtbot, window, [volume], levels=1.0)
    panel = window.data_panel
    slider = panel.sliders[0]
    r = window.data_source.ranges[0]
    slider.setSliderDown(True)
    with qtbot.waitSignal(panel.shown, timeout=120_000) as blocker:
        slider.setSliderPosition(slider.value() + 40)   # (a drag: sliderMoved)
    assert blocker.args == ["coarse"]
    coarse = window.result
    assert coarse.meta["data"]["stride"] > 1
    level = window.data_source.levels[0]
    assert level > 1.0 and abs(level - (r.lo + (r.hi - r.lo) * slider.value() / 1000)) < 1e-9
    assert panel.boxes[0].value() == pytest.approx(level, abs=10 ** -panel.boxes[0].decimals())
    with qtbot.waitSignal(panel.shown, timeout=120_000) as blocker:
        slider.setSliderDown(False)   # (let go: sliderReleased)
    assert blocker.args == ["full"]
    full = window.result
    assert full.meta["data"]["stride"] == 1 and full.count(0) > coarse.count(0)
    assert full.meta["data"]["components"][0]["level"] == pytest.approx(level)
    # the number box: an exact level
    with qtbot.waitSignal(panel.shown, timeout=120_000):
        panel.set_level(0, 0.5)
    V = window.result.vertices   # (index coordinates of a plain .npy: back to [-1.2, 1.2])
    rad = np.sqrt((((-1.2 + V * 0.06) / SEMI) ** 2).sum(axis=1))
    assert np.abs(rad - np.sqrt(0.5)).max() < 0.02


def drop(window, paths):
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(p)) for p in paths])
    event = QDropEvent(QPoint(10, 10), Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier)
    window.dropEvent(event)
    return event


def test_dropping_two_files_opens_two_components(qtbot, window, tmp_path, volume):
    z = np.broadcast_to(np.linspace(-1.2, 1.2, 41)[None, None, :], (41, 41, 41)).astype(np.float32)
    np.save(tmp_path / "z.npy", z)
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(volume), QUrl.fromLocalFile(str(tmp_path / "z.npy"))])
    assert window.dropped_files(mime) == [volume, str(tmp_path / "z.npy")]
    mime.setUrls([QUrl.fromLocalFile(str(tmp_path / "notes.txt"))])
    assert window.dropped_files(mime) == []   # (not offered: the drag is refused)
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        event = drop(window, [volume, tmp_path / "z.npy"])
    assert event.isAccepted()
    cx = window.result
    assert (cx.n, cx.k) == (3, 2) and len(window.data_panel.sliders) == 2


def test_axes_carry_the_files_units(qtbot, window, tmp_path):
    nib = pytest.importorskip("nibabel")
    img = nib.Nifti1Image(ellipsoid(), np.diag([0.06, 0.06, 0.06, 1.0]))
    img.header.set_xyzt_units("mm")
    nib.save(img, tmp_path / "e.nii")
    open_and_wait(qtbot, window, [str(tmp_path / "e.nii")], levels=1.0)
    assert window.result_names == ["x [mm]", "y [mm]", "z [mm]"]
    assert window.result.meta["units"] == ["mm"] * 3


def test_a_bad_file_says_so_and_keeps_the_window(qtbot, window, tmp_path):
    (tmp_path / "junk.npy").write_bytes(b"garbage")
    assert not window.open_data([str(tmp_path / "junk.npy")])
    assert "not a valid .npy" in window.last_status and window.result is None


def test_open_a_saved_result_and_export_it(qtbot, window, tmp_path, volume):
    open_and_wait(qtbot, window, [volume], levels=1.0)
    window.export_complex(tmp_path / "saved.npz")
    original = window.result
    with qtbot.waitSignal(window.resultChanged, timeout=60_000):
        assert window.open_file(str(tmp_path / "saved.npz"))
    cx = window.result
    assert cx is not original and cx.vertices.tobytes() == original.vertices.tobytes()
    assert window.result_names == ["x", "y", "z"]
    window.export_mesh(tmp_path / "again.ply")   # (the view's mesh of the reopened complex)
    assert (tmp_path / "again.ply").stat().st_size > 1000
    window.model.set_slice(on=True, index=2, c=0.5, w=0.1)   # (slicing works on it too)
    assert window.result is cx and window.model.slice_readout


def test_session_entry_and_a_moved_file(tmp_path, volume):
    from gcmh_studio.data_source import DataSource

    src = DataSource([volume], levels=1.0)
    entry = src.session_entry()
    again = DataSource.from_session(entry)
    assert again.specs == [volume] and again.levels == [1.0]
    (tmp_path / "e.npy").rename(tmp_path / "moved.npy")
    with pytest.raises(InputError, match="is not there any more .moved or deleted.: open it again"):
        DataSource.from_session(entry)
    with pytest.raises(InputError, match="data entry is not usable: data.components: must be true, false or null"):
        DataSource.from_session({**entry, "components": "yes"})


def test_a_real_int16_scan_opens_at_its_middle_level(qtbot, window):
    nib_testing = pytest.importorskip("nibabel.testing")
    import os

    path = os.path.join(nib_testing.data_path, "anatomical.nii")
    assert open_and_wait(qtbot, window, [path]) == "full"   # (no level: the middle of the data's range)
    r = window.data_source.ranges[0]
    assert (r.lo, r.hi) == (-610.0, 30393.0)
    assert window.data_source.levels == [pytest.approx((r.lo + r.hi) / 2)]
    assert window.result_names == ["x [mm]", "y [mm]", "z [mm]"] and window.result.count(0) > 0


def test_a_session_remembers_the_data_and_says_when_a_file_moved(qtbot, window, tmp_path, volume):
    open_and_wait(qtbot, window, [volume], levels=0.8)
    window.save_session(tmp_path / "s.json")
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        assert window.open_file(str(tmp_path / "s.json"))
    assert window.data_source.specs == [volume] and window.data_source.levels == [0.8]
    (tmp_path / "e.npy").rename(tmp_path / "elsewhere.npy")
    assert not window.open_file(str(tmp_path / "s.json"))
    assert "is not there any more (moved or deleted)" in window.last_status
    box = window.files.problem_box   # (said in the window too, in a box that does not block it)
    assert box.isVisible() and str(tmp_path / "e.npy") in box.text() and "moved or deleted" in box.text()
    # the command line: one line, exit 2, no picture
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-m", "gcmh_studio", "--session", str(tmp_path / "s.json"),
                           "--screenshot", str(tmp_path / "s.png")], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and not (tmp_path / "s.png").exists()
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("gcmh-app: error: cannot open ") and "moved or deleted" in lines[0]


def test_a_file_changed_since_the_session_opens_and_says_so(qtbot, window, tmp_path, volume):
    open_and_wait(qtbot, window, [volume], levels=0.8)
    window.save_session(tmp_path / "s.json")
    np.save(volume, ellipsoid(33))   # (the simulation run again: another grid)
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        assert window.open_file(str(tmp_path / "s.json"))
    assert window.data_source.shape == (33, 33, 33) and window.data_source.levels == [0.8]
    box = window.files.problem_box
    assert box.isVisible() and "has changed since it was saved" in box.text() and volume in box.text()


def test_the_gallery_remembers_the_data_opened(qtbot, window, tmp_path, volume):
    from gcmh_studio import recent_data

    open_and_wait(qtbot, window, [volume], levels=0.8)
    first = recent_data.recent()[0]
    assert first["entry"]["files"] == [volume] and first["entry"]["levels"] == [0.8]
    assert first["title"] == "e.npy" and first["picture"] is not None   # (the isosurface as shown)
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        window.data_panel.set_level(0, 0.6)
    assert [r["entry"]["levels"] for r in recent_data.recent()] == [[0.6]]   # (one entry: its latest level)
    window.load_example("sphere", run=False)
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        assert window.files.open_entry(first["entry"])   # (what the gallery's dataChosen opens)
    assert window.data_source.levels == [0.8] and window.showing_data()


def test_the_autosave_keeps_the_data_source_and_restores_it(qtbot, window, tmp_path, volume, monkeypatch):
    from gcmh_studio import autosave, studio_io

    monkeypatch.setenv("GCMH_STATE_DIR", str(tmp_path / "state"))
    open_and_wait(qtbot, window, [volume], levels=0.8)
    saved = autosave.save(window.session())   # (what keep_autosaving writes after each run)
    assert studio_io.read_session(saved)["data"]["files"] == [volume]
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        window.data_panel.set_level(0, 0.6)   # (changed after the autosave)
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        assert window.open_file(saved)        # (what the restore offer opens)
    assert window.data_source.specs == [volume] and window.data_source.levels == [0.8] and window.showing_data()
    autosave.discard()


def test_the_gallery_opens_a_data_source_it_remembers(qtbot, window, volume):
    from gcmh_studio import recent_data

    open_and_wait(qtbot, window, [volume], levels=0.8)
    window.load_example("sphere", run=False)
    gallery = window.open_gallery()
    with qtbot.waitSignal(window.data_panel.shown, timeout=120_000):
        gallery.dataChosen.emit(recent_data.recent()[0]["entry"])
    assert window.data_source.specs == [volume] and window.showing_data()


def test_a_4d_series_is_a_3_manifold_sliced_in_time(qtbot, window, tmp_path):
    nib = pytest.importorskip("nibabel")
    # a sphere growing over 4 frames of 2 s: its isosurfaces in space-time are a 3-manifold in R^4
    t = np.linspace(-1.2, 1.2, 17)
    X = np.meshgrid(t, t, t, indexing="ij")
    r2 = sum(x**2 for x in X)
    series = np.stack([r2 / (0.5 + 0.15 * f) ** 2 for f in range(4)], axis=-1).astype(np.float32)
    img = nib.Nifti1Image(series, np.diag([0.15, 0.15, 0.15, 1.0]))
    img.header.set_xyzt_units("mm", "sec")
    img.header["pixdim"][4] = 2.0
    nib.save(img, tmp_path / "series.nii.gz")
    open_and_wait(qtbot, window, [str(tmp_path / "series.nii.gz")], levels=1.0)
    cx = window.result
    assert (cx.n, cx.k, cx.dim) == (4, 1, 3)
    assert window.result_names == ["x [mm]", "y [mm]", "z [mm]", "t [sec]"]
    assert window.data_source.plan.bounds[3].tolist() == [0.0, 6.0]
    window.model.set_slice(on=True, index=3, c=0.5, w=0.05)   # (a section in time: a surface)
    assert window.model.slice_readout.startswith("t [sec] in [2.7, 3.3] of [0, 6]")


@pytest.mark.parametrize("data, words", [
    ({"files": []}, "data.files: must have 1 to"), ({"files": [3]}, "data.files[0]: must be a text"),
    ({"files": ["a.npy"], "levels": [float("nan")]}, "data.levels[0]: must be a finite number"),
    ({"files": ["a.npy"], "bounds": [[0, "x"]] * 3}, "data.bounds[0][1]: must be a number"),
    ({"files": ["a.npy"], "components": "yes"}, "data.components: must be true, false or null"),
    ({"files": ["a.npy"], "seen": [[1, 2], None]}, "data.seen: must have 0 to 1 entries"),
])
def test_a_sessions_data_entry_is_checked_whole(data, words):
    from gcmh_studio.session_schema import SessionError, validate_session

    session = {"format": "gcmh-session/1", "system": {"formulas": [""], "n": 3}, "data": data}
    with pytest.raises(SessionError, match=words.replace("[", r"\[").replace("]", r"\]")):
        validate_session(session)
    # (a data session's Manifold tab may be blank; a formula session's may not)
    ok = {"format": "gcmh-session/1", "system": {"formulas": [""], "n": 3}}
    assert validate_session({**ok, "data": {"files": ["a.npy"], "levels": [1.0], "seen": [[5, 7]]}})
    with pytest.raises(SessionError, match="are all empty"):
        validate_session(ok)
