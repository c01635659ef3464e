"""GCMH Studio: ``gcmh-app`` / ``python -m gcmh_studio``.

    gcmh-app                                   # the window, opening on the Klein bottle
    gcmh-app --example complex-cosine          # the window, opening on another example
    gcmh-app --session my.json                 # the window, restoring a saved session
    gcmh-app --example klein-bottle --screenshot klein.png --size 1600x1200 [--div 30]
                                               # no window: extract, render off screen, write the PNG
    gcmh-app --example klein-bottle --animate rotate:s-t --frames 60 --gif klein.gif [--mp4 klein.mp4]
    gcmh-app --example clifford-torus --mapping stereographic --animate tour --mp4 tour.mp4
    gcmh-app --example klein-bottle --animate slice:s --slice-width 0.2 --gif sweep.gif
                                               # no window: an animation as GIF and/or MP4
    gcmh-app --example hyperboloid --animate param:a=-1:1 --frames 24 --gif a.gif [--mp4 a.mp4]
                                               # a parameter sweep: one extraction per frame, one camera,
                                               # each frame captioned with the value and chi
    gcmh-app --example hyperboloid --param a=-0.3 --screenshot two-sheets.png
                                               # a parameter's value (repeatable; default: the example's)

Sizes and frame counts are checked first (``gcmh_core.budget.check_image_size`` /
``check_frames``): what the renderer cannot draw is refused with its limit (exit 2).
Ctrl-C in a mode without a window ends with one line and exit status 130.
"""

from __future__ import annotations

import os
import signal
import sys
import threading


def _interrupted(signum, frame) -> None:
    """Ctrl-C (130) or SIGTERM (143), at any moment: one line and out. (A KeyboardInterrupt raised inside
    VTK's rendering crashes the process, and one raised in an import prints a traceback.)"""
    try:
        sys.stderr.write("gcmh-app: interrupted\n" if signum == signal.SIGINT else "gcmh-app: terminated\n")
        sys.stderr.flush()
    finally:
        os._exit(128 + signum)


def install_interrupt_handlers() -> None:
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, _interrupted)


if __name__ == "__main__":   # python -m gcmh_studio: before the imports below (gcmh-app: main() installs them)
    install_interrupt_handlers()

import argparse  # noqa: E402

from .headless import Options, default_size, fail, parse_size, prepare_env, render  # noqa: E402


def _div(text: str):
    try:
        parts = [int(p) for p in text.replace(",", " ").split()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"div must be an integer or a comma-separated list, got {text!r}") from None
    if not parts or min(parts) < 1:
        raise argparse.ArgumentTypeError("div must be at least 1")
    return parts[0] if len(parts) == 1 else parts


def build_parser() -> argparse.ArgumentParser:
    from .projection import MAPPINGS

    p = argparse.ArgumentParser(prog="gcmh-app", description="GCMH Studio: see implicit manifolds of any dimension.")
    p.add_argument("--example", metavar="NAME", help="open this example (see --list)")
    p.add_argument("--session", metavar="FILE", help="open a saved session (.json)")
    p.add_argument("--list", action="store_true", help="list the examples and exit")
    p.add_argument("--screenshot", metavar="PNG", help="render without a window, write this PNG and exit")
    p.add_argument("--size", type=parse_size, default=None, metavar="WxH",
                   help="picture size (default 1600x1200 for a screenshot, 960x540 for an animation)")
    p.add_argument("--div", type=_div, metavar="N", help="override the example's grid divisions (N or N1,N2,...)")
    p.add_argument("--seed", type=int, default=0, help="grid perturbation seed (default 0)")
    p.add_argument("--param", dest="params", action="append", default=[], metavar="NAME=VALUE",
                   help="value of a parameter of the example's formulas (repeatable), e.g. --param a=-0.3 "
                        "or --param 'c=pi/4'; default: the example's")
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
                   help="no window: render an animation, SPEC = rotate:I-J | tour | slice:VAR | param:NAME=FROM:TO "
                        "(a parameter sweep, e.g. param:a=-1:1; needs --gif/--mp4)")
    p.add_argument("--frames", type=int, default=60, help="animation frames (default 60)")
    p.add_argument("--fps", type=float, default=20.0, help="animation frames per second (default 20)")
    p.add_argument("--gif", metavar="FILE", help="write the animation as a GIF")
    p.add_argument("--mp4", metavar="FILE", help="write the animation as an MP4 (H.264)")
    return p


