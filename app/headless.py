"""Rendering without a window: ``gcmh-app --screenshot`` / ``--animate``, the gallery thumbnails, and the
window's own animation export all draw here, with the window's drawing code (:class:`gcmh_studio.scene.Scene`) on an
off-screen pyvista plotter.  No Qt is imported.

    from gcmh_studio.headless import Options, render
    render(Options(example="klein-bottle", screenshot="klein.png", size=(800, 600)))   # 0 on success
    render(Options(example="hyperboloid", animate="param:a=-1:1", frames=24, gif="a.gif"))

:class:`Options` has the fields (and defaults) of the command line's options; ``render`` checks them against
the example's variables with one-line messages on stderr (exit code 2), extracts, draws, and writes the PNG
or the animation.  A parameter sweep (``param:NAME=FROM:TO``) extracts once per frame
(:func:`param_sweep`, budget checked first by :func:`check_param_sweep`) and draws the frames with one
camera and one colour scale fitted to all of them, each captioned with its value and topology
(:func:`sweep_images`); :func:`export_param_sweep` does all of it for the window's export too.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from contextlib import contextmanager
from dataclasses import dataclass, field, fields


@dataclass
class Options:
    """What to draw and where to write it (the ``gcmh-app`` options without a window)."""

    example: str | None = None
    screenshot: str | None = None
    size: tuple[int, int] | None = None   # None: SCREENSHOT_SIZE, or ANIMATION_SIZE for an animation
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
    params: list = field(default_factory=list)   # --param NAME=VALUE texts (the formulas' parameters)

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> Options:
        return cls(**{f.name: getattr(args, f.name) for f in fields(cls) if hasattr(args, f.name)})


SCREENSHOT_SIZE = (1600, 1200)
# An animation's default: a slide's 16:9 at half HD (a projector doubles it cleanly).  60-frame GIFs at
# 1600x1200 were 11.9 MB (complex cosine rotate:x-y) and 14.6 MB (Clifford torus tour); at 1280x720 with
# frame differences they are 1.6 and 1.7 MB, but the bagel Klein bottle's rotate:x-s is 4.1 MB; here all
# three are well under 4 MB (docs/animations.md).  MP4 is 5-10 times smaller than any GIF, WebP 3-4 times.
ANIMATION_SIZE = (960, 540)


def default_size(animate: bool) -> tuple[int, int]:
    """The picture size when none is given: :data:`ANIMATION_SIZE` for an animation, else
    :data:`SCREENSHOT_SIZE`."""
    return ANIMATION_SIZE if animate else SCREENSHOT_SIZE


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` (e.g. 1600x1200) as an argparse type."""
    try:
        ws, hs = text.lower().replace("*", "x").split("x")
        w, h = int(ws), int(hs)
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
    """One ``gcmh-app: error:`` line on stderr, and the exit code."""
    print(f"gcmh-app: error: {msg}", file=sys.stderr)
    return code


# Anti-aliasing of pictures that are kept: screenshots super-sample (four times the pixels); animation
# frames use FXAA (a 60-frame GIF: 51 s with super-sampling), and move, which hides the rest.
SCREENSHOT_AA = "ssaa"
ANIMATION_AA = "fxaa"


@contextmanager
def offscreen_scene(size, anti_aliasing: str | None = ANIMATION_AA):
    """A :class:`gcmh_studio.scene.Scene` on an off-screen plotter of ``size`` (w, h) pixels, closed afterwards."""
    import pyvista as pv

    from .sections import SectionScene

    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    try:
        yield SectionScene(pl, anti_aliasing=anti_aliasing)  # a slice frame shows the section, its value and chi
    finally:
        pl.close()


def write_frames(scene, projection, frames, window, paths, fps: float, progress=None, cancel=None) -> int:
    """Draw ``frames`` on ``scene`` and write them to each of ``paths`` (.gif/.mp4); returns the frames written.

    The camera, from its direction, is fitted once to every frame's geometry together
    (:func:`gcmh_studio.framing.fit_animation`): no frame cut, none over the text.
    One path: the frames stream to it (``progress(k)``, ``cancel()`` as in
    :func:`gcmh_studio.animation.write_animation`);
    several: rendered once, then written to each.
    """
    from .framing import animation_extent, fit_animation
    from .offscreen import animation_images

    frames = list(frames)
    fit_animation(scene.plotter, animation_extent(scene, projection, frames))
    return write_images(animation_images(scene, projection, frames, window), paths, fps, progress, cancel)


