"""GCMH Studio, the desktop application (PyQt5 via qtpy + pyvistaqt).

Modules, model apart from view (napari style); the first group imports no Qt:

- ``model``: ``StudioModel``, the studio's state (system, checks, projection, style, slice, animation settings,
  result, pick, status) with psygnal events that panels and the view redraw from;
- ``controller``: ``StudioController``, what the buttons do: runs and parameter steps, examples, undo / redo,
  sessions, refinement (talks to a runner and a view it is given);
- ``live_play``: ``LivePlay``, the Animate tab's live play (rotation, tour, slice and parameter sweeps);
- ``formula_names``: the Manifold tab's variable names and typo checks ("did you mean y?");
- ``presentation``: what the presentation's card shows and when its axes are framed again;
- ``latest``: ``LatestCall``, "the newest request wins" for work off the GUI thread;
- ``jobs``: ``Job``, one extraction as data, ``run_job`` and ``view_data`` (what showing a result needs);
- ``inputs``: checks for what the user types (numbers through ``gcmh_core.formula.evaluate_constant``);
- ``projection``: the projection model R^n -> R^3 (Givens rotations, base frames), pure numpy;
- ``geometry``: drawing arrays of a CellComplex (cells, centred vertices, normal field), pure numpy;
- ``slicing``: clipping a complex to a slab |<u, x> - c| <= w;
- ``animation``: frame sequences (rotate, tour, slice sweep), the live clock, GIF / MP4 writing;
- ``scene``: ``Scene``, a projected complex on any pyvista plotter (the window's or an off-screen one), with
  ``camera``, ``labels``, ``offscreen`` and ``still_process`` (the window's still picture, drawn in a worker process);
- ``studio_io``: sessions (JSON) and exports of the complex and the projected mesh;
- ``headless``: rendering without a window (``--screenshot``, ``--animate``, thumbnails, animation export);
- ``make_gallery``: ``python -m gcmh_studio.make_gallery`` draws ``resources/gallery/*.png``;

and with Qt:

- ``worker``: ``ExtractWorker`` / ``RefineWorker``, QThreads running the engine with progress and cancel;
- ``qt_run_controller``: ``QtRunController``, the life-cycle of runs and refinements (the controller's runner);
- ``qt_viewer``: ``QtViewer``, the 3D view (pyvistaqt) drawn from the model, with ``qt_still_picture``
  (a see-through result's picture drawn in a thread) and ``qt_drag_turn`` (Shift-drag turns hidden planes);
- ``qt_actions``: the menus, shortcuts and file dialogs; ``qt_exports``: an animation exported under a progress
  dialog;
- the Manifold tab ``qt_formula_panel`` (with ``qt_system_shape``, ``qt_complex_box``, ``qt_formula_rows``,
  ``qt_formula_checks``, ``qt_parameters``, ``qt_domain_box``, ``qt_method_box``), the View tab
  ``qt_projection_panel`` (with ``qt_rotation_sliders``, ``qt_turn_pad``, ``qt_slice_box``, ``qt_style_box``),
  ``qt_animation_panel``, ``qt_topology_panel``, ``qt_gallery``, ``qt_run_bar`` (Run, progress, status) and
  ``qt_widgets`` (small builders, ``QtLatestCall``): the widgets, each reading and writing the model;
- ``qt_main_window``: ``QtMainWindow``, which lays out and wires the parts;
- ``__main__``: the ``gcmh-app`` command (also ``python -m gcmh_studio``).
"""
