"""GCMH Studio: ``gcmh-app`` / ``python -m app``.

    gcmh-app                                   # the window, opening on the Klein bottle
    gcmh-app --example complex-cosine          # the window, opening on another example
    gcmh-app --session my.json                 # the window, restoring a saved session
    gcmh-app --example klein-bottle --screenshot klein.png --size 1600x1200 [--div 30]
                                               # no window: extract, render off screen, write the PNG
    gcmh-app --example klein-bottle --animate rotate:s-t --frames 60 --gif klein.gif [--mp4 klein.mp4]
    gcmh-app --example clifford-torus --mapping stereographic --animate tour --mp4 tour.mp4
    gcmh-app --example klein-bottle --animate slice:s --slice-width 0.2 --gif sweep.gif
                                               # no window: an animation as GIF and/or MP4
"""

from __future__ import annotations

import argparse
import os
import sys

from .projection import MAPPINGS


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = text.lower().replace("*", "x").split("x")
        w, h = int(w), int(h)
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must look like 1600x1200, got {text!r}") from None
    if not (16 <= w <= 16384 and 16 <= h <= 16384):
        raise argparse.ArgumentTypeError("size out of range (16..16384 pixels per side)")
    return w, h


def _div(text: str):
    try:
        parts = [int(p) for p in text.replace(",", " ").split()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"div must be an integer or a comma-separated list, got {text!r}") from None
    if not parts or min(parts) < 1:
        raise argparse.ArgumentTypeError("div must be at least 1")
    return parts[0] if len(parts) == 1 else parts


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="gcmh-app", description="GCMH Studio: see implicit manifolds of any dimension.")
    p.add_argument("--example", metavar="NAME", help="open this example (see --list)")
    p.add_argument("--session", metavar="FILE", help="open a saved session (.json)")
    p.add_argument("--list", action="store_true", help="list the examples and exit")
    p.add_argument("--screenshot", metavar="PNG", help="render without a window, write this PNG and exit")
    p.add_argument("--size", type=_size, default=(1600, 1200), metavar="WxH", help="screenshot size (default 1600x1200)")
    p.add_argument("--div", type=_div, metavar="N", help="override the example's grid divisions (N or N1,N2,...)")
    p.add_argument("--seed", type=int, default=0, help="grid perturbation seed (default 0)")
    p.add_argument("--method", default="gcmh", type=str.lower,
                   help="extraction method: gcmh (whole grid, the default), gcch (continuation from the "
                        "example's start point), or the simplicial baselines cms and ccs")
    p.add_argument("--window-screenshot", metavar="PNG",
                   help="show the window, wait for the first result, save a picture of the whole window and exit")
    p.add_argument("--transparent", action="store_true", help="screenshot with a transparent background")
    p.add_argument("--color", metavar="VAR", help="colour by this variable instead of the example's choice")
    p.add_argument("--project", metavar="A,B,C", help="show these three variables as X, Y, Z")
    p.add_argument("--rotate", metavar="I-J=DEG", action="append", default=[],
                   help="rotate in the plane of variables I and J by DEG degrees (repeatable), e.g. s-x=30")
    p.add_argument("--mapping", choices=MAPPINGS, default=None,
                   help="how R^n goes to 3D: orthographic, perspective or stereographic (n >= 4); "
                        "default: the example's own (mostly orthographic)")
    p.add_argument("--distance", type=float, default=3.0,
                   help="perspective eye distance, in radii of the object (> 1, default 3)")
    p.add_argument("--slice", metavar="VAR=C", help="show only |VAR - C| <= --slice-width (screenshots)")
    p.add_argument("--slice-width", type=float, default=None, metavar="W",
                   help="half-width of the slicing window (default: 4%% of the variable's range)")
    p.add_argument("--two-sided", action="store_true",
                   help="front faces gold, back faces blue (a surface's two sides; Klein bottle: where they swap)")
    p.add_argument("--boundary", action="store_true", help="draw the boundary facets in red")
    p.add_argument("--animate", metavar="SPEC",
                   help="no window: render an animation, SPEC = rotate:I-J | tour | slice:VAR (needs --gif/--mp4)")
    p.add_argument("--frames", type=int, default=60, help="animation frames (default 60)")
    p.add_argument("--fps", type=float, default=20.0, help="animation frames per second (default 20)")
    p.add_argument("--gif", metavar="FILE", help="write the animation as a GIF")
    p.add_argument("--mp4", metavar="FILE", help="write the animation as an MP4 (H.264)")
    return p


def _prepare_env() -> None:
    if not os.environ.get("XDG_RUNTIME_DIR"):
        d = os.path.join("/tmp", f"runtime-{os.getuid()}") if hasattr(os, "getuid") else None
        if d:
            os.makedirs(d, mode=0o700, exist_ok=True)
            os.environ["XDG_RUNTIME_DIR"] = d


def _fail(msg: str, code: int = 2) -> int:
    print(f"gcmh-app: {msg}", file=sys.stderr)
    return code