def write_images(images, paths, fps: float, progress=None, cancel=None) -> int:
    """Write the (h, w, 3) ``images`` (any iterable) to each of ``paths`` (.gif/.mp4), each atomically;
    returns the frames written.  One path: they stream to it; several: held, then written to each."""
    from .animation import write_animation

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
    from gcmh_core._validate import parse_params
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
    try:
        given = parse_params(opts.params) or {}
    except InputError as e:
        return fail(str(e))
    params = {**ex.param_values(), **given}
    spec = None
    if opts.animate:
        try:
            spec = parse_spec(opts.animate, names, params=list(ex.params))
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
            if not math.isfinite(float(deg)):   # (a NaN angle drew nothing, exit 0)
                raise ValueError(f"the angle of {plane} must be a finite number of degrees, got {deg.strip()!r}")
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
            if not math.isfinite(slice_c):
                raise ValueError(c)
        except ValueError:
            return fail(f"bad --slice {opts.slice!r}: use VAR=C with VAR one of {', '.join(names)}")
    if opts.slice_width is not None and not opts.slice_width > 0:
        return fail("--slice-width must be > 0")
    job = Job(formulas=list(ex.formulas), variables=list(ex.variables), bounds=[tuple(b) for b in ex.bounds],
              div=opts.div if opts.div is not None else ex.div, seed=opts.seed, method=opts.method,
              start=(list(ex.start) if ex.start else "auto") if opts.method in CONTINUATION_METHODS else None,
              params=params or None, periodic=list(getattr(ex, "periodic", None) or []) or None)
    if spec is not None and spec.kind == "param":
        if opts.slice:
            return fail("--slice goes with screenshots and rotate, tour or slice animations, not with param:")
        # every frame is its own extraction: param_sweep, after the budget check
        return dict(ex=ex, names=names, model=model, mapping=mapping, color=color, cx=None, spec=spec,
                    window=None, job=job)
    try:
        cx = run_job(job)
    except InputError as e:
        return fail(str(e))
    if cx.count(0) == 0:
        return fail("the result is empty (no sign change of F on this grid): nothing to draw", 1)
    model.set_vertices(cx.vertices)
    slice_range = (0.0, 1.0)    # (the range a slice animation sweeps)
    if slice_var is not None:
        window = SliceWindow(slice_var)
        slice_range = lo, hi = window_range(cx.vertices, window.direction(model.frame()))
        window.w = opts.slice_width if opts.slice_width is not None else max(0.04 * (hi - lo), 1e-9)
        window.c = slice_c if slice_c is not None else 0.5 * (lo + hi)
    return dict(ex=ex, names=names, model=model, mapping=mapping, color=color, cx=cx, spec=spec, window=window,
                slice_range=slice_range, job=job)


def render(opts: Options) -> int:
    """Extract the example, render it off screen, write the PNG (``opts.screenshot``) or the animation
    (``opts.animate`` to ``opts.gif`` / ``opts.mp4``); prints one line per file. Returns an exit code."""
    import numpy as np

    from .camera import default_camera
    from .labels import example_labels, view_subtitle
    from .overlays import draw_overlays
    from .scene import Style

    problem = check_outputs([opts.screenshot, opts.gif, opts.mp4])
    if problem is not None:
        return fail(problem)
    if opts.size is None:
        from dataclasses import replace

        opts = replace(opts, size=default_size(bool(opts.animate)))
    prep = _prepare(opts)
    if isinstance(prep, int):
        return prep
    if prep["spec"] is not None and prep["spec"].kind == "param":
        return _param_animation(opts, prep)
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
            return _animation(opts, scene, model, window, spec, prep["slice_range"])
        from .offscreen import RenderError, checked_screenshot

        try:   # (never a black picture: a size the renderer cannot draw super-sampled is drawn with FXAA)
            img = checked_screenshot(scene, opts.transparent)
        except RenderError as e:
            return fail(f"--size {opts.size[0]}x{opts.size[1]}: {e}", 1)
        from PIL import Image

        _written(opts.screenshot, lambda temp: Image.fromarray(np.asarray(img)).save(temp))
    counts = ", ".join(str(c) for c in cx.counts())
    print(f"{opts.screenshot}: {img.shape[1]}x{img.shape[0]}, {ex.title}, dim {cx.dim}, cells by dimension "
          f"{counts}, chi = {cx.euler_characteristic()}, {cx.meta.get('seconds', float('nan')):.2f} s")
    return 0 if np.asarray(img).size else 1


