"""The Manifold tab's names without Qt (:mod:`gcmh_studio.formula_names`): the variables' names as n changes,
and free names held back as typos of a variable. Runs with ``-p no:xvfb``."""

from gcmh_studio.formula_names import VariableNames, hold_typos, replace_name


def test_default_names_follow_n_until_the_user_types_their_own():
    names = VariableNames()
    assert names.resized(["x1", "x2", "x3"], 5) == ["x1", "x2", "x3", "x4", "x5"]
    names.typed("a, b, c, d")
    assert names.resized(["a", "b", "c", "d"], 2) == ["a", "b"]
    assert names.resized(["a", "b"], 4) == ["a", "b", "c", "d"]           # what a smaller n hid comes back
    assert names.resized(["a", "b", "c", "d"], 6) == ["a", "b", "c", "d", "x5", "x6"]
    names = VariableNames()
    names.typed()
    assert names.resized(["x2", "y"], 3) == ["x2", "y", "x3"]


def test_a_repeated_typed_name_gives_way_to_its_default():
    names = VariableNames()
    names.typed()
    assert names.resized(["a", "a"], 3) == ["a", "x2", "x3"]


def test_a_new_system_forgets_what_an_earlier_one_hid():
    names = VariableNames()
    names.typed()
    names.resized(["a", "b", "c"], 1)
    names.reset(["u", "v"], ["x1", "x2"], complex_mode=False)
    assert not names.auto and names.resized(["u", "v"], 3) == ["u", "v", "x3"]
    names.reset(["x1", "x2"], ["x1", "x2"], complex_mode=False)
    assert names.auto and names.resized(["x1", "x2"], 3) == ["x1", "x2", "x3"]


def test_complex_modes_own_names_give_way_and_typed_ones_stay():
    names = VariableNames()
    names.reset(["x", "y", "u", "v"], ["x", "y", "u", "v"], complex_mode=True)
    assert not names.auto and names.auto_complex == "x, y, u, v"
    assert names.complex_own("x, y, u, v") and names.complex_own("")
    assert not names.complex_own("a, b, c, d")


def test_typos_are_held_back_and_the_first_is_asked_about():
    found = ["a", "yy", "zz", "yy", "r"]
    assert hold_typos(found, ["x", "y", "z"], kept=set()) == (("yy", "y"), ["a", "r"])
    assert hold_typos(found, ["x", "y", "z"], kept={"yy"}) == (("zz", "z"), ["a", "yy", "yy", "r"])
    assert hold_typos(found, ["x", "y", "z"], kept={"yy", "zz"}) == (None, found)
    assert hold_typos([], ["x"], kept=()) == (None, [])


def test_a_name_is_replaced_whole():
    assert replace_name("yy^2 + yyy + a_yy + yy1 + 2*yy", "yy", "y") == "y^2 + yyy + a_yy + yy1 + 2*y"
    assert replace_name("x.y + y", "y", "z") == "x.z + z"
