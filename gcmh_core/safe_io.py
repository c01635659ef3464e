"""Writing output files without clobbering anything: checked first, replaced atomically.

* `check_output(path)` before any work: the folder exists and is writable, the path
  is not a folder; a symlink is followed (its target is written, the link stays); a
  device, FIFO or socket is refused, never replaced; a read-only file is refused.
* `AtomicFile`: the content goes to a temporary file beside the target, which
  replaces it by `os.replace` only when complete (so a reader, a crash or Ctrl-C
  sees the old file or the new one, never half of one).  The temporary is removed
  on any exception, KeyboardInterrupt included.  A new file gets the usual mode
  (0666 minus the umask); a replaced one keeps its mode.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable

from .errors import InputError

__all__ = ["check_output", "AtomicFile", "atomic_write", "default_mode"]

_KINDS = {
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFIFO: "a FIFO (named pipe)",
    stat.S_IFSOCK: "a socket",
}


def default_mode() -> int:
    """0666 minus the process's umask (read from /proc: os.umask would change it)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # (not thread-safe, hence only as a fallback)
    os.umask(mask)
    return 0o666 & ~mask


def check_output(path, what: str = "output") -> str:
    """The file to write for `path` (a symlink's target), or InputError saying why not."""
    try:
        text = os.fspath(path)
    except TypeError:
        raise InputError(f"{what}: expected a file name, got {path!r}") from None
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if not text:
        raise InputError(f"{what}: empty file name")
    target = os.path.realpath(text) if os.path.islink(text) else text
    try:
        st = os.stat(target)
    except (FileNotFoundError, NotADirectoryError):  # (the folder is checked below)
        st = None
    except OSError as err:
        raise InputError(f"{what}: cannot use {text!r}: {err.strerror}") from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise InputError(f"{what}: {text!r} is a folder, not a file name")
        if not stat.S_ISREG(st.st_mode):
            kind = _KINDS.get(stat.S_IFMT(st.st_mode), "not a regular file")
            raise InputError(f"{what}: {text!r} is {kind}; only regular files are written (it is left as it is)")
        if not os.access(target, os.W_OK):
            raise InputError(f"{what}: {text!r} is read-only")
    folder = os.path.dirname(target) or "."
    if not os.path.isdir(folder):
        why = "is not a folder" if os.path.exists(folder) else "does not exist"
        raise InputError(f"{what}: folder {folder!r} {why}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{what}: folder {folder!r} is not writable")
    return target


class AtomicFile:
    """A temporary file beside `path` that becomes `path` on `commit()`.

    Use::

        out = AtomicFile("result.npz")      # checks the path (InputError)
        try:
            write(out.temp)                   # any writer taking a file name
            out.commit()
        finally:
            out.discard()                     # no-op after commit
    """

    def __init__(self, path, suffix: str = "", what: str = "output"):
        self.path = os.fspath(path)
        self.target = check_output(path, what)
        folder = os.path.dirname(self.target) or "."
        name = os.path.basename(self.target)
        fd, self.temp = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=f".tmp{suffix}")
        os.close(fd)
        self.done = False

    def commit(self) -> None:
        """Flush the temporary to disk, give it the target's mode and move it into place."""
        try:
            mode = stat.S_IMODE(os.stat(self.target).st_mode)
        except FileNotFoundError:
            mode = default_mode()
        os.chmod(self.temp, mode)
        fd = os.open(self.temp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(self.temp, self.target)
        self.done = True

    def discard(self) -> None:
        if not self.done:
            self.done = True
            try:
                os.unlink(self.temp)
            except FileNotFoundError:
                pass

    def __enter__(self) -> AtomicFile:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None and not self.done:
            self.commit()
        self.discard()


def atomic_write(path, write: Callable[[str], None], suffix: str = "", what: str = "output") -> str:
    """write(temporary file name), then replace `path` by it; returns the file written."""
    with AtomicFile(path, suffix, what) as out:
        write(out.temp)
    return out.target
