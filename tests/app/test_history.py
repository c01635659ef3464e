"""Undo / Redo in the Qt-free model (gcmh_studio.model.History, StudioModel.undo/redo): no display needed."""

from gcmh_studio.model import History, StudioModel, changed_paths


class FakeClock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def system(formulas=("x1^2 + x2^2 + x3^2 - 1",), n=3, div="8", method="gcmh", bounds=None):
    return {"n": n, "k": len(formulas), "variables": [f"x{i + 1}" for i in range(n)], "formulas": list(formulas),
            "bounds": bounds or [["-1.5", "1.5"]] * n, "div": div, "method": method}


def view(angles=(0.0, 0.0, 0.0), mapping="orthographic", slice_=None):
    d = {"kind": "coordinates", "axes": [0, 1, 2], "angles": list(angles), "mapping": mapping}
    if slice_ is not None:
        d["slice"] = slice_
    return d


def test_changed_paths_name_the_places():
    a, b = system(), system(formulas=("x1 - 1",), div="9")
    assert changed_paths(a, b) == {"formulas.0", "div"}
    assert changed_paths(view(), view(angles=(0, 30, 0))) == {"angles.1"}
    assert changed_paths(system(n=3), system(n=4)) >= {"n", "variables", "bounds"}
    assert changed_paths(a, dict(a)) == frozenset()


def test_undo_restores_the_previous_system_and_redo_reapplies_it():
    m = StudioModel()
    first, second = system(), system(formulas=("x1^2 + x2^2 - 1", "x3"), div="12", method="gcch")
    m.set_system(first)
    m.set_system(second)
    assert m.history.can_undo() and not m.history.can_redo()
    state = m.undo()
    assert state["system"] == first and m.system == first
    assert m.history.can_redo()
    state = m.redo()
    assert state["system"] == second and m.system == second
    assert m.redo() is None   # nothing more to redo
    assert m.system == second


def test_view_settings_are_undone_too():
    m = StudioModel()
    m.set_system(system())
    m.set_view_variables(["x1", "x2", "x3", "x4"])
    m.projection.mapping = "stereographic"
    m.projection_changed()
    m.set_slice(on=True, index=0, c=0.5, w=0.04)
    assert m.view_state()["slice"] == {"along": "x1", "c": 0.5, "w": 0.04}
    state = m.undo()
    assert state["view"]["mapping"] == "stereographic" and "slice" not in state["view"] and not m.slice.on
    assert m.undo()["view"]["mapping"] == "orthographic" and m.projection.mapping == "orthographic"
    assert m.redo()["view"]["mapping"] == "stereographic" and m.projection.mapping == "stereographic"


def test_a_view_of_other_variables_is_passed_over():
    m = StudioModel()
    m.set_system(system())                               # (a view of x1, x2, x3)
    m.set_view_variables(["u", "v", "w", "t"])           # another result's view
    m.set_system(system(div="9"))
    assert m.undo()["system"]["div"] == "8"
    assert m.view_names == ["u", "v", "w", "t"]          # the 3-variable view was not put on the 4 variables'
    assert m.undo() is None


def test_typing_and_dragging_are_one_step_each():
    clock = FakeClock()
    m = StudioModel()
    m.history = History(clock=clock)
    m.set_system(system(formulas=("",)))
    for text in ["x", "x1", "x1^", "x1^2", "x1^2 - 1"]:   # keystrokes in F1
        clock.t += 0.2
        m.set_system(system(formulas=(text,)))
    for a in range(0, 90, 10):   # a slider dragged
        clock.t += 0.05
        m.set_angles([0, a, 0])
    state = m.undo()   # the whole drag at once
    assert state["view"]["angles"] == [0, 0, 0] and state["system"]["formulas"] == ["x1^2 - 1"]
    assert list(m.projection.angles) == [0, 0, 0]
    assert m.undo()["system"]["formulas"] == [""]      # the whole word at once
    assert m.undo() is None


def test_the_same_field_after_a_pause_is_a_new_step():
    clock = FakeClock()
    h = History(clock=clock, merge_seconds=1.5)
    h.record({"div": "8"})
    h.record({"div": "9"})
    clock.t += 5.0
    h.record({"div": "10"})
    assert h.undo() == {"div": "9"}
    assert h.undo() == {"div": "8"}


def test_a_change_after_undo_drops_the_redo_branch():
    h = History()
    for d in ("8", "9", "10"):
        h.record({"div": d, "n": 3})
        h.record({"div": d, "n": 4})   # (a different place each time: no merging)
    h.undo()
    h.undo()
    assert h.can_redo()
    assert h.record({"div": "33", "n": 4})
    assert not h.can_redo()
    assert h.undo() == {"div": "9", "n": 4}


def test_recording_nothing_new_is_not_a_step():
    h = History()
    assert h.record({"a": 1})
    assert not h.record({"a": 1})
    assert not h.can_undo()


def test_the_history_has_a_limit():
    h = History(limit=5, merge_seconds=0.0)
    for i in range(20):
        h.record({"i": i, "even": i % 2 == 0})
    steps = 0
    while h.undo() is not None:
        steps += 1
    assert steps == 4 and h.current["i"] == 15


def test_model_stops_recording_while_told():
    m = StudioModel()
    m.set_system(system())
    m.recording = False
    m.set_angles([0, 10, 0])   # e.g. an animation frame
    m.set_angles([0, 20, 0])
    m.recording = True
    assert not m.history.can_undo()


def test_history_event_says_what_can_be_undone():
    m = StudioModel()
    seen = []
    m.events.history.connect(lambda u, r: seen.append((u, r)))
    m.set_system(system())
    m.set_system(system(div="9"))
    m.undo()
    assert seen[-2:] == [(True, False), (False, True)]


def test_sync_keeps_undo_and_redo():
    h = History()
    h.record({"a": 1})
    h.record({"a": 2})
    h.undo()
    h.sync({"a": 1, "b": 0})   # the panels' reading of the state just restored
    assert h.current == {"a": 1, "b": 0}
    assert h.redo() == {"a": 2}


def test_a_change_that_undoes_itself_leaves_no_step():
    m = StudioModel()
    m.set_system(system(n=4))
    m.set_system(system(formulas=("x1 - x4",), n=4))
    m.set_system(system(formulas=("x1 - x4",), n=3))
    m.set_system(system(formulas=("x1 - x4",), n=4))   # n 4 -> 3 -> 4 at once
    state = m.undo()
    assert state["system"] == system(n=4)