def _headless_prepare(args):
    """Load the example, check every option against its variables, extract. Returns a dict or an exit code."""
    from gcmh_core.errors import InputError
    from gcmh_core.examples import load_example
    from gcmh_core.extract import CONTINUATION_METHODS

    from .animation import parse_spec
    from .projection import ProjectionModel
    from .slicing import SliceWindow, window_range
    from .worker import Job, run_job

    name = args.example or "klein-bottle"
    try:
        ex = load_example(name)
    except InputError as e:
        return _fail(str(e))
    names = list(ex.variables)
    view = dict(ex.view or {})
    project = args.project.split(",") if args.project else view.get("project", names[:3])
    color = args.color or view.get("color")
    args.mapping = args.mapping or view.get("mapping", "orthographic")
    spec = None
    if args.animate:
        try:
            spec = parse_spec(args.animate, names)
        except ValueError as e:
            return _fail(f"bad --animate: {e}")
        if not (args.gif or args.mp4):
            return _fail("--animate needs --gif FILE and/or --mp4 FILE")
        if args.frames < 1 or args.frames > 10000:
            return _fail(f"--frames must be between 1 and 10000, got {args.frames}")
        if not args.fps > 0:
            return _fail("--fps must be > 0")
        for f, ext in ((args.gif, ".gif"), (args.mp4, ".mp4")):
            if f and not f.lower().endswith(ext):
                return _fail(f"{f!r} must end in {ext}")
    try:
        model = ProjectionModel(n=len(names), axes=tuple(names.index(a.strip()) for a in project),
                                mapping=args.mapping, distance=args.distance)
        for spec_r in args.rotate:
            plane, deg = spec_r.split("=")
            a, b = (names.index(t.strip()) for t in plane.replace("\u2013", "-").split("-"))
            i, j = min(a, b), max(a, b)
            sgn = 1.0 if a < b else -1.0
            model.angles[model.planes.index((i, j))] = sgn * float(deg)
    except ValueError as e:
        return _fail(f"bad --project/--rotate/--mapping ({e}); variables are {', '.join(names)}")
    if args.mapping != "orthographic" and len(names) < 4:
        return _fail(f"--mapping {args.mapping} needs n >= 4 (this example has n = {len(names)})")
    if color is not None and color not in names:
        return _fail(f"--color must be one of {', '.join(names)}")
    window = None
    slice_var = spec.var if spec is not None and spec.kind == "slice" else None
    slice_c = None
    if args.slice:
        var, _, c = args.slice.partition("=")
        try:
            slice_var, slice_c = names.index(var.strip()), float(c)
        except ValueError:
            return _fail(f"bad --slice {args.slice!r}: use VAR=C with VAR one of {', '.join(names)}")
    if args.slice_width is not None and not args.slice_width > 0:
        return _fail("--slice-width must be > 0")
    job = Job(formulas=list(ex.formulas), variables=list(ex.variables), bounds=[tuple(b) for b in ex.bounds],
              div=args.div if args.div is not None else ex.div, seed=args.seed, method=args.method,
              start=(list(ex.start) if ex.start else "auto") if args.method in CONTINUATION_METHODS else None)
    try:
        cx = run_job(job)
    except InputError as e:
        return _fail(str(e))
    if cx.count(0) == 0:
        return _fail("the result is empty (no sign change of F on this grid): nothing to draw", 1)
    model.set_vertices(cx.vertices)
    if slice_var is not None:
        window = SliceWindow(slice_var)
        lo, hi = window_range(cx.vertices, window.direction(model.frame()))
        window.w = args.slice_width if args.slice_width is not None else max(0.04 * (hi - lo), 1e-9)
        window.c = slice_c if slice_c is not None else 0.5 * (lo + hi)
        window.range = (lo, hi)
    return dict(ex=ex, names=names, model=model, color=color, cx=cx, spec=spec, window=window)


