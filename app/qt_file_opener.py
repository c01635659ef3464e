"""QtFileOpener: what the window opens (File -> Open, Open data..., drops): sessions, saved results
(.npz cell complexes) and data files (gcmh_core.data_files), each by what it is."""

from __future__ import annotations

from qtpy.QtWidgets import QMessageBox

from . import data_source, recent_data
from .qt_widgets import scrolled


class QtFileOpener:
    """Opens files into ``window`` (a QtMainWindow): its data panel, tabs, controller and view."""

    def __init__(self, window):
        self.window = window
        self._data_scroll = None
        self._remembering = False
        self.problem_box = None   # the last message box about a data source (not modal: the window runs on)

    def open_data(self, specs, levels=None) -> bool:
        """Open data files as F's components (one per file or field) and extract at their levels (default:
        the middle of each range); the Data tab gets a live slider per level. False (status line) on a bad file."""
        w = self.window
        specs = [str(s) for s in ([specs] if isinstance(specs, (str, bytes)) or hasattr(specs, "__fspath__")
                                  else specs)]
        source = w.guard("Opening the data", data_source.DataSource, specs, levels)
        if source is None:
            return False
        w.data_source = source
        tab = self._data_tab()
        if w.tabs.indexOf(tab) < 0:
            w.tabs.addTab(tab, "Data")
        w.tabs.setCurrentWidget(tab)
        w.show_description(source.title, "")
        if not self._remembering:   # (the gallery's "your data": each source as last shown in full)
            w.data_panel.shown.connect(self._remember)
            self._remembering = True
        w.data_panel.set_source(source)
        return True

    def _remember(self, step: str) -> None:
        w = self.window
        if step == "full" and w.data_source is not None and w.showing_data():
            picture = w.guard("Remembering the data source", w.screenshot_array)
            recent_data.remember(w.data_source.session_entry(), w.data_source.title, picture)

    def open_entry(self, entry: dict) -> bool:
        """Open a data source a session or the gallery remembers (:meth:`DataSource.from_session`): a file
        moved or deleted is said in a message box and on the status line (False); a file changed since
        opens, and the box says so."""
        w = self.window
        source = w.guard("Opening the data", data_source.DataSource.from_session, entry)
        if source is None:
            self.tell("Cannot open the data", w.last_status)
            return False
        opened = self.open_data(source.specs, source.levels)
        if opened and source.changed:   # (the status line is the run's: the box stays)
            self.tell("The data have changed", "\n".join(source.changed))
        return opened

    def tell(self, title: str, text: str) -> None:
        """A warning box in the window that does not block it."""
        box = QMessageBox(QMessageBox.Warning, title, text, QMessageBox.Ok, self.window)
        box.open()
        self.problem_box = box

    def _data_tab(self):
        if self._data_scroll is None:
            self._data_scroll = scrolled(self.window.data_panel)
        return self._data_scroll

    def open_result(self, path) -> bool:
        """Show a cell complex saved as .npz (Export complex, ``gcmh extract -o``): view, slices and exports
        work on it as on a run's result."""
        w = self.window
        opened = w.guard("Opening the result", data_source.open_result, str(path))
        if opened is None:
            return False
        cx, names, title = opened
        w.data_panel.stop()
        w.show_result(cx, names, title=title)
        w.show_description(title, "")
        w.set_status(f"Opened {path}: {cx.count(0):,} vertices, a {cx.dim}-manifold in R^{cx.n}")
        return True

    def open_file(self, path) -> bool:
        """A session (.json), a saved result (.npz of a cell complex) or a data file, by what it is."""
        w = self.window
        path = str(path)
        if path.lower().endswith(".json"):
            entry = data_source.session_data(path)
            if entry is None:
                if w.controller.open_session(path):
                    return True
                # (checked whole first: nothing on screen was changed)
                QMessageBox.warning(w, "Cannot open the session", w.last_status)
                return False
            return self.open_entry(entry)
        if data_source.is_result_file(path):
            return self.open_result(path)
        return self.open_data([path])

    def dropped_files(self, mime) -> list[str]:
        """The local files of a drag that the window opens (sessions, results, data), else []."""
        if not mime.hasUrls():
            return []
        paths = [u.toLocalFile() for u in mime.urls() if u.isLocalFile()]
        ok = [p for p in paths if p.lower().endswith(".json") or data_source.is_data_file(p)]
        return ok if len(ok) == len(paths) else []

    def drag_enter(self, event) -> None:
        if self.dropped_files(event.mimeData()):
            event.acceptProposedAction()
        else:
            event.ignore()

    def drop(self, event) -> None:
        """One file opens by its kind; several data files open together, one component of F each."""
        paths = self.dropped_files(event.mimeData())
        if not paths:
            event.ignore()
            return
        event.acceptProposedAction()
        if len(paths) == 1:
            self.open_file(paths[0])
        else:
            self.open_data(paths)