def _animation(opts: Options, scene, model, window, spec, slice_range) -> int:
    import numpy as np

    from .animation import frames_for

    if spec.kind == "rotate" and model.mapping == "orthographic":
        P = model.matrix()
        i, j = spec.plane
        if np.allclose(P[:, [i, j]], 0.0):
            names = scene.names
            print(f"gcmh-app: note: {names[i]} and {names[j]} are both hidden in this view, so turning their plane "
                  f"moves nothing on screen (try rotate:{names[int(np.abs(P).sum(0).argmax())]}-{names[i]}, "
                  "or --mapping perspective)", file=sys.stderr)
    frames = frames_for(spec, model.angles.copy(), opts.frames, slice_range=slice_range)
    outs = [p for p in (opts.gif, opts.mp4) if p]
    n = write_frames(scene, model, frames, window, outs, opts.fps)
    for p in outs:
        print(f"{p}: {n} frames, {opts.size[0]}x{opts.size[1]}, {spec.describe(scene.names)}")
    return 0


# ------------------------------------------------------------------ parameter sweeps
SWEEP_SAMPLE = 200_000   # vertices of all frames together that fix the common centre and the camera


def sweep_values(spec, frames: int) -> list[float]:
    """The parameter's value in each frame of a ``param`` spec (:func:`gcmh_studio.animation.param_frames`)."""
    from .animation import param_frames

    return [v for v in (f.param_value for f in param_frames(spec.lo, spec.hi, frames)) if v is not None]


def _at(job, name: str, value: float):
    """``job`` with parameter ``name`` at ``value``."""
    from dataclasses import replace

    return replace(job, params={**(job.params or {}), name: float(value)})