def headless_screenshot(args) -> int:
    """Extract the example, render it off screen with the window's drawing code, write the PNG or the animation."""
    import numpy as np
    import pyvista as pv

    from .scene import Scene, Style, animation_images, default_camera, describe

    if args.session:
        return _headless_session(args)
    prep = _headless_prepare(args)
    if isinstance(prep, int):
        return prep
    ex, names, model, color, cx = prep["ex"], prep["names"], prep["model"], prep["color"], prep["cx"]
    window, spec = prep["window"], prep["spec"]
    w, h = args.size
    pl = pv.Plotter(off_screen=True, window_size=[w, h])
    try:
        scene = Scene(pl)
        dim = cx.dim
        sub = describe(cx, names, None if args.two_sided else color)
        if args.two_sided:
            sub += " \u00b7 two sides: gold front, blue back"
        if args.mapping != "orthographic":
            sub += f" \u00b7 {args.mapping}"
        scene.set_complex(cx, names, model.view(), Style(color_by=color, title=ex.title, subtitle=sub,
                                                         two_sided=args.two_sided))
        if args.boundary:
            from .geometry import boundary_lines
            from .scene import BOUNDARY_COLOR

            X, E = boundary_lines(cx)
            scene.set_overlay("boundary", X, E, BOUNDARY_COLOR, width=4.0, render=False)
        default_camera(pl)   # fitted to the whole complex: a slice or a tour stays in the picture
        if window is not None:
            scene.set_slice(window.direction(model.frame()), window.c, window.w, render=False)
        if args.transparent:
            pl.renderer.GradientBackgroundOff()
        if spec is not None:
            return _headless_animation(args, scene, model, window, spec, cx)
        pl.render()
        img = pl.screenshot(args.screenshot, transparent_background=args.transparent, return_img=True)
    finally:
        pl.close()
    counts = ", ".join(str(c) for c in cx.counts())
    print(f"{args.screenshot}: {img.shape[1]}x{img.shape[0]}, {ex.title}, dim {dim}, cells by dimension {counts}, "
          f"chi = {cx.euler_characteristic()}, {cx.meta.get('seconds', float('nan')):.2f} s")
    return 0 if np.asarray(img).size else 1


def _headless_animation(args, scene, model, window, spec, cx) -> int:
    import numpy as np

    from .animation import frames_for, write_animation
    from .scene import animation_images

    rng = getattr(window, "range", (0.0, 1.0))
    if spec.kind == "rotate" and model.mapping == "orthographic":
        P = model.matrix()
        i, j = spec.plane
        if np.allclose(P[:, [i, j]], 0.0):
            names = scene.names
            print(f"gcmh-app: note: {names[i]} and {names[j]} are both hidden in this view, so turning their plane "
                  f"moves nothing on screen (try rotate:{names[int(np.abs(P).sum(0).argmax())]}-{names[i]}, "
                  "or --mapping perspective)", file=sys.stderr)
    frames = frames_for(spec, model.angles.copy(), args.frames, slice_range=rng)
    outs = [p for p in (args.gif, args.mp4) if p]
    if len(outs) == 1:
        n = write_animation(outs[0], animation_images(scene, model, frames, window), fps=args.fps)
    else:   # render once, write both
        imgs = list(animation_images(scene, model, frames, window))
        for p in outs:
            n = write_animation(p, imgs, fps=args.fps)
    for p in outs:
        print(f"{p}: {n} frames, {args.size[0]}x{args.size[1]}, {spec.describe(scene.names)}")
    return 0


def _headless_session(args) -> int:
    """Headless screenshot of a saved session: uses the window's own code, unshown."""
    from qtpy.QtCore import QEventLoop, QTimer
    from qtpy.QtWidgets import QApplication

    from .qt_main_window import QtMainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    win = QtMainWindow(example=None)
    loop = QEventLoop()
    outcome = {}

    def finished(how):
        outcome["how"] = how
        QTimer.singleShot(0, loop.quit)

    win.runFinished.connect(finished)
    if not win.open_session(args.session):
        print(f"gcmh-app: {win.last_status}", file=sys.stderr)
        return 2
    loop.exec_()
    if outcome.get("how") != "done":
        print(f"gcmh-app: {win.last_status}", file=sys.stderr)
        win.close()
        return 1
    win.save_screenshot(args.screenshot, size=args.size, transparent=args.transparent)
    print(args.screenshot)
    win.close()
    return 0


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    _prepare_env()
    if args.list:
        from gcmh_core.examples import list_examples
        for ex in list_examples():
            print(f"{ex.name:18s} {ex.title}  (n={ex.n}, k={ex.k})")
        return 0
    if args.screenshot or args.animate:
        return headless_screenshot(args)
    if args.gif or args.mp4:
        return _fail("--gif/--mp4 need --animate SPEC (rotate:I-J, tour or slice:VAR)")

    from qtpy.QtWidgets import QApplication

    from .qt_main_window import QtMainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("GCMH Studio")

    def excepthook(kind, value, tb):
        # PyQt5 aborts on an exception escaping a slot unless a hook is set: print it, tell the user
        import traceback

        traceback.print_exception(kind, value, tb)
        try:
            win.set_status(f"Internal error: {kind.__name__}: {value}", error=True)
        except Exception:  # noqa: BLE001
            pass

    sys.excepthook = excepthook
    win = QtMainWindow(example=None if args.session else (args.example or "klein-bottle"), div=args.div,
                       method=args.method)
    if args.window_screenshot:
        w, h = args.size if args.size != (1600, 1200) else (1400, 900)
        win.resize(w, h)

        def grab(how):
            win.tabs.setCurrentIndex(1)
            app.processEvents()
            win.plotter.render()
            win.grab().save(args.window_screenshot)
            print(f"{args.window_screenshot} ({how}: {win.result_label.text()})")
            win.close()
            app.quit()

        win.runFinished.connect(grab)
    if args.session:
        win.open_session(args.session)
    win.show()
    return app.exec_()


if __name__ == "__main__":
    sys.exit(main())
