"""Generated session files, valid and broken (issue 26): the loader accepts a session whole or refuses it with one
SessionError line, never another exception, within hypothesis' deadline and a memory bound; what it accepts, the
model shows without an exception (the system, the view's projection, colour, opacity and slice). No display.
"""

import copy
import json
import math
import tracemalloc

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from gcmh_studio import studio_io  # noqa: E402
from gcmh_studio.session_schema import SessionError  # noqa: E402

SUITE = settings(max_examples=40, deadline=30_000, derandomize=True,
                 suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
MEMORY_BOUND = 64 << 20

BASE = {"format": "gcmh-session/1", "title": "T",
        "system": {"n": 3, "k": 1, "variables": ["x", "y", "z"], "formulas": ["x^2 + y^2 + z^2 - 1"],
                   "bounds": [[-2.0, 2.0]] * 3, "div": 8, "method": "gcmh", "seed": 0, "start": None,
                   "params": {"a": {"value": 0.5, "min": -1.0, "max": 1.0}}, "periodic": []},
        "view": {"kind": "coordinates", "axes": [0, 1, 2], "seed": 0, "angles": [0.0, 0.0, 0.0],
                 "mapping": "orthographic", "distance": 3.0, "color": "z", "opacity": 1.0, "show_edges": False,
                 "two_sided": False, "boundary": False, "grid": False, "slice": {"along": "z", "c": 0.1, "w": 0.2}},
        "camera": {"position": [1, 2, 3], "focal_point": [0, 0, 0], "up": [0, 0, 1]}, "keep_camera": False}

PATHS = ["title", "system", "view", "camera", "keep_camera", "format", "system.n", "system.k", "system.variables",
         "system.formulas", "system.bounds", "system.div", "system.method", "system.seed", "system.start",
         "system.params", "system.periodic", "system.complex", "system.complex_variables", "view.kind", "view.axes",
         "view.angles", "view.mapping", "view.distance", "view.color", "view.opacity", "view.slice", "view.slice.c",
         "view.slice.w", "view.slice.along", "view.show_edges", "system.params.a", "system.params.a.value"]

scalars = st.one_of(st.none(), st.booleans(), st.integers(-10**30, 10**30), st.floats(),
                    st.text(max_size=20), st.sampled_from(["inf", "nan", "-pi", "x", "", "1e999", "z = w"]))
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=6),
                                                       st.dictionaries(st.text(max_size=6), inner, max_size=4)),
                      max_leaves=12) | st.just("x" * 300_000) | st.just(list(range(20_000)))


@st.composite
def sessions(draw):
    d = copy.deepcopy(BASE)
    for _ in range(draw(st.integers(0, 3))):
        path = draw(st.sampled_from(PATHS)).split(".")
        at = d
        for key in path[:-1]:
            at = at.get(key) if isinstance(at, dict) else None
        if isinstance(at, dict):
            if draw(st.integers(0, 5)) == 0:
                at.pop(path[-1], None)
            else:
                at[path[-1]] = draw(values)
    return d


@SUITE
@given(sessions())
def test_a_generated_session_is_opened_whole_or_refused_in_one_line(tmp_path_factory, d):
    from gcmh_studio.inputs import default_variables
    from gcmh_studio.model import StudioModel

    p = tmp_path_factory.mktemp("s") / "s.json"
    p.write_text(json.dumps(d), encoding="utf-8")
    tracemalloc.start()
    try:
        try:
            back = studio_io.read_session(p)
        except SessionError as e:
            assert "\n" not in str(e) and len(str(e)) < 400, str(e)
            return
        system = back["system"]
        m = StudioModel()
        m.set_system(system)
        n = 2 * len(system["complex_variables"]) if system.get("complex") else \
            int(system.get("n") or len(system.get("variables") or []))
        assert 1 <= n <= 12
        m.set_view_variables(system.get("variables") or default_variables(n), keep=False)
        m.set_view_state(back.get("view") or {})
        assert all(math.isfinite(a) for a in m.projection.angles)
        assert 0.0 <= m.style.opacity <= 1.0
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert peak < MEMORY_BOUND, peak
