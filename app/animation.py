"""Frame sequences for animations, and writing them as GIF / MP4 (numpy + imageio; no Qt, no VTK).

Three kinds, all as lists of :class:`Frame` (what to change before drawing a frame):

* ``rotate``: one plane's angle goes once around (360 degrees) from its current value;
* ``tour``: a smooth closed path through projections. Every plane angle follows
  ``a_p(t) = a_p(0) + A sin(2 pi f_p t + phi_p) - A sin(phi_p)``, t in [0, 1),
  with small integer frequencies ``f_p`` and random phases (seeded). The path
  is smooth, starts at the current view and closes up (a GIF loops without a
  jump), and because it moves the very angles the sliders show, the sliders
  follow it. (A geodesic tour between random frames would leave the slider
  coordinates; this one never does.)
* ``slice``: the centre of the slicing window sweeps from one end of the
  complex to the other and back.
* ``param``: a parameter of the formulas goes from one value to another, evenly,
  both ends included; every frame is its own extraction (:mod:`gcmh_studio.headless`
  draws them with one camera, so the surface changes and the framing does not).

Spec text (the ``--animate`` option): ``rotate:I-J`` (variable names, e.g.
``rotate:s-t``), ``tour``, ``slice:VAR``, ``param:NAME=FROM:TO`` (e.g.
``param:a=-1:1``; the ends may be constant text such as ``-pi/2``).
:func:`parse_spec` checks it against the variable and parameter names with a
one-line message.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

TOUR_AMPLITUDE = 75.0      # degrees: far enough to see everything, slow enough to follow
KINDS = ("rotate", "tour", "slice", "param")
# seconds per period of a playing animation at speed 1 (the Animate tab)
ROTATE_PERIOD = 12.0
TOUR_PERIOD = 60.0
SLICE_PERIOD = 10.0
PARAM_PERIOD = 16.0   # there and back: every value is an extraction (coarse while playing)


@dataclass
class Frame:
    """What to show in one frame: all plane angles (degrees), a slice centre and/or the swept parameter's
    value (None: unchanged)."""

    angles: np.ndarray | None = None
    slice_center: float | None = None
    param_value: float | None = None


@dataclass(frozen=True)
class Spec:
    """A parsed animation: kind, the plane (i, j) and its sense for ``rotate``, the variable for ``slice``,
    the parameter and its two ends for ``param``."""

    kind: str
    plane: tuple[int, int] | None = None
    sign: float = 1.0
    var: int | None = None
    param: str | None = None
    lo: float = 0.0
    hi: float = 0.0

    def describe(self, names) -> str:
        if self.kind == "param":
            return f"param:{self.param}={self.lo:g}:{self.hi:g}"
        if self.kind == "rotate":
            assert self.plane is not None   # (a rotation has its plane)
            i, j = self.plane
            a, b = (names[i], names[j]) if self.sign > 0 else (names[j], names[i])
            return f"rotate:{a}-{b}"
        if self.kind == "slice":
            return f"slice:{names[self.var]}"
        return "tour"


def parse_spec(text: str, names, params=()) -> Spec:
    """``rotate:I-J`` | ``tour`` | ``slice:VAR`` | ``param:NAME=FROM:TO`` -> :class:`Spec`; ValueError with a
    one-line message. ``params``: the parameter names of the formulas (what ``param`` may sweep)."""
    names = list(names)
    t = (text or "").strip()
    kind, _, arg = t.partition(":")
    kind = kind.strip().lower()
    arg = arg.strip()
    if kind == "tour":
        if arg:
            raise ValueError(f"'tour' takes no argument, got {text!r}")
        return Spec("tour")
    if kind == "rotate":
        parts = [p.strip() for p in arg.replace("\u2013", "-").split("-")] if arg else []
        if len(parts) != 2 or not all(parts):
            raise ValueError(f"rotate needs a plane of two variables, e.g. rotate:{'-'.join(names[-2:])}; got {text!r}")
        for p in parts:
            if p not in names:
                raise ValueError(f"unknown variable {p!r} in {text!r}; variables are {', '.join(names)}")
        a, b = names.index(parts[0]), names.index(parts[1])
        if a == b:
            raise ValueError(f"rotate needs two different variables, got {text!r}")
        return Spec("rotate", plane=(min(a, b), max(a, b)), sign=1.0 if a < b else -1.0)
    if kind == "slice":
        if arg not in names:
            raise ValueError(f"slice needs one of the variables {', '.join(names)}, e.g. slice:{names[-1]}; "
                             f"got {text!r}")
        return Spec("slice", var=names.index(arg))
    if kind == "param":
        return _parse_param(arg, text, list(params))
    raise ValueError(f"unknown animation {text!r}: use rotate:I-J, tour, slice:VAR or param:NAME=FROM:TO")


def _parse_param(arg: str, text: str, params: list) -> Spec:
    """``NAME=FROM:TO`` of a ``param`` spec; the ends are numbers or constant text (``-pi/2``)."""
    from gcmh_core.errors import InputError
    from gcmh_core.formula import evaluate_constant

    example = f"param:{params[0] if params else 'a'}=-1:1"
    name, eq, rng = arg.partition("=")
    name = name.strip()
    if not eq or not name:
        raise ValueError(f"param needs NAME=FROM:TO, e.g. {example}; got {text!r}")
    if not params:
        raise ValueError(f"these formulas have no parameter to sweep (got {text!r})")
    if name not in params:
        raise ValueError(f"unknown parameter {name!r} in {text!r}; the formulas' parameters are {', '.join(params)}")
    ends = rng.split(":")
    if len(ends) != 2 or not all(e.strip() for e in ends):
        raise ValueError(f"param needs a range FROM:TO, e.g. {example}; got {text!r}")
    try:
        lo, hi = (evaluate_constant(e) for e in ends)
    except InputError as err:
        raise ValueError(f"param {name}: {err}") from None
    if lo == hi:
        raise ValueError(f"param {name}: the range {lo:g}:{hi:g} is empty (FROM and TO must differ)")
    return Spec("param", param=name, lo=float(lo), hi=float(hi))


def plane_index(n: int, plane: tuple[int, int]) -> int:
    from .projection import planes

    return planes(n).index((plane[0], plane[1]))


def rotation_frames(angles0, row: int, frames: int, sign: float = 1.0, degrees: float = 360.0) -> list[Frame]:
    """``frames`` frames turning plane ``row`` once around from ``angles0`` (the last frame is not the first)."""
    _check_frames(frames)
    a0 = np.asarray(angles0, dtype=float)
    out = []
    for k in range(frames):
        a = a0.copy()
        a[row] = _wrap(a0[row] + sign * degrees * k / frames)
        out.append(Frame(angles=a))
    return out


def tour_angles(angles0, t, seed: int = 0, amplitude: float = TOUR_AMPLITUDE) -> np.ndarray:
    """The tour's angles (degrees) at times ``t`` (scalar or (T,)); period 1, equal to ``angles0`` at t = 0."""
    a0 = np.asarray(angles0, dtype=float)
    m = len(a0)
    rng = np.random.default_rng(seed)
    f = rng.integers(1, 3, size=m).astype(float)             # 1 or 2 turns per period
    phi = rng.uniform(0, 2 * np.pi, size=m)
    amp = amplitude * rng.uniform(0.6, 1.0, size=m)
    tt = np.atleast_1d(np.asarray(t, dtype=float))[:, None]
    a = a0 + amp * (np.sin(2 * np.pi * f * tt + phi) - np.sin(phi))
    a = _wrap(a)
    return a[0] if np.ndim(t) == 0 else a


