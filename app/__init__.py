"""GCMH Studio, the desktop application (PyQt5 via qtpy + pyvistaqt).

Modules, model apart from view (napari style):

- ``projection``: the projection model R^n -> R^3 (Givens rotations, base frames), pure numpy;
- ``geometry``: drawing arrays of a CellComplex (cells, centred vertices, normal field), pure numpy;
- ``inputs``: checks for what the user types, pure Python;
- ``worker``: ``ExtractWorker``, a QThread running ``gcmh_core.extract`` with progress and cancel;
- ``scene``: ``Scene``, a projected complex on any pyvista plotter (the window's or an off-screen one);
- ``qt_formula_panel``, ``qt_projection_panel``, ``qt_main_window``: the widgets;
- ``__main__``: the ``gcmh-app`` command (also ``python -m app``), with a headless screenshot mode;
- ``bench_view``: timing of one rotation-slider step for up to 1M vertices.
"""
