"""Draw the gallery thumbnails: ``python -m gcmh_studio.make_gallery [NAME ...]``.

For every example (or the ones named) this runs the headless screenshot code
of ``gcmh-app --example NAME --screenshot`` (:func:`gcmh_studio.headless.render`) at
twice the thumbnail size and scales the picture down (the overlay text then
fits and the edges are smooth), writing ``app/resources/gallery/<name>.png``
(package data: the gallery ships with the app).  A thumbnail that would be
over ``MAX_BYTES`` is stored with a 256-colour palette instead.

    python -m gcmh_studio.make_gallery                      # all examples
    python -m gcmh_studio.make_gallery sphere torus         # just these
    python -m gcmh_studio.make_gallery --size 320x240 --out /tmp/gallery
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from importlib.resources import files
from pathlib import Path

from .headless import Options, parse_size, prepare_env, render

SIZE = (320, 240)
SUPERSAMPLE = 2
MAX_BYTES = 100_000


def gallery_files():
    """The thumbnails as package data (an importlib.resources Traversable): what the gallery reads."""
    return files("app") / "resources" / "gallery"


def gallery_dir() -> Path:
    """The thumbnails' folder on disk, ``app/resources/gallery`` in the package: where they are written."""
    return Path(str(gallery_files()))


def thumbnail_path(name: str, folder: Path | None = None) -> Path:
    """Where the thumbnail of example ``name`` lives."""
    return (folder or gallery_dir()) / f"{name}.png"


def _shrink(src: str, dst: Path, size: tuple[int, int]) -> int:
    """Scale the PNG at src to size, write it to dst; returns the file size in bytes."""
    from PIL import Image

    with Image.open(src) as im:
        small = im.convert("RGB").resize(size, Image.LANCZOS)
    small.save(dst, optimize=True)
    if dst.stat().st_size > MAX_BYTES:  # photographic shading compresses badly: use a palette
        small.quantize(colors=256, method=Image.MEDIANCUT, dither=Image.NONE).save(dst, optimize=True)
    return dst.stat().st_size


def make_thumbnail(name: str, out: Path, size: tuple[int, int] = SIZE) -> int:
    """Render example ``name`` off screen and write its thumbnail; returns the byte size.

    Raises RuntimeError if the screenshot command fails.
    """
    w, h = size
    with tempfile.TemporaryDirectory() as tmp:
        big = os.path.join(tmp, f"{name}.png")
        status = render(Options(example=name, screenshot=big, size=(SUPERSAMPLE * w, SUPERSAMPLE * h)))
        if status != 0 or not os.path.isfile(big):
            raise RuntimeError(f"screenshot of {name!r} failed (status {status})")
        return _shrink(big, out, size)


def main(argv=None) -> int:
    from gcmh_core.examples import example_names

    p = argparse.ArgumentParser(prog="python -m gcmh_studio.make_gallery", description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", metavar="NAME", help="examples to draw (default: all)")
    p.add_argument("--out", type=Path, default=None, help="output folder (default: app/resources/gallery)")
    p.add_argument("--size", type=parse_size, default=SIZE, metavar="WxH", help="thumbnail size (default 320x240)")
    args = p.parse_args(argv)
    prepare_env()
    known = example_names()
    names = args.names or known
    unknown = [n for n in names if n not in known]
    if unknown:
        print(f"make_gallery: unknown example(s) {', '.join(unknown)}; known: {', '.join(known)}", file=sys.stderr)
        return 2
    out = args.out or gallery_dir()
    out.mkdir(parents=True, exist_ok=True)
    failed = []
    for name in names:
        try:
            nbytes = make_thumbnail(name, thumbnail_path(name, out), args.size)
        except RuntimeError as err:
            print(f"make_gallery: {err}", file=sys.stderr)
            failed.append(name)
            continue
        print(f"{thumbnail_path(name, out)}: {nbytes // 1024} KB")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