def tour_frames(angles0, frames: int, seed: int = 0) -> list[Frame]:
    _check_frames(frames)
    A = tour_angles(angles0, np.arange(frames) / frames, seed)
    return [Frame(angles=A[k]) for k in range(frames)]


def slice_frames(lo: float, hi: float, frames: int) -> list[Frame]:
    """Centres sweeping ``lo -> hi -> lo`` with a cosine ease (slow at the ends)."""
    _check_frames(frames)
    t = np.arange(frames) / frames
    c = lo + (hi - lo) * 0.5 * (1 - np.cos(2 * np.pi * t))
    return [Frame(slice_center=float(x)) for x in c]


def param_frames(lo: float, hi: float, frames: int) -> list[Frame]:
    """``frames`` values from ``lo`` to ``hi``, evenly spaced, both ends included (one frame: ``lo``)."""
    _check_frames(frames)
    return [Frame(param_value=float(v)) for v in np.linspace(lo, hi, int(frames))]


def param_caption(name: str, value: float, step: float, chi: int, components: int) -> str:
    """The caption of a parameter sweep's frame: ``a = -0.50   chi = 2   2 components``.
    ``step``: the sweep's step, which sets the decimals shown (enough to tell two frames apart)."""
    digits = 2 if not step else min(6, max(2, int(np.ceil(-np.log10(abs(step))))))
    v = round(float(value), digits) + 0.0   # (+ 0.0: no "-0.00")
    if not components:
        return f"{name} = {v:.{digits}f}   empty (M misses the grid)"
    return (f"{name} = {v:.{digits}f}   chi = {int(chi)}   "
            f"{int(components)} component{'' if int(components) == 1 else 's'}")


