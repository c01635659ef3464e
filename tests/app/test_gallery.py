"""QtGallery on its own: thumbnails, details, and choosing an example."""

from pathlib import Path

import pytest
from qtpy.QtCore import Qt
from qtpy.QtWidgets import QDialog

from gcmh_core.examples import example_names, load_example
from gcmh_studio.qt_gallery import QtGallery


@pytest.fixture(autouse=True)
def state(monkeypatch, tmp_path):
    """The user's state folder (remembered data sources) kept out of the tests."""
    monkeypatch.setenv("GCMH_STATE_DIR", str(tmp_path / "state"))
    return tmp_path / "state"


@pytest.fixture
def gallery(qtbot):
    g = QtGallery()
    qtbot.addWidget(g)
    g.show()
    qtbot.waitExposed(g)
    return g


def test_every_example_with_its_picture(gallery):
    assert gallery.names() == example_names()
    for i, name in enumerate(gallery.names()):
        assert gallery.has_thumbnail(name), name
        item = gallery.grid.item(i)
        assert item.text() == load_example(name).title
        assert not item.icon().isNull()


def test_thumbnails_are_real_pictures():
    import io

    import numpy as np
    from PIL import Image

    from gcmh_studio.make_gallery import gallery_files

    folder = gallery_files()      # package data, read as importlib.resources does
    for name in example_names():
        with Image.open(io.BytesIO((folder / f"{name}.png").read_bytes())) as im:
            assert im.size == (320, 240)
            rgb = np.asarray(im.convert("RGB")).reshape(-1, 3)
        # an object in front of the background: many colours, not a blank frame
        assert len(np.unique(rgb, axis=0)) > 200, name


def test_thumbnails_ship_inside_the_app_package():
    import app
    from gcmh_studio.make_gallery import gallery_dir, thumbnail_path

    package = Path(app.__file__).resolve().parent
    assert gallery_dir().resolve() == package / "resources" / "gallery"
    assert thumbnail_path("sphere").resolve().is_file()


def test_details_follow_the_selection(gallery):
    assert gallery.select("hopf-tori")
    assert gallery.current_name() == "hopf-tori"
    text = gallery.details.text()
    assert "Hopf tori" in text and "stereographic" in text and "R<sup>4</sup>" in text
    assert not gallery.select("no-such-example")
    assert gallery.current_name() == "hopf-tori"


def test_open_button_emits_the_name(gallery, qtbot):
    gallery.select("moebius-strip")
    with qtbot.waitSignal(gallery.exampleChosen, timeout=1000) as blocker:
        qtbot.mouseClick(gallery.open_button, Qt.LeftButton)
    assert blocker.args == ["moebius-strip"]
    assert gallery.result() == QDialog.Accepted and not gallery.isVisible()


def test_double_click_emits_once(gallery, qtbot):
    gallery.select("riemann-sqrt")
    item = gallery.grid.currentItem()
    seen = []
    gallery.exampleChosen.connect(seen.append)
    gallery.grid.scrollToItem(item)
    rect = gallery.grid.visualItemRect(item)
    # Qt's item views act on a double-click only after a press on the same item
    qtbot.mouseClick(gallery.grid.viewport(), Qt.LeftButton, pos=rect.center())
    qtbot.mouseDClick(gallery.grid.viewport(), Qt.LeftButton, pos=rect.center())
    qtbot.wait(50)
    assert seen == ["riemann-sqrt"]


def test_missing_thumbnail_gets_a_card(qtbot, tmp_path):
    examples = [load_example("sphere")]
    g = QtGallery(examples=examples, gallery_dir=tmp_path)
    qtbot.addWidget(g)
    assert g.names() == ["sphere"] and not g.has_thumbnail("sphere")
    assert not g.grid.item(0).icon().isNull()
    with qtbot.waitSignal(g.exampleChosen, timeout=1000) as blocker:
        g.grid.itemActivated.emit(g.grid.item(0))
    assert blocker.args == ["sphere"]


def test_remembered_data_sources_follow_the_examples(qtbot, tmp_path):
    import numpy as np

    from gcmh_studio import recent_data

    for name in ("a", "b"):
        np.save(tmp_path / f"{name}.npy", np.zeros((3, 3, 3), np.float32))
    picture = np.zeros((300, 500, 3), np.uint8)
    picture[100:200, 200:300] = (200, 80, 40)   # (an object in the middle: kept by the crop)
    a = {"files": [str(tmp_path / "a.npy")], "levels": [0.5], "bounds": None, "components": None}
    assert recent_data.remember(a, "a.npy", picture)
    assert recent_data.remember({**a, "files": [str(tmp_path / "b.npy")]}, "b.npy")
    assert recent_data.remember({**a, "levels": [0.25]}, "a.npy")   # (again: first, with its newest level)
    recent = recent_data.recent()
    assert [r["title"] for r in recent] == ["a.npy", "b.npy"] and recent[0]["entry"]["levels"] == [0.25]
    assert recent[0]["picture"] is not None and recent[1]["picture"] is None
    (tmp_path / "b.npy").rename(tmp_path / "moved.npy")

    g = QtGallery(examples=[load_example("sphere")])
    qtbot.addWidget(g)
    assert g.names() == ["sphere"] and g.grid.count() == 3   # (the examples' names only)
    assert g.grid.item(1).text() == "a.npy (your data)" and not g.grid.item(1).icon().isNull()
    assert g.select_data(1) and "not there any more (moved or deleted)" in g.details.text()
    assert g.select_data(0) and str(tmp_path / "a.npy") in g.details.text() and "0.25" in g.details.text()
    with qtbot.waitSignal(g.dataChosen, timeout=1000) as blocker:
        qtbot.mouseClick(g.open_button, Qt.LeftButton)
    assert blocker.args[0]["files"] == [str(tmp_path / "a.npy")] and blocker.args[0]["levels"] == [0.25]


def test_a_broken_list_of_remembered_sources_is_no_sources(state):
    from gcmh_studio import recent_data

    state.mkdir()
    for text in ("{not json", '[{"entry": {"files": []}, "title": "x"}]', '[{"entry": {"files": ["/a.npy"]}}]',
                 '{"entry": 1}'):
        recent_data.recent_path().write_text(text)
        assert recent_data.recent() == []
