"""Fixtures both suites use (tests/core and tests/app)."""

import os
import subprocess

import pytest


@pytest.fixture
def full_disk(tmp_path):
    """A 64 kB tmpfs (root, where mount is permitted), empty; `fill_disk` fills it."""
    d = tmp_path / "small"
    d.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(d)], capture_output=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {r.stderr.decode().strip()}")
    try:
        yield d
    finally:
        subprocess.run(["umount", str(d)], check=False)


@pytest.fixture
def fill_disk():
    """fill(d, leave=0): write d/ballast until the disk is full, then give back ``leave`` bytes."""
    def fill(d, leave: int = 0) -> None:
        fd = os.open(d / "ballast", os.O_WRONLY | os.O_CREAT)
        try:
            while True:
                os.write(fd, b"\0" * 4096)
        except OSError:
            pass
        finally:
            os.close(fd)
        if leave:
            os.truncate(d / "ballast", max(0, os.path.getsize(d / "ballast") - leave))
    return fill