def _session_screenshot(args) -> int:
    """A screenshot of a saved session: restoring its view needs the panels, so the window's own code runs,
    unshown (every other screenshot is drawn without Qt, by gcmh_studio.headless)."""
    from qtpy.QtCore import QEventLoop, QTimer
    from qtpy.QtWidgets import QApplication

    from .qt_main_window import QtMainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])  # noqa: F841 - kept alive while the window lives
    win = QtMainWindow(example=None)
    loop = QEventLoop()
    outcome = {}

    def finished(how):
        outcome["how"] = how
        QTimer.singleShot(0, loop.quit)

    win.runFinished.connect(finished)
    from . import data_source

    if data_source.session_data(args.session) is not None:   # data files: the Data tab's run, at full grid
        win.data_panel.shown.connect(lambda step: finished("done") if step == "full" else None)
        win.data_panel.failed.connect(lambda message: finished("failed"))
        if not win.open_file(args.session):
            win.close()
            return fail(f"{args.session}: {win.last_status}")
    # (a system the panel finds invalid starts no run: waiting for its end would never end)
    elif not win.controller.open_session(args.session) or not win.controller.is_running():
        status = win.last_status or "the session's system cannot run"
        win.close()
        return fail(f"{args.session}: {status}")
    loop.exec_()
    if outcome.get("how") != "done":
        status = win.last_status or f"the run {outcome.get('how', 'ended')}"
        win.close()
        return fail(f"{args.session}: {status}", 1)
    win.save_screenshot(args.screenshot, size=args.size, transparent=args.transparent)
    print(args.screenshot)
    win.close()
    return 0


def check_output_size(args) -> str | None:
    """Why the renderer cannot make what ``args`` asks for (size, frames), or None."""
    from gcmh_core import budget
    from gcmh_core.errors import InputError

    try:
        if args.animate:
            budget.check_frames(args.frames, *args.size)
        elif args.screenshot or args.window_screenshot:
            budget.check_image_size(*args.size)
    except InputError as e:
        return f"--size {args.size[0]}x{args.size[1]}" + (f" --frames {args.frames}" if args.animate else "") + \
            f": {e}"
    return None


def main(argv=None) -> int:
    install_interrupt_handlers()
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        return _main(argv)
    except KeyboardInterrupt:
        print("gcmh-app: interrupted", file=sys.stderr)
        return 130
    except OSError as e:   # a full disk, a folder gone: the writers leave the old file and no temporary
        return fail(f"cannot write {_written_name(e, argv)}: {e.strerror or e}", 1)


def _written_name(e: OSError, argv) -> str:
    """The file an OSError names, as the user gave it (not the hidden temporary beside it); else the outputs
    the command line named."""
    import re

    name = os.path.basename(str(e.filename or ""))
    real = re.fullmatch(r"\.(.+)\.[A-Za-z0-9_]{8}\.tmp(\.\w+)?", name)   # (safe_io.AtomicFile's temporaries)
    if real:
        name = real.group(1)
    if name:
        return repr(name)
    outs = [argv[i + 1] for i, a in enumerate(argv[:-1]) if a in ("--screenshot", "--gif", "--mp4")]
    return " or ".join(repr(o) for o in outs) or "the output"


def read_session_or_fail(path):
    """The session in ``path`` checked whole (:func:`gcmh_studio.studio_io.read_session`), or the one-line
    message saying why it cannot be opened."""
    from .studio_io import read_session

    try:
        return read_session(path), None
    except (OSError, ValueError) as e:
        return None, f"cannot open {path}: {e.strerror if isinstance(e, OSError) and e.strerror else e}"


