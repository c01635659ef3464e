"""gcmh-app --screenshot/--gif/--mp4: outputs checked before any work, written atomically.

Issue 15: a missing folder was found only after the render (with a traceback), a FIFO
was written into, and an interrupted write could leave half a file.
"""

import os
import stat
import subprocess
import sys

import pytest
from PIL import Image

from app_helpers import app_in_process

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _app(*args, timeout=300):
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-m", "gcmh_studio", *args], cwd=REPO, env=env, capture_output=True,
                          text=True, timeout=timeout)


def _one_line_refusal(r):
    assert r.returncode == 2, r.stderr
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    return lines[0]


@pytest.mark.parametrize("flag", ["--screenshot", "--gif", "--mp4"])
def test_missing_folder_is_refused_before_the_run(tmp_path, flag, capsys, monkeypatch):
    from gcmh_studio import jobs

    def no_run(*args, **kwargs):
        raise AssertionError("extracted before the refusal")

    monkeypatch.setattr(jobs, "run_job", no_run)
    target = tmp_path / "nodir" / ("x.png" if flag == "--screenshot" else "x" + flag.replace("--", "."))
    extra = [] if flag == "--screenshot" else ["--animate", "tour", "--frames", "2"]
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "sphere", "--div", "6", flag, str(target),
                                  *extra)
    assert "does not exist" in _one_line_refusal(subprocess.CompletedProcess([], code, "", err))
    assert not (tmp_path / "nodir").exists()


def test_a_fifo_is_left_as_it_is(tmp_path):
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    r = _app("--example", "sphere", "--div", "6", "--screenshot", str(fifo))
    assert "FIFO" in _one_line_refusal(r)
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_a_screenshot_replaces_the_old_file_whole_and_keeps_its_mode(tmp_path):
    out = tmp_path / "shot.png"
    out.write_bytes(b"old")
    os.chmod(out, 0o640)
    r = _app("--example", "sphere", "--div", "6", "--screenshot", str(out), "--size", "160x120")
    assert r.returncode == 0, r.stderr
    assert Image.open(out).size == (160, 120)
    assert stat.S_IMODE(os.stat(out).st_mode) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shot.png"]  # no temporary left
