"""GCMH Studio, the desktop application (PyQt5 via qtpy + pyvistaqt).

Modules, model apart from view (napari style); the first group imports no Qt:

- ``model``: ``StudioModel``, the studio's state (system, view, result, pick, status) with plain callbacks;
- ``jobs``: ``Job``, one extraction as data, ``run_job`` and ``view_data`` (what showing a result needs);
- ``inputs``: checks for what the user types (numbers through ``gcmh_core.formula.evaluate_constant``);
- ``projection``: the projection model R^n -> R^3 (Givens rotations, base frames), pure numpy;
- ``geometry``: drawing arrays of a CellComplex (cells, centred vertices, normal field), pure numpy;
- ``slicing``: clipping a complex to a slab |<u, x> - c| <= w;
- ``animation``: frame sequences (rotate, tour, slice sweep), the live clock, GIF / MP4 writing;
- ``scene``: ``Scene``, a projected complex on any pyvista plotter (the window's or an off-screen one);
- ``studio_io``: sessions (JSON) and exports of the complex and the projected mesh;
- ``headless``: rendering without a window (``--screenshot``, ``--animate``, thumbnails, animation export);
- ``make_gallery``: ``python -m gcmh_studio.make_gallery`` draws ``resources/gallery/*.png``;

and with Qt:

- ``worker``: ``ExtractWorker`` / ``RefineWorker``, QThreads running the engine with progress and cancel;
- ``qt_run_controller``: ``QtRunController``, the life-cycle of runs and refinements;
- ``qt_viewer``: ``QtViewer``, the 3D view (pyvistaqt) drawn from the model and the View tab;
- ``qt_actions``: the menus, shortcuts and file dialogs;
- ``qt_formula_panel``, ``qt_projection_panel``, ``qt_animation_panel``, ``qt_topology_panel``, ``qt_gallery``,
  ``qt_widgets``: the widgets;
- ``qt_main_window``: ``QtMainWindow``, which lays out and wires the parts;
- ``__main__``: the ``gcmh-app`` command (also ``python -m gcmh_studio``).
"""
