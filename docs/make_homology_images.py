"""The pictures of docs/homology.md: generators of H1 (and the w1 loop) on three examples.

    xvfb-run -a .venv/bin/python docs/make_homology_images.py [--out docs/images] [--small]

Opens the window (as a teacher would), runs each example, waits for the Topology tab's
homology (computed in its worker), presses b1 (and the w1 switch on the Klein bottle),
and saves the whole window: the numbers in the tab and the loops on the picture.  The
window's hook that hands the box's overlays to the scene is connected here the same way
the main window's is (see docs/homology.md, "App").
"""

from __future__ import annotations

import argparse
import os
import sys

CASES = [  # example, div (None: the example's own), picture, w1 switch, curvature colours, Betti number pressed
    ("klein-bottle-closed", [24, 24, 12, 24, 24], "homology-klein-bottle.png", True, False, 1),
    ("torus-angles", None, "homology-torus-angles.png", False, False, 1),
    ("pentagon-linkage", None, "homology-pentagon-linkage.png", False, False, 1),
    ("genus-two", None, "homology-genus-two-curvature.png", False, True, 1),
    ("three-torus", None, "homology-three-torus-h2.png", False, False, 2),   # H2 as see-through surfaces
]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "images"))
    ap.add_argument("--small", action="store_true", help="smaller grids (a quick look)")
    ap.add_argument("--only", default=None, help="comma-separated example names")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    os.environ.setdefault("XDG_RUNTIME_DIR", "/tmp/gcmh-runtime-0")

    from qtpy.QtCore import QEventLoop, QTimer
    from qtpy.QtWidgets import QApplication

    from gcmh_studio.homology_surfaces import draw_homology_surfaces
    from gcmh_studio.overlays import colour_by_values, draw_homology
    from gcmh_studio.qt_main_window import QtMainWindow

    app = QApplication.instance() or QApplication(sys.argv)
    w = QtMainWindow(example=None)
    w.resize(1500, 950)
    w.show()
    box = w.topology_panel.homology_box
    box.overlays.connect(lambda specs: draw_homology(w.scene, specs))
    box.surfaces.connect(lambda specs: draw_homology_surfaces(w.scene, specs))
    box.curvature.connect(lambda values: colour_by_values(w.scene, w.model.result, values))
    w.tabs.setCurrentIndex(w.tabs.count() - 1)   # the Topology tab

    def wait(signal, timeout_s=900):
        loop = QEventLoop()
        signal.connect(loop.quit)
        QTimer.singleShot(int(timeout_s * 1000), loop.quit)
        loop.exec_()
        signal.disconnect(loop.quit)

    only = set(args.only.split(",")) if args.only else None
    for name, div, picture, w1, curvature, q in CASES:
        if only and name not in only:
            continue
        if args.small and div is not None:
            div = [max(6, d // 2) for d in div]
        w.load_example(name, div=div)
        wait(w.runFinished)
        if box.data is None:
            wait(box.computed)
        if box.data is None:
            print(f"{name}: {box.status.text()}")
            continue
        if curvature:
            box.curvature_check.click()
        else:
            box.betti[q].click()
        if q == 2:   # the 3-manifold itself faint, so its H2 classes show inside it
            w.scene.set_opacity(0.06)
        if w1:
            box.w1_check.click()
        app.processEvents()
        w.plotter.render()
        path = os.path.join(args.out, picture)
        w.grab().save(path)
        print(f"{name}: {box.status.text()}  ->  {path}")
    w.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
