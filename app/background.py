"""What waited for VTK drawing off the GUI thread, which nothing does any more.

The window's still picture was drawn in a thread, and every render and every GL context made or ended on the
GUI thread waited for it. It is drawn in a worker process now (:mod:`gcmh_studio.still_process`), which shares
no VTK, GL or X state with the app: there is nothing to wait for. :func:`wait_background` stays until its
callers in files of other owners (``qt_drag_turn``, and through :func:`gcmh_studio.offscreen.gl_lifecycle`
``qt_main_window`` and ``headless``) drop it (issue 26's report has the patch); then this module goes.
"""

from __future__ import annotations


def wait_background() -> None:
    """Returns at once: no picture is drawn in the app off the GUI thread."""