def keep_autosaving(app, win, offer: bool = True) -> None:
    """Save the window's session after each run and every minute (:mod:`gcmh_studio.autosave`), remove it on a
    clean exit; with ``offer``, offer back the session a crashed window left (a question that does not block)."""
    from qtpy.QtCore import QTimer
    from qtpy.QtWidgets import QMessageBox

    from . import autosave

    def save(*_):
        try:
            autosave.save(win.session())   # (with the data files, when they are what is shown)
        except Exception:  # noqa: BLE001 - an autosave never interrupts the lesson
            pass

    timer = QTimer(win)
    timer.setInterval(autosave.PERIOD_MS)
    timer.timeout.connect(save)
    timer.start()
    win.runFinished.connect(lambda how: save() if how == "done" else None)
    app.aboutToQuit.connect(autosave.discard)
    found = autosave.recoverable() if offer else None
    if found is None:
        return
    import time

    when = time.strftime("%H:%M on %d %b", time.localtime(found.stat().st_mtime))
    box = QMessageBox(QMessageBox.Question, "Restore the last session?",
                      f"GCMH Studio did not close cleanly last time. Restore the session it was showing "
                      f"(saved at {when})?", QMessageBox.Yes | QMessageBox.No, win)

    def answered(button):
        if box.standardButton(button) != QMessageBox.Yes:
            autosave.restored(found)
            return

        def open_it(*_):
            win.open_file(found)   # (checked whole again: a bad file is said, not opened; data files reopened)
            autosave.restored(found)

        if win.controller.is_running():   # the example the window opened on: its run is cancelled first
            _once(win.runFinished, open_it)
            win.controller.cancel()
        else:
            open_it()

    box.buttonClicked.connect(answered)
    box.open()
    win.autosave_offer = box


def _once(signal, slot) -> None:
    """Connect ``slot`` to ``signal`` for its next emission only."""
    def call(*args):
        signal.disconnect(call)
        slot(*args)

    signal.connect(call)


def list_examples_or_warn() -> list:
    """The examples that can be read; each that cannot is named on stderr (one line each)."""
    from gcmh_core.examples import list_examples

    return list_examples(on_error=lambda name, err: print(f"gcmh-app: warning: example {name!r} left out: {err}",
                                                         file=sys.stderr))


# What a session file holds itself (system, grid, method, view): given beside --session, it would be ignored.
_SESSION_HOLDS = ("example", "div", "seed", "params", "method", "color", "project", "rotate", "mapping", "distance",
                  "slice", "slice_width", "two_sided", "boundary", "animate")


def _session_clash(args) -> str | None:
    """Why the options beside ``--session`` can't be honoured, or None: a session brings its own system and
    view, and a picture that silently leaves out a --slice asked for misleads."""
    if not args.session:
        return None
    defaults = build_parser()
    given = [name for name in _SESSION_HOLDS if getattr(args, name) != defaults.get_default(name)]
    if not given:
        return None
    flags = ", ".join("--" + name.replace("_", "-") for name in given)
    return (f"{flags} cannot go with --session: the session holds its own system and view (open it in the "
            "window, change it there and save it)")


def _main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if args.size is None:  # an animation's default is a slide's (headless.ANIMATION_SIZE)
        args.size = default_size(bool(args.animate))
    prepare_env()
    problem = check_output_size(args)
    if problem:
        return fail(problem)
    if args.list:
        examples = list_examples_or_warn()
        for ex in examples:
            print(f"{ex.name:18s} {ex.title}  (n={ex.n}, k={ex.k})")
        return 0 if examples else fail("no example could be read", 1)
    problem = None
    clash = _session_clash(args)
    if clash:
        return fail(clash)
    if args.session:   # checked whole before anything is built from it
        _, problem = read_session_or_fail(args.session)
        if problem and (args.screenshot or args.animate):
            return fail(f"{problem}")
    if args.screenshot or args.animate:
        return _session_screenshot(args) if args.session else render(Options.from_args(args))
    if args.params:   # (the window takes a parameter from its slider)
        return fail("--param goes with --screenshot or --animate; in the window, set it with its slider")
    if args.gif or args.mp4:
        return fail("--gif/--mp4 need --animate SPEC (rotate:I-J, tour, slice:VAR or param:NAME=FROM:TO)")

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
    win = QtMainWindow(example=None if args.session else (args.example or "klein-bottle-closed"), div=args.div,
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
    if args.session and problem is None:
        win.open_file(args.session)   # (a session of formulas, or of data files: the Data tab)
    win.show()
    if not args.window_screenshot:
        keep_autosaving(app, win, offer=not (args.session or args.example))
    if problem is not None:   # said, and the window stays
        print(f"gcmh-app: error: {problem}", file=sys.stderr)
        from qtpy.QtWidgets import QMessageBox

        win.set_status(problem, error=True)
        box = QMessageBox(QMessageBox.Warning, "Cannot open the session", problem, QMessageBox.Ok, win)
        box.open()   # (not modal to the program: the window runs on)
        win.session_problem_box = box
    return app.exec_()


if __name__ == "__main__":
    sys.exit(main())
