"""Benchmark: what finding and splitting the cells that are not balls costs (issue 13, item 1).

    python tests/bench/bench_balls.py [--repeat N]

Run from the repository root (not collected by pytest).  For each case, in one process
after a warm-up, the best of N runs of:
  - gcmh: the default path (n = 3: the one-pass marching, which hands a grid with such a
    piece to the general path, which splits it);
  - gcmh, no split: the same with the split and the solids' Euler check switched off (the
    paper's cells, wrong there);
  - cms on the same grid (the simplicial baseline, right everywhere).
Cases: the diagonal tube at div 8 (8 pieces), a closed torus whose tube runs along cube
diagonals at div 48 (2 pieces) and at div 52 (none: the price of the check alone), and
the tube lifted to R^5 (k = 3); solids: the tube around R^4's diagonal (S^2 x R, cells refined by
CMS), and spheres with no such piece (the price of the Euler check alone: n <= 5 checks, n = 6
doesn't), and a surface in R^4 (checked too from n = 4).  The table gives seconds and the ratio
to "no split".
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from datetime import datetime, timezone

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "core"))

TUBE = "(x - (x+y+z)/3)^2 + (y - (x+y+z)/3)^2 + (z - (x+y+z)/3)^2 - 0.04"


def torus_text(R=2.0, r=0.14):
    X, Y, Z = "(x + 2/sqrt(2))", "(y - 2/sqrt(2))", "z"
    pu, pv = f"(({X} + {Y} + {Z})/sqrt(3))", f"(({X} - {Y})/sqrt(2))"
    return f"({X}^2 + {Y}^2 + {Z}^2 + {R * R - r * r})^2 - {4 * R * R}*({pu}^2 + {pv}^2)"


def lifted(n):
    t = TUBE.replace("x", "x1").replace("y", "x2").replace("z", "x3")
    return [t] + [f"x{a} - 0.1*x1 + 0.05*x2 - 0.137" for a in range(4, n + 1)]


CASES = {
    "tube, div 8": (dict(F=[TUBE], bounds=[(-1, 1)] * 3, div=8, variables="x,y,z")),
    "diagonal torus, div 48": (dict(F=[torus_text()], bounds=[(-4.5, 4.5)] * 3, div=48, variables="x,y,z")),
    "diagonal torus, div 52": (dict(F=[torus_text()], bounds=[(-4.5, 4.5)] * 3, div=52, variables="x,y,z")),
    "tube in R^5, div 8x8x8x3x3": (dict(F=lifted(5), bounds=[(-1, 1)] * 5, div=[8, 8, 8, 3, 3])),
    "surface: Clifford torus in R^4, div 24": (dict(F=["x1^2+x2^2-0.5", "x3^2+x4^2-0.5"], bounds=[(-1.3, 1.3)] * 4,
                                                    div=24)),
    "solid: tube in R^4, div 8": (dict(F=["+".join(f"(x{a}-(x1+x2+x3+x4)/4)^2" for a in range(1, 5)) + "-0.04"],
                                       bounds=[(-1, 1)] * 4, div=8)),
    "solid: S^3 in R^4, div 40": (dict(F=["x1^2+x2^2+x3^2+x4^2-1"], bounds=[(-1.3, 1.3)] * 4, div=40)),
    "solid: S^3 in R^5 (k = 2), div 12": (dict(F=["x1^2+x2^2+x3^2+x4^2-1", "x5-0.1*x1-0.2*x2"],
                                                bounds=[(-1.3, 1.3)] * 5, div=12)),
    "solid: S^3 in R^6 (k = 3), div 6 (not checked)": (dict(
        F=["x1^2+x2^2+x3^2+x4^2-1", "x5-0.1*x1-0.2*x2", "x6-0.3*x3+0.1*x4"], bounds=[(-1.3, 1.3)] * 6, div=6)),
}


def best(fn, repeat):
    out = None
    t_best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        t_best = min(t_best, time.perf_counter() - t)
    return t_best, out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    from gcmh_core import extract, runner

    split, check = runner.split_non_ball_cells, runner.checks_cells

    def run(case, method="gcmh", do_split=True):
        runner.split_non_ball_cells = split if do_split else (lambda grid, records, cubes, common: records)
        runner.checks_cells = check if do_split else (lambda *args: False)
        try:
            return extract(case["F"], case["bounds"], case["div"], variables=case.get("variables"), method=method)
        finally:
            runner.split_non_ball_cells, runner.checks_cells = split, check

    for case in CASES.values():  # warm-up: every kernel compiled or loaded
        run(case), run(case, do_split=False), run(case, "cms")
    load = os.getloadavg()[0]
    print(f"# bench_balls.py, {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, load {load:.1f}, best of {args.repeat}")
    print("| case | pieces split | chi gcmh / no split / cms | gcmh (s) | no split (s) | cms (s) | gcmh / no split |")
    print("|---|---|---|---|---|---|---|")
    for name, case in CASES.items():
        t_on, on = best(lambda c=case: run(c), args.repeat)
        t_off, off = best(lambda c=case: run(c, do_split=False), args.repeat)
        t_cms, cms = best(lambda c=case: run(c, "cms"), args.repeat)
        chis = f"{on.euler_characteristic()} / {off.euler_characteristic()} / {cms.euler_characteristic()}"
        print(f"| {name} | {on.meta['non_ball_split']} of {on.meta['non_ball_cells']} | {chis} | {t_on:.4f} | "
              f"{t_off:.4f} | {t_cms:.4f} | {t_on / t_off:.2f} |")


if __name__ == "__main__":
    main()
