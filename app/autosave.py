"""The window's session saved as it goes, so that a crash mid-lesson loses little: a restart offers it back.

Each running window process writes its session (:func:`gcmh_studio.studio_io.session_dict`) to
``autosave-<pid>.json`` in the user's state folder (``$GCMH_STATE_DIR``, else ``$XDG_STATE_HOME/gcmh-studio``,
else ``~/.local/state/gcmh-studio``), atomically, after each run and every :data:`PERIOD_MS`; a clean exit
removes it. A file whose process is gone is what a crash left: :func:`recoverable` finds the newest such file
that still opens (checked whole, as any session), and the window offers it. No Qt here: the window's timer,
its run signal and its question are the caller's (:mod:`gcmh_studio.__main__`).
"""

from __future__ import annotations

import os
from pathlib import Path

PERIOD_MS = 60_000          # how often the session is saved while the window is open
KEEP = 5                    # crashed sessions kept (the oldest go)


def state_dir() -> Path:
    """The folder of the autosaved sessions (made when first written)."""
    if os.environ.get("GCMH_STATE_DIR"):
        return Path(os.environ["GCMH_STATE_DIR"])
    base = os.environ.get("XDG_STATE_HOME") or os.path.join(os.path.expanduser("~"), ".local", "state")
    return Path(base) / "gcmh-studio"


def own_path(pid: int | None = None) -> Path:
    return state_dir() / f"autosave-{os.getpid() if pid is None else pid}.json"


def save(session: dict) -> Path | None:
    """Write ``session`` as this process's autosave (atomically: a crash mid-write leaves the previous one);
    None, silently, when it cannot be written or is not a session that would open again (an autosave must
    never take the window down or interrupt a lesson)."""
    from .session_schema import validate_session
    from .studio_io import write_session

    try:
        validate_session(session)
        folder = state_dir()
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        return write_session(own_path(), session)
    except (OSError, ValueError):
        return None


def discard() -> None:
    """A clean exit: this process's autosave goes."""
    try:
        own_path().unlink()
    except OSError:
        pass


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:   # (another user's process)
        return True
    return True


def _left_behind() -> list[Path]:
    """Autosaves of processes that are gone, newest first."""
    folder = state_dir()
    try:
        files = list(folder.glob("autosave-*.json"))
    except OSError:
        return []
    out = []
    for f in files:
        try:
            pid = int(f.stem.split("-", 1)[1])
        except ValueError:
            continue
        if pid != os.getpid() and not _alive(pid):
            out.append(f)
    return sorted(out, key=lambda f: f.stat().st_mtime if f.exists() else 0.0, reverse=True)


def recoverable() -> Path | None:
    """The newest autosave a crashed window left that opens (checked whole); files that do not open are
    removed, and all but the newest :data:`KEEP` crashed ones."""
    from .studio_io import read_session

    found = None
    for i, f in enumerate(_left_behind()):
        if found is None:
            try:
                read_session(f)
                found = f
                continue
            except (OSError, ValueError):
                pass
        if found is None or i >= KEEP:
            try:
                f.unlink()
            except OSError:
                pass
    return found


def restored(path: Path) -> None:
    """The user answered the offer of ``path`` (restored or not): it is not offered again."""
    try:
        Path(path).unlink()
    except OSError:
        pass
