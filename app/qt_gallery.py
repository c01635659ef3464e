"""QtGallery: pick an example by its picture.

A dialog with one thumbnail per example (``app/resources/gallery/<name>.png``,
package data read with importlib.resources, drawn by ``python -m gcmh_studio.make_gallery``),
its title under it, and the selected example's description beside the grid.  Double-clicking a thumbnail, pressing
Enter or "Open" emits ``exampleChosen(name)`` and accepts the dialog.

After the examples, the data files the window opened lately (:mod:`gcmh_studio.recent_data`: their
isosurface's picture, files and levels); choosing one emits ``dataChosen(entry)``, the source's entry as
a session keeps it (a file that has moved since is marked in the details, and the window says so when
it is opened).

    gallery = QtGallery(parent)
    gallery.exampleChosen.connect(window.load_example)
    gallery.dataChosen.connect(window.files.open_entry)
    gallery.exec_()
"""

from __future__ import annotations

import html
from pathlib import Path

from qtpy.QtCore import QSize, Qt, Signal
from qtpy.QtGui import QColor, QIcon, QPainter, QPixmap
from qtpy.QtWidgets import (
    QAbstractItemView,
    QDialog,
    QDialogButtonBox,
    QHBoxLayout,
    QLabel,
    QListView,
    QListWidget,
    QListWidgetItem,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

THUMB = QSize(320, 240)
ICON = QSize(224, 168)
NAME_ROLE = Qt.UserRole
DATA_ROLE = Qt.UserRole + 1   # (a remembered data source: its index in QtGallery.recent)


def _missing_picture(text: str) -> QPixmap:
    """A grey card for an example whose thumbnail has not been drawn yet."""
    pm = QPixmap(THUMB)
    pm.fill(QColor("#5a5f6b"))
    p = QPainter(pm)
    p.setPen(QColor("#e8e8e8"))
    p.drawText(pm.rect(), Qt.AlignCenter | Qt.TextWordWrap, text)
    p.end()
    return pm


class QtGallery(QDialog):
    """The example gallery.

    Parameters
    ----------
    parent : QWidget, optional
    examples : list of gcmh_core.examples.Example, optional
        Default: every example (:func:`gcmh_core.examples.list_examples`).
    gallery_dir : path, optional
        Folder of the thumbnails; default the package's ``app/resources/gallery``.

    Signals
    -------
    exampleChosen(str)
        The name of the example the user opened.
    dataChosen(dict)
        The entry of the remembered data source the user opened (``recent_data.recent()[i]["entry"]``).
    """

    exampleChosen = Signal(str)
    dataChosen = Signal(dict)

    def __init__(self, parent=None, examples=None, gallery_dir=None, recent=None):
        super().__init__(parent)
        from gcmh_core.examples import list_examples

        from . import recent_data
        from .make_gallery import gallery_files

        self.recent = recent_data.recent() if recent is None else list(recent)

        self.setWindowTitle("Example gallery")
        self.resize(1100, 720)
        self._examples = {ex.name: ex for ex in (list_examples() if examples is None else examples)}
        self._dir = Path(gallery_dir) if gallery_dir is not None else gallery_files()
        self._chosen = False

        self.grid = QListWidget()
        self.grid.setViewMode(QListView.IconMode)
        self.grid.setIconSize(ICON)
        self.grid.setGridSize(QSize(ICON.width() + 24, ICON.height() + 48))
        self.grid.setResizeMode(QListView.Adjust)
        self.grid.setMovement(QListView.Static)
        self.grid.setWordWrap(True)
        self.grid.setUniformItemSizes(True)
        self.grid.setSelectionMode(QAbstractItemView.SingleSelection)
        for name, ex in self._examples.items():
            item = QListWidgetItem(QIcon(self._picture(name)), ex.title)
            item.setData(NAME_ROLE, name)
            item.setToolTip(f"{ex.title}\n{name}: n = {ex.n}, k = {ex.k}")
            self.grid.addItem(item)
        for i, r in enumerate(self.recent):
            item = QListWidgetItem(QIcon(self._data_picture(r)), f"{r['title']} (your data)")
            item.setData(DATA_ROLE, i)
            item.setToolTip("\n".join(r["entry"]["files"]))
            self.grid.addItem(item)

        self.details = QLabel()
        self.details.setWordWrap(True)
        self.details.setAlignment(Qt.AlignTop | Qt.AlignLeft)
        self.details.setTextFormat(Qt.RichText)
        self.details.setMinimumWidth(260)
        self.details.setObjectName("gallery_details")
        side = QWidget()
        sl = QVBoxLayout(side)
        sl.setContentsMargins(8, 0, 0, 0)
        sl.addWidget(self.details)
        sl.addStretch(1)

        split = QSplitter()
        split.addWidget(self.grid)
        split.addWidget(side)
        split.setStretchFactor(0, 3)
        split.setStretchFactor(1, 1)

        self.buttons = QDialogButtonBox(QDialogButtonBox.Open | QDialogButtonBox.Close)
        self.open_button = self.buttons.button(QDialogButtonBox.Open)
        self.buttons.accepted.connect(self._open_current)
        self.buttons.rejected.connect(self.reject)

        layout = QVBoxLayout(self)
        layout.addWidget(split, 1)
        bottom = QHBoxLayout()
        hint = QLabel("Double-click a picture to open it.")
        hint.setStyleSheet("color: #777;")
        bottom.addWidget(hint)
        bottom.addStretch(1)
        bottom.addWidget(self.buttons)
        layout.addLayout(bottom)

        self.grid.currentItemChanged.connect(self._show_details)
        self.grid.itemActivated.connect(self._choose)
        self.grid.itemDoubleClicked.connect(self._choose)
        if self.grid.count():
            self.grid.setCurrentRow(0)
        else:
            self.details.setText("No examples found.")
        self._show_details(self.grid.currentItem())

    # ---------------------------------------------------------------- public

    def names(self) -> list[str]:
        """Example names in the order shown."""
        items = (self.grid.item(i) for i in range(self.grid.count()))
        return [item.data(NAME_ROLE) for item in items if item.data(NAME_ROLE) is not None]

    def select_data(self, index: int) -> bool:
        """Make the remembered data source ``recent[index]`` current; False if there is none."""
        return self._select(DATA_ROLE, index)

    def _select(self, role, value) -> bool:
        for i in range(self.grid.count()):
            if self.grid.item(i).data(role) == value:
                self.grid.setCurrentRow(i)
                return True
        return False

    def current_name(self) -> str | None:
        item = self.grid.currentItem()
        return None if item is None else item.data(NAME_ROLE)

    def select(self, name: str) -> bool:
        """Make `name` the current example; False if there is no such example."""
        return self._select(NAME_ROLE, name)

    def has_thumbnail(self, name: str) -> bool:
        return (self._dir / f"{name}.png").is_file()

    # --------------------------------------------------------------- private

    def _picture(self, name: str) -> QPixmap:
        path = self._dir / f"{name}.png"
        pm = QPixmap()
        if path.is_file():   # (bytes, not a file name: package data need not be a file on disk)
            pm.loadFromData(path.read_bytes())
        if pm.isNull():
            return _missing_picture(f"{name}\n(no picture yet: python -m gcmh_studio.make_gallery)")
        return pm

    def _data_picture(self, r: dict) -> QPixmap:
        pm = QPixmap()
        if r["picture"] is not None:
            pm.loadFromData(Path(r["picture"]).read_bytes())
        return _missing_picture(r["title"]) if pm.isNull() else pm

    def _show_data_details(self, r: dict) -> None:
        from .data_source import moved_file

        e = r["entry"]
        moved = moved_file(e)
        files = "".join(f"<li>{html.escape(f)}</li>" for f in e["files"])
        levels = ", ".join(f"{v:g}" for v in e.get("levels") or [])
        self.details.setText(
            f"<h3>{html.escape(r['title'])}</h3><p style='color:#666'>your data, opened lately</p>"
            f"<ul>{files}</ul><p>level {html.escape(levels)}</p>"
            + (f"<p style='color:#b00020'>{html.escape(moved)}</p>" if moved else ""))

    def _show_details(self, item, _previous=None) -> None:
        self.open_button.setEnabled(item is not None)
        if item is None:
            return
        if item.data(DATA_ROLE) is not None:
            self._show_data_details(self.recent[item.data(DATA_ROLE)])
            return
        ex = self._examples[item.data(NAME_ROLE)]
        dim = ex.n - ex.k
        self.details.setText(
            f"<h3>{html.escape(ex.title)}</h3>"
            f"<p style='color:#666'>{html.escape(ex.name)} · dimension {dim} in R<sup>{ex.n}</sup>, "
            f"k = {ex.k}</p>"
            f"<p>{html.escape(ex.description)}</p>"
            f"<p style='color:#666'>F = ({html.escape(', '.join(ex.formulas))})</p>")

    def _open_current(self) -> None:
        if self.grid.currentItem() is not None:
            self._choose(self.grid.currentItem())

    def _choose(self, item) -> None:
        # a double-click is also an activation in most styles: open once
        if self._chosen:
            return
        self._chosen = True
        if item.data(DATA_ROLE) is not None:
            self.dataChosen.emit(self.recent[item.data(DATA_ROLE)]["entry"])
        else:
            self.exampleChosen.emit(item.data(NAME_ROLE))
        self.accept()

    def showEvent(self, event) -> None:
        self._chosen = False
        super().showEvent(event)