def critical_note(name: str, singular: int) -> str:
    """The notice under a frame at a critical value (``meta["singular_vertices"]`` > 0), else ""."""
    if not singular:
        return ""
    return (f"critical value of {name}: M is singular (F's Jacobian nearly loses rank) at {int(singular):,} "
            f"vert{'ex' if int(singular) == 1 else 'ices'}")


def frames_for(spec: Spec, angles0, frames: int, slice_range=(0.0, 1.0), seed: int = 0) -> list[Frame]:
    """The frames of ``spec`` starting from the current angles (and the slice range for ``slice``)."""
    if spec.kind == "param":
        return param_frames(spec.lo, spec.hi, frames)
    n_planes = len(angles0)
    if spec.kind == "rotate":
        n = int(round((1 + np.sqrt(1 + 8 * n_planes)) / 2))
        assert spec.plane is not None   # (a rotation has its plane)
        return rotation_frames(angles0, plane_index(n, spec.plane), frames, spec.sign)
    if spec.kind == "tour":
        return tour_frames(angles0, frames, seed)
    return slice_frames(float(slice_range[0]), float(slice_range[1]), frames)


@dataclass
class Clock:
    """Where a playing animation is (the Animate tab's live play, not a file).

    ``t`` counts periods since the start and ``angles0`` are the angles the tour
    started from; each ``*_step(dt)`` advances by ``dt`` seconds (times the
    speed) and returns what to show next.
    """

    t: float = 0.0
    angles0: np.ndarray | None = None

    def start(self, angles, slice_centre: float | None = None) -> None:
        """A tour starts from the view on screen; a sweep from the slider's place (a fraction in [0, 1])."""
        self.t = 0.0
        self.angles0 = np.array(angles, dtype=float)
        if slice_centre is not None:   # the inverse of sweep_step's ease
            self.t = float(np.arccos(np.clip(1 - 2 * slice_centre, -1, 1)) / (2 * np.pi))

    @staticmethod
    def rotate_step(angles, row: int, dt: float) -> np.ndarray:
        """``angles`` with plane ``row`` turned by dt / ROTATE_PERIOD of a turn, wrapped to [-180, 180)."""
        a = np.array(angles, dtype=float)
        a[row] = (a[row] + 360.0 * dt / ROTATE_PERIOD + 180.0) % 360.0 - 180.0
        return a

    def tour_step(self, dt: float) -> np.ndarray:
        self.t += dt / TOUR_PERIOD
        return tour_angles(self.angles0, self.t)

    def sweep_step(self, dt: float, period: float = SLICE_PERIOD) -> float:
        """The slice centre (or a swept parameter) as a fraction of its range (cosine ease, as
        :func:`slice_frames`), there and back once per ``period`` seconds."""
        self.t += dt / period
        return float(0.5 * (1 - np.cos(2 * np.pi * self.t)))


# A parameter sweep's notice at a critical value (a colour of its own, kept exactly in a GIF)
CRITICAL_COLOUR = (0xff, 0x8a, 0x5c)
# Colours a GIF's palette keeps exactly: the title's white, the text greys of gcmh_studio.scene and the critical
# notice (text never recoloured)
RESERVED_COLOURS = ((255, 255, 255), (0xc8, 0xcf, 0xdc), (0xdf, 0xe4, 0xee), (0, 0, 0), CRITICAL_COLOUR)
PALETTE_PIXELS = 1_500_000  # pixels (from every frame) the GIF's adaptive palette is learnt from


