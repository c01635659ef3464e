"""The data files the window opened lately, remembered for the gallery: each source's entry (its files by
path, levels, box: :meth:`gcmh_studio.data_source.DataSource.session_entry`), its title and a small picture
of its isosurface.

Kept in ``recent-data.json`` in the user's state folder (:func:`gcmh_studio.autosave.state_dir`), newest
first, at most :data:`KEEP` sources; the pictures beside it in ``recent-data/``.  Reading never fails: a
missing, unreadable or hand-broken file is no sources (each entry is checked as a session's data entry is,
:func:`gcmh_studio.session_schema.data_entry`, and one that is not usable is left out).  No Qt here.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from .autosave import state_dir
from .make_gallery import SIZE as PICTURE_SIZE  # (as the examples' thumbnails)

KEEP = 12                    # sources remembered (the oldest go)
RECENT_FILE = "recent-data.json"
PICTURES = "recent-data"


def recent_path() -> Path:
    return state_dir() / RECENT_FILE


def _key(files) -> str:
    return hashlib.sha1("\n".join(map(str, files)).encode("utf-8")).hexdigest()[:16]


def picture_path(files) -> Path:
    """Where the picture of the source with these files is kept."""
    return state_dir() / PICTURES / f"{_key(files)}.png"


def recent() -> list[dict]:
    """The remembered sources, newest first: {"entry": {...}, "title": str, "picture": path or None}."""
    from .session_schema import MAX_TITLE, SessionError, data_entry

    try:
        with open(recent_path(), "rb") as f:
            items = json.loads(f.read(1 << 20).decode("utf-8"))
    except (OSError, ValueError, RecursionError):
        return []
    out = []
    for item in items if isinstance(items, list) else []:
        try:
            entry = data_entry(item.get("entry")) if isinstance(item, dict) else None
        except SessionError:
            continue
        title = item.get("title")
        if entry is None or not isinstance(title, str) or len(title) > MAX_TITLE:
            continue
        picture = picture_path(entry["files"])
        out.append({"entry": entry, "title": title, "picture": picture if picture.is_file() else None})
    return out[:KEEP]


def remember(entry: dict, title: str, picture=None) -> bool:
    """Put a source first among the remembered ones (the same files once: their latest levels), with its
    picture ((h, w, 3) uint8, shrunk to PICTURE_SIZE) when given.  False, silently, when it cannot be
    written (remembering must never interrupt the work)."""
    from gcmh_core.safe_io import atomic_write

    items = [{"entry": r["entry"], "title": r["title"]} for r in recent() if r["entry"]["files"] != entry["files"]]
    items = [{"entry": entry, "title": str(title)}] + items
    for gone in items[KEEP:]:
        picture_path(gone["entry"]["files"]).unlink(missing_ok=True)
    text = json.dumps(items[:KEEP], indent=1, allow_nan=False) + "\n"
    try:
        state_dir().mkdir(parents=True, exist_ok=True, mode=0o700)
        def write(tmp: str) -> None:
            Path(tmp).write_text(text, encoding="utf-8")

        atomic_write(recent_path(), write, ".json", what=str(recent_path()))
        if picture is not None:
            _save_picture(picture, picture_path(entry["files"]))
    except (OSError, ValueError):
        return False
    return True


def _save_picture(rgb, path: Path) -> None:
    """The picture cropped to the thumbnails' aspect about its middle, shrunk and written as PNG."""
    from PIL import Image

    im = Image.fromarray(rgb[..., :3])
    w, h = im.size
    tw, th = PICTURE_SIZE
    if w * th > h * tw:   # wider than 4:3: keep the middle
        cw = h * tw // th
        im = im.crop(((w - cw) // 2, 0, (w - cw) // 2 + cw, h))
    else:
        ch = w * th // tw
        im = im.crop((0, (h - ch) // 2, w, (h - ch) // 2 + ch))
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    im.resize(PICTURE_SIZE, Image.Resampling.LANCZOS).save(path)
