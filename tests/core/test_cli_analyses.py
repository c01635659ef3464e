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
