"""Rendering without a window: ``gcmh-app --screenshot`` / ``--animate``, the gallery thumbnails, and the
window's own animation export all draw here, with the window's drawing code (:class:`app.scene.Scene`) on an
off-screen pyvista plotter.  No Qt is imported.

    from app.headless import Options, render
    render(Options(example="klein-bottle", screenshot="klein.png", size=(800, 600)))   # 0 on success

:class:`Options` has the fields (and defaults) of the command line's options; ``render`` checks them against
the example's variables with one-line messages on stderr (exit code 2), extracts, draws, and writes the PNG
or the animation.
"""

from __future__ import annotations

import argparse
import os
import sys
from contextlib import contextmanager
from dataclasses import dataclass, field, fields


@dataclass
class Options:
    """What to draw and where to write it (the ``gcmh-app`` options without a window)."""

    example: str | None = None
    screenshot: str | None = None
    size: tuple[int, int] = (1600, 1200)
    div: object = None
    seed: int = 0
    method: str = "gcmh"
    transparent: bool = False
    color: str | None = None
    project: str | None = None
    rotate: list = field(default_factory=list)
    mapping: str | None = None
    distance: float = 3.0
    slice: str | None = None
    slice_width: float | None = None
    two_sided: bool = False
    boundary: bool = False
    animate: str | None = None
    frames: int = 60
    fps: float = 20.0
    gif: str | None = None
    mp4: str | None = None

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> Options:
        return cls(**{f.name: getattr(args, f.name) for f in fields(cls) if hasattr(args, f.name)})


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` (e.g. 1600x1200) as an argparse type."""
    try:
        w, h = text.lower().replace("*", "x").split("x")
        w, h = int(w), int(h)
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must look like 1600x1200, got {text!r}") from None
    if not (16 <= w <= 16384 and 16 <= h <= 16384):
        raise argparse.ArgumentTypeError("size out of range (16..16384 pixels per side)")
    return w, h


def prepare_env() -> None:
    """Qt and VTK want a private runtime folder; make one when the session has none (ssh, containers)."""
    if not os.environ.get("XDG_RUNTIME_DIR"):
        d = os.path.join("/tmp", f"runtime-{os.getuid()}") if hasattr(os, "getuid") else None
        if d:
            os.makedirs(d, mode=0o700, exist_ok=True)
            os.environ["XDG_RUNTIME_DIR"] = d


def fail(msg: str, code: int = 2) -> int:
    print(f"gcmh-app: {msg}", file=sys.stderr)
    return code


# Anti-aliasing of pictures that are kept: screenshots super-sample (four times the pixels); animation
# frames use FXAA (a 60-frame GIF: 51 s with super-sampling), and move, which hides the rest.
SCREENSHOT_AA = "ssaa"
ANIMATION_AA = "fxaa"


@contextmanager
def offscreen_scene(size, anti_aliasing: str | None = ANIMATION_AA):
    """A :class:`app.scene.Scene` on an off-screen plotter of ``size`` (w, h) pixels, closed afterwards."""
    import pyvista as pv

    from .scene import Scene

    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    try:
        yield Scene(pl, anti_aliasing=anti_aliasing)
    finally:
        pl.close()


def write_frames(scene, projection, frames, window, paths, fps: float, progress=None, cancel=None) -> int:
    """Draw ``frames`` on ``scene`` and write them to each of ``paths`` (.gif/.mp4); returns the frames written.

    One path: the frames stream to it (``progress(k)``, ``cancel()`` as in :func:`app.animation.write_animation`);
    several: rendered once, then written to each.
    """
    from .animation import write_animation
    from .scene import animation_images

    images = animation_images(scene, projection, frames, window)
    if len(paths) == 1:
        return _written(paths[0], lambda temp: write_animation(temp, images, fps=fps, progress=progress,
                                                               cancel=cancel), cancel)
    images = list(images)
    n = 0
    for p in paths:
        n = _written(p, lambda temp: write_animation(temp, images, fps=fps, progress=progress, cancel=cancel),
                     cancel)
    return n


def _written(path, write, cancel=None):
    """write(temporary file beside path), then the temporary replaces path: an interrupted
    or cancelled export leaves the old file as it was and no temporary behind."""
    import os

    from gcmh_core.safe_io import AtomicFile

    out = AtomicFile(path, suffix=os.path.splitext(str(path))[1], what=str(path))
    try:
        result = write(out.temp)
        if os.path.exists(out.temp) and not (cancel is not None and cancel()):
            out.commit()
        return result
    finally:
        out.discard()


def check_outputs(paths) -> str | None:
    """The first problem with any output path (missing or read-only folder, a folder, a device
    or FIFO), as one line, or None: checked before anything is extracted or drawn."""
    from gcmh_core.errors import InputError
    from gcmh_core.safe_io import check_output

    for p in paths:
        if p:
            try:
                check_output(p, what=str(p))
            except InputError as e:
                return str(e)
    return None


def _prepare(opts: Options):
    """Load the example, check every option against its variables, extract. Returns a dict or an exit code."""
    from gcmh_core.errors import InputError
    from gcmh_core.examples import load_example
    from gcmh_core.extract import CONTINUATION_METHODS

    from .animation import parse_spec
    from .jobs import Job, run_job
    from .projection import ProjectionModel
    from .slicing import SliceWindow, window_range

    name = opts.example or "klein-bottle"
    try:
        ex = load_example(name)
    except InputError as e:
        return fail(str(e))
    names = list(ex.variables)
    view = dict(ex.view or {})
    project = opts.project.split(",") if opts.project else view.get("project", names[:3])
    color = opts.color or view.get("color")
    mapping = opts.mapping or view.get("mapping", "orthographic")
    spec = None
    if opts.animate:
        try:
            spec = parse_spec(opts.animate, names)
        except ValueError as e:
            return fail(f"bad --animate: {e}")
        if not (opts.gif or opts.mp4):
            return fail("--animate needs --gif FILE and/or --mp4 FILE")
        if opts.frames < 1 or opts.frames > 10000:
            return fail(f"--frames must be between 1 and 10000, got {opts.frames}")
        if not opts.fps > 0:
            return fail("--fps must be > 0")
        for f, ext in ((opts.gif, ".gif"), (opts.mp4, ".mp4")):
            if f and not f.lower().endswith(ext):
                return fail(f"{f!r} must end in {ext}")
    try:
        model = ProjectionModel(n=len(names), axes=tuple(names.index(a.strip()) for a in project),
                                mapping=mapping, distance=opts.distance)
        for spec_r in opts.rotate:
            plane, deg = spec_r.split("=")
            a, b = (names.index(t.strip()) for t in plane.replace("\u2013", "-").split("-"))
            i, j = min(a, b), max(a, b)
            sgn = 1.0 if a < b else -1.0
            model.angles[model.planes.index((i, j))] = sgn * float(deg)
    except ValueError as e:
        return fail(f"bad --project/--rotate/--mapping ({e}); variables are {', '.join(names)}")
    if mapping != "orthographic" and len(names) < 4:
        return fail(f"--mapping {mapping} needs n >= 4 (this example has n = {len(names)})")
    if color is not None and color not in names:
        return fail(f"--color must be one of {', '.join(names)}")
    window = None
    slice_var = spec.var if spec is not None and spec.kind == "slice" else None
    slice_c = None
    if opts.slice:
        var, _, c = opts.slice.partition("=")
        try:
            slice_var, slice_c = names.index(var.strip()), float(c)
        except ValueError:
            return fail(f"bad --slice {opts.slice!r}: use VAR=C with VAR one of {', '.join(names)}")
    if opts.slice_width is not None and not opts.slice_width > 0:
        return fail("--slice-width must be > 0")
    job = Job(formulas=list(ex.formulas), variables=list(ex.variables), bounds=[tuple(b) for b in ex.bounds],
              div=opts.div if opts.div is not None else ex.div, seed=opts.seed, method=opts.method,
              start=(list(ex.start) if ex.start else "auto") if opts.method in CONTINUATION_METHODS else None,
              extra={"params": ex.param_values()} if getattr(ex, "params", None) else {},
              periodic=list(getattr(ex, "periodic", None) or []) or None)
    try:
        cx = run_job(job)
    except InputError as e:
        return fail(str(e))
    if cx.count(0) == 0:
        return fail("the result is empty (no sign change of F on this grid): nothing to draw", 1)
    model.set_vertices(cx.vertices)
    if slice_var is not None:
        window = SliceWindow(slice_var)
        lo, hi = window_range(cx.vertices, window.direction(model.frame()))
        window.w = opts.slice_width if opts.slice_width is not None else max(0.04 * (hi - lo), 1e-9)
        window.c = slice_c if slice_c is not None else 0.5 * (lo + hi)
        window.range = (lo, hi)
    return dict(ex=ex, names=names, model=model, mapping=mapping, color=color, cx=cx, spec=spec, window=window)


def render(opts: Options) -> int:
    """Extract the example, render it off screen, write the PNG (``opts.screenshot``) or the animation
    (``opts.animate`` to ``opts.gif`` / ``opts.mp4``); prints one line per file. Returns an exit code."""
    import numpy as np

    from .scene import Style, default_camera, draw_overlays, example_labels, view_subtitle

    problem = check_outputs([opts.screenshot, opts.gif, opts.mp4])
    if problem is not None:
        return fail(problem)
    prep = _prepare(opts)
    if isinstance(prep, int):
        return prep
    ex, names, model, color, cx = prep["ex"], prep["names"], prep["model"], prep["color"], prep["cx"]
    window, spec = prep["window"], prep["spec"]
    with offscreen_scene(opts.size, ANIMATION_AA if spec is not None else SCREENSHOT_AA) as scene:
        pl = scene.plotter
        labels = example_labels(ex)
        sub = view_subtitle(cx, names, color, opts.two_sided, prep["mapping"], labels)
        scene.set_complex(cx, names, model.view(), Style(color_by=color, title=ex.title, subtitle=sub,
                                                         two_sided=opts.two_sided, labels=labels))
        if opts.boundary:
            draw_overlays(scene, cx, boundary=True)
        default_camera(pl)   # fitted to the whole complex: a slice or a tour stays in the picture
        if window is not None:
            scene.set_slice(window.direction(model.frame()), window.c, window.w, render=False)
        if opts.transparent:
            pl.renderer.GradientBackgroundOff()
        if spec is not None:
            return _animation(opts, scene, model, window, spec)
        pl.render()
        img = pl.screenshot(None, transparent_background=opts.transparent, return_img=True)
        from PIL import Image

        _written(opts.screenshot, lambda temp: Image.fromarray(np.asarray(img)).save(temp))
    counts = ", ".join(str(c) for c in cx.counts())
    print(f"{opts.screenshot}: {img.shape[1]}x{img.shape[0]}, {ex.title}, dim {cx.dim}, cells by dimension "
          f"{counts}, chi = {cx.euler_characteristic()}, {cx.meta.get('seconds', float('nan')):.2f} s")
    return 0 if np.asarray(img).size else 1


def _animation(opts: Options, scene, model, window, spec) -> int:
    import numpy as np

    from .animation import frames_for

    rng = getattr(window, "range", (0.0, 1.0))
    if spec.kind == "rotate" and model.mapping == "orthographic":
        P = model.matrix()
        i, j = spec.plane
        if np.allclose(P[:, [i, j]], 0.0):
            names = scene.names
            print(f"gcmh-app: note: {names[i]} and {names[j]} are both hidden in this view, so turning their plane "
                  f"moves nothing on screen (try rotate:{names[int(np.abs(P).sum(0).argmax())]}-{names[i]}, "
                  "or --mapping perspective)", file=sys.stderr)
    frames = frames_for(spec, model.angles.copy(), opts.frames, slice_range=rng)
    outs = [p for p in (opts.gif, opts.mp4) if p]
    n = write_frames(scene, model, frames, window, outs, opts.fps)
    for p in outs:
        print(f"{p}: {n} frames, {opts.size[0]}x{opts.size[1]}, {spec.describe(scene.names)}")
    return 0
