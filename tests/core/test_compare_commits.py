"""tests/bench/compare_commits.py: its aggregation of the processes' results (medians, the
ratio of the medians, the pairs' ratios) on made-up results; the timing itself runs only
as the benchmark (a --quick run takes minutes)."""

import importlib.util
import os

import pytest

_PATH = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "bench", "compare_commits.py")
_spec = importlib.util.spec_from_file_location("compare_commits", _PATH)
cc = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cc)


def _result(case, side, i, value, fresh=1.0, digest="h"):
    return dict(case=case, side=side, round=i, value=value, fresh=fresh, hash=digest)


def test_medians_ratio_and_pairs():
    a = [0.20, 0.24, 0.22, 0.21, 0.90]  # (one loaded round)
    b = [0.30, 0.28, 0.33, 0.43, 0.29]
    results = [_result("gcch-cosine-80", "A", i, v) for i, v in enumerate(a)]
    results += [_result("gcch-cosine-80", "B", i, v, fresh=2.0) for i, v in enumerate(b)]
    (row,) = cc.summarize(results, ["gcch-cosine-80"])
    s = row["value"]
    assert s["a"] == pytest.approx(0.22) and s["b"] == pytest.approx(0.30)
    assert s["ratio"] == pytest.approx(0.30 / 0.22)
    ratios = [y / x for x, y in zip(a, b)]
    assert (s["lo"], s["hi"]) == (pytest.approx(min(ratios)), pytest.approx(max(ratios)))
    assert (s["slower"], s["pairs"]) == (4, 5)
    assert row["fresh"]["ratio"] == pytest.approx(2.0)
    assert row["unit"] == "s" and row["same_output"] is True and row["note"] == ""


def test_pairs_need_both_sides_of_a_round():
    results = [_result("kernel-cosine-40", "A", 0, 4.0), _result("kernel-cosine-40", "B", 0, 2.0),
               _result("kernel-cosine-40", "A", 1, 4.0), dict(case="kernel-cosine-40", side="B", round=1,
                                                              error="killed after 600 s"),
               _result("kernel-cosine-40", "A", 2, 8.0), _result("kernel-cosine-40", "B", 2, 6.0, digest="other")]
    (row,) = cc.summarize(results, ["kernel-cosine-40"])
    s = row["value"]
    assert s["a"] == 4.0 and s["b"] == 4.0 and s["ratio"] == 1.0
    assert (s["lo"], s["hi"], s["slower"], s["pairs"]) == (0.5, 0.75, 0, 2)
    assert row["unit"] == "us/cube" and row["same_output"] is False
    assert "B round 1: killed after 600 s" in row["note"]


def test_a_skipped_case_has_no_numbers_and_says_why():
    rows = cc.summarize([], ["prune-cosine-160"], {"prune-cosine-160": {"A": "no pruned sweep", "B": None}})
    s = rows[0]["value"]
    assert s["a"] is None and s["ratio"] is None and s["pairs"] == 0
    assert rows[0]["note"] == "A: no pruned sweep"
    table = cc.format_table(rows)
    assert "| prune-cosine-160 | s | - | - | - | - | - | - | A: no pruned sweep |" in table


def test_table_rows():
    results = [_result("gcch-cosine-80", side, i, v) for i, (side, v) in enumerate([("A", 0.2), ("B", 0.3)])]
    results = [dict(r, round=0) for r in results]
    table = cc.format_table(cc.summarize(results, ["gcch-cosine-80"]), fresh=True).splitlines()
    assert table[2] == "| gcch-cosine-80 | s | 0.200 | 0.300 | 1.50 | 1.50-1.50 | 1/1 | same |  |"
    assert table[3].startswith("| gcch-cosine-80 (process) | s, fresh | 1.000 | 1.000 | 1.00 |")