def gif_palette(frames: list, reserved=RESERVED_COLOURS):
    """One adaptive palette for a whole animation (a PIL "P" image): 256 - len(reserved) colours learnt
    from about ``PALETTE_PIXELS`` pixels of all ``frames`` (h, w, 3) uint8, then the ``reserved`` colours.

    One palette for all frames: no colour flickers from frame to frame; learnt from this animation's
    pixels: its gradients get the fine steps (no banding) a fixed web palette lacks."""
    from PIL import Image

    tiles = []
    per = max(20_000, PALETTE_PIXELS // max(len(frames), 1))
    for fr in frames:
        f = np.asarray(fr)[..., :3]
        step = max(1, int(np.sqrt(f.shape[0] * f.shape[1] / per)))
        tiles.append(f[::step, ::step].reshape(-1, 3))
    mosaic = np.concatenate(tiles)
    budget = 256 - len(reserved)
    packed = (mosaic[:, 0].astype(np.int64) << 16) | (mosaic[:, 1].astype(np.int64) << 8) | mosaic[:, 2]
    keys, counts = np.unique(packed, return_counts=True)
    colours = np.stack([(keys >> 16) & 255, (keys >> 8) & 255, keys & 255], 1).astype(np.float64)
    if len(colours) <= budget:            # few colours (flat pictures): every one exactly
        learnt = colours
    else:
        side = int(np.ceil(np.sqrt(len(mosaic))))
        pad = np.zeros((side * side - len(mosaic), 3), np.uint8) + mosaic[:1]
        img = Image.fromarray(np.concatenate([mosaic, pad]).reshape(side, side, 3))
        q = img.quantize(colors=budget, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
        palette = q.getpalette()
        assert palette is not None   # (a quantized image has one)
        learnt = np.asarray(palette[: 3 * budget], dtype=np.float64).reshape(-1, 3)
        learnt = _lloyd(colours, counts.astype(np.float64), learnt)
    pal = [int(v) for v in np.clip(np.round(learnt), 0, 255).astype(np.int64).ravel()]
    pal += [0] * (3 * budget - len(pal))
    for c in reserved:
        pal += list(c)
    out = Image.new("P", (1, 1))
    out.putpalette(pal)
    return out


BACKGROUND_ENTRIES = 24   # palette entries kept for the background's gradient


def background_colours(frames: list, count: int = BACKGROUND_ENTRIES) -> tuple:
    """``count`` colours of the background, evenly spread along it: the distinct colours of the frames'
    left-most column (the gradient behind the object, from top to bottom), from darkest to lightest.

    A palette learnt from the pixels gives this large, smooth, low-contrast gradient only about ten entries
    (the shaded surface takes the rest): it banded, and dithered between entries that far apart its dots
    showed as a grainy stripe.  Kept entries a few levels apart, it is smooth either way."""
    edge = np.concatenate([np.asarray(f)[:, 0, :3] for f in frames])
    colours = np.unique(edge, axis=0)
    if len(colours) <= count:
        return tuple(tuple(int(v) for v in c) for c in colours)
    colours = colours[np.argsort(colours.astype(np.int64).sum(1), kind="stable")]
    picks = np.round(np.linspace(0, len(colours) - 1, count)).astype(int)
    return tuple(tuple(int(v) for v in colours[i]) for i in picks)


def _lloyd(colours: np.ndarray, weights: np.ndarray, centres: np.ndarray, steps: int = 4) -> np.ndarray:
    """A few weighted k-means steps on the distinct colours: the octree's palette moved to where the
    pixels are (the shaded surface gets its fine steps, the background no more than it needs)."""
    C = centres.copy()
    for _ in range(steps):
        lab = np.empty(len(colours), np.int64)
        for a in range(0, len(colours), 8192):   # (chunks: distances are colours x 250)
            X = colours[a:a + 8192]
            d = (X * X).sum(1)[:, None] - 2 * X @ C.T + (C * C).sum(1)[None]
            lab[a:a + 8192] = np.argmin(d, axis=1)
        w = np.bincount(lab, weights=weights, minlength=len(C))
        for j in range(3):
            s = np.bincount(lab, weights=weights * colours[:, j], minlength=len(C))
            C[:, j] = np.where(w > 0, s / np.maximum(w, 1e-12), C[:, j])
    return C


# Ordered dithering of a GIF's frames: the strength (in units of the palette's local spacing) and the
# lookup table's bits per channel.  Measured on 24-frame 800x600 rotations (Klein bottle, complex cosine):
# with the background's entries (background_colours), the error of 5x5-blurred frames (what the eye
# sees) fell from 1.19 / 1.09 to 0.70 / 0.67 grey levels and the per-pixel error from 1.54 / 1.39 to
# 1.33 / 1.15; the contour bands on the shaded surfaces and on the background went, the text stayed
# exact; the files grew from 0.84 / 0.75 MB to 1.64 / 1.66 MB, the mapping took a third of the time.
DITHER = 0.75
_LUT_BITS = 6


def _bayer(size: int = 8) -> np.ndarray:
    """The ordered-dither threshold matrix (size x size, size a power of 2), values in (-1/2, 1/2)."""
    m = np.zeros((1, 1), np.int64)
    while m.shape[0] < size:
        m = np.block([[4 * m, 4 * m + 2], [4 * m + 3, 4 * m + 1]])
    return (m + 0.5) / m.size - 0.5


class _PaletteMap:
    """Maps frames onto one GIF palette (a PIL "P" image): colours the palette holds exactly (the text's,
    the background's) map to themselves, undithered, so text stays crisp; every other pixel is dithered
    (an 8x8 Bayer matrix, mirrored differently for R, G and B so hues mix too, the same in every frame so
    nothing flickers) by about the palette's spacing near its colour, so a shaded surface's gradient
    comes out smooth, not in bands of one colour each.
    Nearest colours come from a lookup table of 2^(3 * _LUT_BITS) cells, built once per animation."""

    def __init__(self, palette, strength: float = DITHER):
        self.entries = palette.getpalette()[:768]
        P = np.asarray(self.entries, dtype=np.float64).reshape(-1, 3)
        step = 256 >> _LUT_BITS
        g = np.arange(0, 256, step) + (step - 1) / 2.0
        X = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
        PP = (P * P).sum(1)
        lut = np.empty(len(X), np.uint8)
        for a in range(0, len(X), 32768):   # (the first of equal entries: the twin stays unused)
            lut[a:a + 32768] = np.argmin(PP[None] - 2 * X[a:a + 32768] @ P.T, axis=1)
        self.lut = lut.reshape(len(g), len(g), len(g))
        d = ((P[:, None] - P[None]) ** 2).sum(-1)
        np.fill_diagonal(d, np.inf)
        self.amplitude = strength * np.sqrt(d.min(1))   # (0 at a twin entry: white's twin, padding)
        keys = (P[:, 0].astype(np.int64) << 16) | (P[:, 1].astype(np.int64) << 8) | P[:, 2].astype(np.int64)
        self.order = np.argsort(keys, kind="stable")
        self.keys = keys[self.order]

    def indices(self, img) -> np.ndarray:
        """(h, w) uint8: each pixel's palette index (exact, or dithered as the class says)."""
        f = np.ascontiguousarray(np.asarray(img)[..., :3])
        h, w = f.shape[:2]
        shift = 8 - _LUT_BITS
        packed = (f[..., 0].astype(np.int64) << 16) | (f[..., 1].astype(np.int64) << 8) | f[..., 2]
        pos = np.minimum(np.searchsorted(self.keys, packed), len(self.keys) - 1)
        exact = self.keys[pos] == packed
        near = self.lut[f[..., 0] >> shift, f[..., 1] >> shift, f[..., 2] >> shift]
        b = _bayer(8)
        t = np.stack([np.tile(m, (h // 8 + 1, w // 8 + 1))[:h, :w] for m in (b, b[::-1], b[:, ::-1])], -1)
        g = np.clip(f + t * self.amplitude[near][..., None], 0, 255).astype(np.int64) >> shift
        return np.where(exact, self.order[pos], self.lut[g[..., 0], g[..., 1], g[..., 2]]).astype(np.uint8)

    def frame(self, img):
        from PIL import Image

        out = Image.fromarray(self.indices(img), mode="P")
        out.putpalette(self.entries)
        return out


# The palette entry no pixel takes (a twin of white, the last entry): in every frame after the first it marks
# the pixels that kept their colour, transparent over the frame before (GIF disposal 1, "leave in place")
UNCHANGED = 255


def frame_differences(indices: list) -> list:
    """The (h, w) uint8 index frames with each pixel equal to the one before it in the frame before set to
    ``UNCHANGED`` (the first frame whole).  A still background then codes as one long run of one index (LZW
    squeezes it to almost nothing) and the encoder crops each frame to what changed.

    A frame that changes nothing keeps the top-left pixel's own index, or ``UNCHANGED`` when the frame
    before kept it, so no two frames in a row are equal (PIL would merge them: one frame fewer than asked)."""
    out = [indices[0]]
    for prev, cur in zip(indices, indices[1:]):
        d = np.where(cur == prev, np.uint8(UNCHANGED), cur)
        if not np.any(d != UNCHANGED):
            d[0, 0] = cur[0, 0] if out[-1][0, 0] == UNCHANGED else UNCHANGED
        out.append(d)
    return out


def write_gif(path, images, fps: float = 20.0, progress=None, cancel=None, dither: float = DITHER) -> int:
    """Write the images to a looping GIF with one adaptive palette (:func:`gif_palette`), ordered-dithered
    where it lacks a colour (:class:`_PaletteMap`), each frame after the first only what changed
    (:func:`frame_differences`); returns the count.

    The palette needs a look at the frames, so they are all held (a 60-frame 1280x720 animation is 166 MB).
    ``dither``: the dither's strength (:data:`DITHER`; 0: none).
    ``cancel()`` true: nothing is written, the frames made so far are counted."""
    from PIL import Image

    frames: list[np.ndarray] = []
    for img in images:
        if cancel is not None and cancel():
            return len(frames)
        frames.append(np.ascontiguousarray(np.asarray(img)[..., :3]))
        if progress is not None:
            progress(len(frames))
    if not frames:
        raise ValueError("no frames to write")
    # the last entry repeats white, so no pixel maps to it (the first of equal entries wins): UNCHANGED
    pal = gif_palette(frames, RESERVED_COLOURS + background_colours(frames) + (RESERVED_COLOURS[0],))
    mapper = _PaletteMap(pal, dither)
    pics = []
    for d in frame_differences([mapper.indices(f) for f in frames]):
        pic = Image.fromarray(d, mode="P")
        pic.putpalette(mapper.entries)
        pics.append(pic)
    pics[0].save(str(path), save_all=True, append_images=pics[1:], duration=int(round(1000.0 / fps)), loop=0,
                 optimize=False, disposal=1, transparency=UNCHANGED)
    return len(pics)


def write_animation(path, images, fps: float = 20.0, progress=None, cancel=None) -> int:
    """Write the (h, w, 3) uint8 images (any iterable) to ``path`` (.gif or .mp4); returns the frame count.

    ``progress(k)`` is called after frame k; ``cancel()`` true stops and removes the file
    (returns the frames written so far, the file is gone). GIFs get one adaptive palette for the
    whole animation with the text colours kept (:func:`write_gif`); MP4 is smaller and smoother.
    """
    import os

    import imageio.v2 as imageio

    path = str(path)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".gif":
        return write_gif(path, images, fps=fps, progress=progress, cancel=cancel)
    if ext == ".mp4":
        # yuv420p needs even sides; macro_block_size=2 pads to them instead of 16
        writer = imageio.get_writer(path, fps=fps, codec="libx264", quality=7, macro_block_size=2,
                                    pixelformat="yuv420p", ffmpeg_log_level="error")
    else:
        raise ValueError(f"unknown animation format {ext!r}: use .gif or .mp4")
    k = 0
    stopped = False
    try:
        for img in images:
            if cancel is not None and cancel():
                stopped = True
                break
            writer.append_data(np.ascontiguousarray(np.asarray(img)[..., :3]))
            k += 1
            if progress is not None:
                progress(k)
    finally:
        writer.close()
        if stopped:
            try:
                os.remove(path)
            except OSError:
                pass
    return k


def _check_frames(frames: int) -> None:
    if int(frames) < 1:
        raise ValueError(f"frames must be at least 1, got {frames}")


def _wrap(a):
    """Angles to [-180, 180)."""
    return (np.asarray(a, dtype=float) + 180.0) % 360.0 - 180.0
