"""QtWaitingPicture: the example's picture over the 3D view until its first result is drawn.

On a first launch the kernels compile for half a minute before the first result: the view was blank all
that time. Now, while nothing is drawn, the view shows the gallery's picture of the example on the
Manifold tab (:mod:`gcmh_studio.make_gallery` draws them) with its title and what the wait is; the first
result drawn takes its place (a later run keeps the last picture on screen meanwhile, as before)."""

from __future__ import annotations

from pathlib import Path

from qtpy.QtCore import QRect, Qt
from qtpy.QtGui import QColor, QFont, QPainter, QPixmap
from qtpy.QtWidgets import QLabel

GALLERY = Path(__file__).resolve().parent / "resources" / "gallery"
BACKGROUND = "#1f2430"


def example_of_system(system: dict):
    """The example whose formulas and variables the Manifold tab shows (``system``: the model's), or None."""
    from gcmh_core.examples import list_examples

    from .labels import _gluing

    formulas = [str(f).strip() for f in system.get("formulas") or []]
    variables = list(system.get("variables") or [])
    if not formulas:
        return None
    glued = _gluing(system.get("periodic") or None, variables)   # (the closed Klein bottle is not the cut one)
    for ex in list_examples(on_error=lambda *a: None):
        if ([str(f).strip() for f in ex.formulas] == formulas and list(ex.variables) == variables
                and _gluing(ex.periodic, variables) == glued):
            return ex
    return None


class QtWaitingPicture:
    """The picture over ``viewer``'s widget (a QLabel) while no result is drawn."""

    def __init__(self, viewer):
        self.viewer = viewer
        self.label = QLabel(viewer.widget)
        self.label.setAttribute(Qt.WA_TransparentForMouseEvents)
        self.label.setAlignment(Qt.AlignCenter)
        self.label.setStyleSheet(f"background: {BACKGROUND};")
        self.label.hide()
        self.example = None
        self.note = ""

    def on_system(self, system: dict) -> None:
        """A system on the Manifold tab: its example's picture, while nothing is drawn yet."""
        if self.viewer.scene.mesh is not None:
            return
        ex = example_of_system(system)
        if ex is None or not (GALLERY / f"{ex.name}.png").is_file():
            self.hide()
            return
        self.example = ex
        self.show()

    def set_note(self, note: str) -> None:
        """What the wait is (the warm-up's notice), under the picture."""
        if note != self.note:
            self.note = note
            if self.label.isVisible():
                self.show()

    def show(self) -> None:
        w, h = self.viewer.widget.width(), self.viewer.widget.height()
        if self.example is None or w < 50 or h < 50:
            return
        self.label.setGeometry(0, 0, w, h)
        self.label.setPixmap(self.card(w, h))
        self.label.show()
        self.label.raise_()

    def hide(self) -> None:
        self.label.hide()

    def shown(self) -> bool:
        return self.label.isVisible()

    def card(self, w: int, h: int) -> QPixmap:
        """The picture (w, h): the thumbnail as large as it fits, the title above, the wait below."""
        out = QPixmap(w, h)
        out.fill(QColor(BACKGROUND))
        qp = QPainter(out)
        qp.setRenderHint(QPainter.SmoothPixmapTransform, True)
        thumb = QPixmap(str(GALLERY / f"{self.example.name}.png"))
        box = QRect(int(0.08 * w), int(0.14 * h), int(0.84 * w), int(0.66 * h))
        if not thumb.isNull():
            img = thumb.scaled(box.size(), Qt.KeepAspectRatio, Qt.SmoothTransformation)
            qp.setOpacity(0.55)   # (a picture of what is coming, not the result itself)
            qp.drawPixmap(box.x() + (box.width() - img.width()) // 2, box.y() + (box.height() - img.height()) // 2,
                          img)
            qp.setOpacity(1.0)
        font = QFont()
        font.setPixelSize(max(18, h // 28))
        qp.setFont(font)
        qp.setPen(QColor("white"))
        qp.drawText(QRect(0, int(0.03 * h), w, int(0.09 * h)), Qt.AlignCenter, self.example.title)
        font.setPixelSize(max(14, h // 45))
        qp.setFont(font)
        qp.setPen(QColor("#c8cfdc"))
        text = "computing\u2026" + (f"\n{self.note}" if self.note else "")
        qp.drawText(QRect(int(0.05 * w), int(0.82 * h), int(0.9 * w), int(0.16 * h)),
                    Qt.AlignHCenter | Qt.AlignTop | Qt.TextWordWrap, text)
        qp.end()
        return out
