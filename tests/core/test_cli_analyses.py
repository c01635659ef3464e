"""`gcmh extract` options that analyse the result after the run: --homology, --section, --confirm."""

import json

from gcmh_core.cli import main


def run_json(capsys, *argv):
    code = main(["extract", *argv, "--json", "-q"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_homology_of_a_torus_in_the_json(capsys):
    s = run_json(capsys, "--f", "(sqrt(x^2 + y^2) - 1)^2 + z^2 - 0.16", "--vars", "x,y,z",
                 "--bounds", "-1.5:1.5", "--div", "12", "--homology")
    assert s["euler_characteristic"] == 0
    assert s["homology"] == {"betti": [1, 2, 1], "betti_mod2": [1, 2, 1], "torsion": [[], [], []]}


def test_homology_line_in_the_summary(capsys):
    code = main(["extract", "--f", "x^2 + y^2 + z^2 - 1", "--vars", "x,y,z", "--bounds", "-1.5:1.5",
                 "--div", "8", "--homology", "-q"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "homology: H0 = Z, H1 = 0, H2 = Z (mod 2 Betti 1, 0, 1)" in out


def test_without_the_flag_no_homology(capsys):
    s = run_json(capsys, "--f", "x^2 + y^2 + z^2 - 1", "--vars", "x,y,z", "--bounds", "-1.5:1.5", "--div", "6")
    assert "homology" not in s


SPHERE3 = ["--f", "x^2 + y^2 + z^2 + w^2 - 1", "--vars", "x,y,z,w", "--bounds", "-1.3:1.3", "--div", "8"]


def test_section_of_the_three_sphere_is_a_two_sphere(capsys, tmp_path):
    out = tmp_path / "s.npz"
    s = run_json(capsys, *SPHERE3, "--section", "w=0.3", "-o", str(out))
    sec = s["section"]
    assert sec["along"] == "w" and sec["value"] == 0.3 and sec["dimension"] == 2
    assert sec["euler_characteristic"] == 2 and sec["pieces"] == 1 and sec["boundary_facets"] == 0
    from gcmh_core import CellComplex

    written = CellComplex.load(out)   # -o writes the section, not the 3-sphere
    assert written.dim == 2 and written.euler_characteristic() == 2


def test_section_outside_is_empty_and_said(capsys):
    code = main(["extract", *SPHERE3, "--section", "w=pi/2", "-q"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "section w = 1.5708: empty" in out


def test_a_bad_section_is_refused_before_the_run(capsys, monkeypatch):
    import gcmh_core

    def never(*a, **k):
        raise AssertionError("the run started")

    monkeypatch.setattr(gcmh_core, "extract", never)
    for spec in ("v=0.3", "w", "w=abc", "w=nan"):
        code = main(["extract", *SPHERE3, "--section", spec, "-q"])
        out, err = capsys.readouterr()
        assert code == 2 and err.startswith("gcmh: error:") and len(err.splitlines()) == 1, (spec, err)


# ---------------------------------------------------------------- outputs that clash (issue 26, item 6)

def test_outputs_that_clash_are_refused_before_the_run(capsys, tmp_path, monkeypatch):
    import gcmh_core

    monkeypatch.setattr(gcmh_core, "extract", lambda *a, **k: (_ for _ in ()).throw(AssertionError("ran")))
    same = str(tmp_path / "a.npz")
    for argv, words in ((["-o", "-", "--vtu", "-"], "--vtu -: only the .npz"),
                        (["-o", ""], "-o: empty file name"),
                        (["--vtu", ""], "empty file name"),
                        (["-o", same, "--vtu", same], "name the same file")):
        code = main(["extract", *SPHERE3, "-q", *argv])
        out, err = capsys.readouterr()
        assert code == 2 and err.startswith("gcmh: error:") and words in err and len(err.splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == []


def test_a_huge_n_is_refused_at_once(capsys):
    code = main(["extract", "--f", "x1", "--n", "100000", "--bounds", "-1:1", "-q"])
    out, err = capsys.readouterr()
    assert code == 2 and err.startswith("gcmh: error:") and len(err.splitlines()) == 1, err


# ---------------------------------------------------------------- how sure the topology is (issue 25)

def test_confirm_agrees_on_a_sphere(capsys):
    s = run_json(capsys, "--f", "x^2 + y^2 + z^2 - 1", "--vars", "x,y,z", "--bounds", "-1.5:1.5", "--div", "8",
                 "--confirm")
    c = s["confirmation"]
    assert c["agree"] is True and c["first"] == c["second"], c


def test_confirm_says_when_a_thin_tube_is_below_the_grid(capsys):
    # a torus of tube radius 0.06 at div 6: the first grid misses or breaks it
    s = run_json(capsys, "--f", "(sqrt(x^2 + y^2) - 1)^2 + z^2 - 0.0036", "--vars", "x,y,z",
                 "--bounds", "-1.5:1.5", "--div", "6", "--confirm")
    c = s["confirmation"]
    assert c["agree"] is False and "finer" in c["message"] and c["suggested_div"], c


def test_the_hyperboloid_cone_is_flagged_at_div_13(capsys):
    code = main(["extract", "--example", "hyperboloid", "--param", "a=0", "--div", "13", "-q"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "critical point" in out