def check_param_sweep(job, spec, frames: int, size) -> None:
    """Raise InputError (``TooLargeError``) unless a sweep of ``frames`` extractions fits, before any work:
    the frames themselves (``budget.check_frames``), the time of all the extractions and the memory of one
    run plus the results held until they are drawn (the engine's estimate at both ends and the middle,
    the largest taken).  A parameter the formulas don't have is the engine's InputError."""
    from gcmh_core import budget

    from .jobs import estimate_job

    budget.check_frames(frames, *size)
    values = sweep_values(spec, frames)
    ests = [estimate_job(_at(job, spec.param, v)) for v in {values[0], values[len(values) // 2], values[-1]}]
    seconds = frames * max(e.seconds for e in ests)
    held = max(e.peak_bytes for e in ests) + frames * max(e.record_bytes for e in ests)   # (records: at most)
    limit, avail = ests[0].seconds_limit, ests[0].available_bytes
    if seconds > limit:
        raise budget.TooLargeError(f"{frames} extractions would take about {seconds:.0f} s (limit {limit:.0f} s, "
                                   "$GCMH_TIME_LIMIT): use fewer frames or a smaller div")
    if held * budget.MEMORY_MARGIN > avail:
        raise budget.TooLargeError(f"{frames} results held until drawn need up to {budget.format_bytes(held)}; with "
                                   f"room for the estimate's error that is more than the {budget.format_bytes(avail)}"
                                   " available: use fewer frames or a smaller div")


def param_sweep(job, spec, frames: int, progress=None, cancel=None) -> list:
    """Extract ``job`` at each value of the sweep (:func:`sweep_values`); returns the complexes.

    Continuation methods (gcch, ccs) start each frame from the previous frame's result (a small step
    projects its vertices onto the new M at once); when none of them reaches it, the frame starts as
    :func:`gcmh_studio.jobs.run_job` does (the job's start, else "auto").  The whole-grid methods run every
    frame afresh.  ``progress(k)`` after frame k; ``cancel()`` true stops (the frames so far come back).
    """
    from gcmh_core.errors import InputError
    from gcmh_core.extract import CONTINUATION_METHODS

    from .jobs import run_job

    out: list = []
    prev = None
    for value in sweep_values(spec, frames):
        if cancel is not None and cancel():
            break
        at = _at(job, spec.param, value)
        cx = None
        if prev is not None and job.method in CONTINUATION_METHODS and prev.count(0):
            from dataclasses import replace

            try:
                cx = run_job(replace(at, extra={**at.extra, "start": prev}))
            except InputError:   # no vertex of the previous result projects onto this M
                cx = None
        if cx is None:
            cx = run_job(at)
        out.append(cx)
        prev = cx
        if progress is not None:
            progress(len(out))
    return out


def _vertex_sample(complexes, limit: int = SWEEP_SAMPLE):
    """Finite vertices of all ``complexes`` together, every m-th of each so at most about ``limit``."""
    import numpy as np

    total = sum(cx.count(0) for cx in complexes)
    step = max(1, total // limit)
    parts = [np.asarray(cx.vertices, dtype=float)[::step] for cx in complexes if cx.count(0)]
    if not parts:
        return np.zeros((0, complexes[0].n if complexes else 3))
    X = np.concatenate(parts)
    return X[np.all(np.isfinite(X), axis=1)]


def sweep_images(scene, names, view, complexes, spec, style, mapping: str = "orthographic",
                 boundary: bool = False, camera=None, progress=None):
    """Draw each frame of a parameter sweep on ``scene`` (an off-screen one) and yield its image.

    One framing for all frames, so the surface changes and the picture doesn't: every frame is centred
    on the centre of all of them (the projection's scales too), the camera is fitted once to all of
    them together (from ``camera``'s direction, a pyvista Camera such as the window's, else the default
    one), and the colour scale spans all of them.  Each frame is captioned with its value and topology
    (:func:`gcmh_studio.animation.param_caption`) and, at a critical value (``meta["singular_vertices"]``), a
    notice in its own colour.  ``view``: the (fixed) projection."""
    import copy

    import numpy as np
    import pyvista as pv

    from .animation import CRITICAL_COLOUR, critical_note, param_caption
    from .camera import copy_camera, default_camera, refit_camera
    from .framing import fit_animation, hull_points
    from .geometry import Geometry
    from .labels import font_size, view_subtitle
    from .overlays import draw_overlays
    from .projection import Projector, bbox_center
    from .scene import colour_range

    pl = scene.plotter
    sample = _vertex_sample(complexes)
    center = bbox_center(sample)
    radii = Projector(sample, center=center).radii()
    probe = Projector(sample, center=center)
    probe.set_radii(radii)
    shown = np.asarray(probe.project_view(view), dtype=float)
    extent = pl.add_mesh(pv.PolyData(shown), render=False, reset_camera=False, name="gcmh-sweep-extent")
    if camera is not None:
        copy_camera(camera, pl.camera)
        refit_camera(pl)
    else:
        default_camera(pl)
    pl.remove_actor(extent, render=False)
    fit_animation(pl, hull_points(shown[np.all(np.isfinite(shown), axis=1)]))   # (the animations' band)
    camera = pv.Camera()
    copy_camera(pl.camera, camera)
    clim = None
    if style.color_by in names and len(sample):
        clim = colour_range(sample[:, names.index(style.color_by)])
    values = sweep_values(spec, len(complexes)) if len(complexes) > 1 else [spec.lo]
    step = (spec.hi - spec.lo) / max(len(complexes) - 1, 1)
    # the caption's font: the title's, smaller where the longest caption would not fit in 60 % of the width
    # (a character is about 0.95 font units wide)
    w = int(pl.window_size[0])
    far = -max(abs(spec.lo), abs(spec.hi))
    longest = max(param_caption(spec.param, far, step, -10, 10), param_caption(spec.param, far, step, 0, 0), key=len)
    font = max(6, min(font_size(pl, 18), int(0.6 * w / (0.95 * len(longest)))))
    for k, cx in enumerate(complexes):
        empty = not cx.count(0)
        st = copy.copy(style)
        st.subtitle = view_subtitle(cx, names, style.color_by, style.two_sided, mapping, style.labels)
        geo = None
        if not empty:
            geo = Geometry.build(cx, lod=False)
            geo.projector = Projector(cx.vertices, center=center)   # (not each frame's own centre)
            geo.projector.set_radii(radii)
        value = float(cx.meta.get("params", {}).get(spec.param, values[k]))
        caption = param_caption(spec.param, value, step, 0 if empty else cx.euler_characteristic(),
                                0 if empty else cx.connected_components())
        note = critical_note(spec.param, int(cx.meta.get("singular_vertices") or 0))
        with scene.held_render(render=False):   # (each added actor would render: one render a frame)
            scene.set_complex(cx, names, view, st, geometry=geo)
            copy_camera(camera, pl.camera)
            if clim is not None and scene.actor is not None:
                scene.actor.mapper.scalar_range = clim
            if boundary and not empty:
                draw_overlays(scene, cx, boundary=True)
            pl.add_text(caption, position=(0.03, 0.055), viewport=True, font_size=font, color="white",
                        name="gcmh-sweep-caption", render=False)
            if note:
                small = max(6, min(int(font * 0.6), int(0.9 * w / (0.95 * len(note)))))
                pl.add_text(note, position=(0.03, 0.015), viewport=True, font_size=small,
                            color=CRITICAL_COLOUR, name="gcmh-sweep-note", render=False)
            else:
                pl.remove_actor("gcmh-sweep-note", render=False)
            pl.renderer.ResetCameraClippingRange()
        pl.render()
        img = pl.screenshot(None, return_img=True)
        if progress is not None:
            progress(k + 1)
        yield img


def export_param_sweep(paths, job, spec, frames: int, names, projection, style, size, fps: float,
                       mapping: str = "orthographic", boundary: bool = False, transparent: bool = False,
                       camera=None, progress=None, cancel=None) -> tuple[int, list]:
    """A parameter sweep from start to file: budget check, output check, the extractions, the frames,
    each of ``paths`` (.gif/.mp4) written atomically.  Returns (frames written, the complexes).

    ``projection``: an :class:`gcmh_studio.projection.ProjectionModel` (its angles and mapping; its principal axes
    are set from all the frames); ``style``: an :class:`gcmh_studio.scene.Style` (title, colour, labels);
    ``camera``: a pyvista Camera whose direction the picture keeps (the window's), else the default view.
    ``progress(phase, k)``: phase "extract" then "draw", k frames done.  Bad input, or a sweep that
    won't fit, raises InputError before any work."""
    from gcmh_core.errors import InputError

    check_param_sweep(job, spec, frames, size)
    problem = check_outputs(paths)
    if problem is not None:
        raise InputError(problem)
    complexes = param_sweep(job, spec, frames, progress=(lambda k: progress("extract", k)) if progress else None,
                            cancel=cancel)
    if len(complexes) < frames:   # cancelled
        return 0, complexes
    if all(cx.count(0) == 0 for cx in complexes):
        raise InputError(f"the result is empty at every value of {spec.param} from {spec.lo:g} to {spec.hi:g} "
                         "(no sign change of F on this grid): nothing to draw")
    projection.set_vertices(_vertex_sample(complexes))
    with offscreen_scene(size, ANIMATION_AA) as scene:
        if transparent:
            scene.plotter.renderer.GradientBackgroundOff()
        images = sweep_images(scene, list(names), projection.view(), complexes, spec, style, mapping=mapping,
                              boundary=boundary, camera=camera,
                              progress=(lambda k: progress("draw", k)) if progress else None)
        n = write_images(images, list(paths), fps, cancel=cancel)
    return n, complexes


def _param_animation(opts: Options, prep) -> int:
    """``--animate param:NAME=FROM:TO``: :func:`export_param_sweep`, then one line per file."""
    from gcmh_core.errors import InputError

    from .labels import example_labels
    from .scene import Style

    ex, names, spec = prep["ex"], prep["names"], prep["spec"]
    style = Style(color_by=prep["color"], title=ex.title, two_sided=opts.two_sided, labels=example_labels(ex))
    outs = [p for p in (opts.gif, opts.mp4) if p]
    try:
        n, complexes = export_param_sweep(outs, prep["job"], spec, opts.frames, names, prep["model"], style,
                                          opts.size, opts.fps, mapping=prep["mapping"], boundary=opts.boundary,
                                          transparent=opts.transparent)
    except InputError as e:
        return fail(str(e))
    chis = [cx.euler_characteristic() if cx.count(0) else "empty" for cx in complexes]
    steps = [f"{chis[0]}"] + [f"{b} at {spec.param} = {cx.meta['params'][spec.param]:.3g}"
                              for a, b, cx in zip(chis, chis[1:], complexes[1:]) if a != b]
    critical = [f"{cx.meta['params'][spec.param]:.3g}" for cx in complexes if cx.meta.get("singular_vertices")]
    for p in outs:
        print(f"{p}: {n} frames, {opts.size[0]}x{opts.size[1]}, {spec.describe(names)}, chi "
              + " -> ".join(steps) + (f"; critical near {spec.param} = {', '.join(critical)}" if critical else ""))
    return 0
