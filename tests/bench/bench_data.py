"""Benchmark: an isosurface of a volume from a file, `gcmh extract --data` against VTK's flying edges
(issue 29, item 4), each run a fresh process, as a user waits for it.

    python tests/bench/bench_data.py [--side 256] [--rounds 5] [--big 512] [--keep DIR]

Run from the repository root.  Writes a float32 .npy of side^3 samples (a noisy blob: a sphere whose
radius wanders, plus noise, so the surface has detail everywhere), then in alternating rounds:

* gcmh: ``python -m gcmh_core.cli extract --data blob.npy --level 0 --json -q`` (the whole command:
  start-up, the range pass over the memory map, the sweep reading F's values from it, the summary);
* vtk: a short pyvista script in its own process that loads the same file (np.load) and runs flying
  edges (``pv.wrap(a).contour([0.0], method="flying_edges")``), printing the point count.

The children run with Python's bytecode cache on (in the volumes' folder; ``--environment-as-is``
keeps this environment, e.g. PYTHONDONTWRITEBYTECODE=1, under which gcmh compiles its modules from
source at every start).  Wall time and the peak RSS of each child (os.wait4); the ratio of the
medians, each round's ratio and the load average (1 min) before and after.  With --big S, a side S
volume: ``--dry-run --json``'s estimated peak against the run's measured peak RSS, less the RSS
of a process that only imports gcmh_core and numba (the estimate is of the run above an idle process).
The machine may be shared: compare the columns of one run, not absolute times.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

VTK_SCRIPT = """
import sys
import numpy as np
import pyvista as pv
a = np.load(sys.argv[1])
mesh = pv.wrap(a).contour([0.0], method="flying_edges")
print(mesh.n_points, mesh.n_cells)
"""

IDLE_SCRIPT = "import gcmh_core, numba, numpy; from gcmh_core.kernels import marching3"


def make_blob(path: str, side: int, seed: int = 0, noise: float = 0.001) -> None:
    """A float32 (side, side, side) volume: distance to a sphere of wandering radius, plus Gaussian noise of
    standard deviation ``noise`` (the box is [-1, 1]^3), written slab by slab (a 512^3 volume never whole
    in memory as float64).  Noise near the grid spacing (0.01 at 256^3) makes the isosurface rough at
    the scale of a cube: pieces of M in a cube that are not balls, where the n = 3 marching pass hands
    over to the general kernel (`sweep`), many times slower; ``--noise`` shows it."""
    rng = np.random.default_rng(seed)
    out = np.lib.format.open_memmap(path, mode="w+", dtype=np.float32, shape=(side,) * 3)
    t = np.linspace(-1.0, 1.0, side)
    y, z = np.meshgrid(t, t, indexing="ij")
    phase = rng.uniform(0, 2 * np.pi, 3)
    for i in range(side):
        x = t[i]
        r = np.sqrt(x * x + y * y + z * z)
        wobble = 0.08 * np.sin(5 * x + phase[0]) * np.cos(4 * y + phase[1]) * np.sin(6 * z + phase[2])
        jitter = rng.normal(0, noise, size=y.shape) if noise else 0.0
        out[i] = (r - 0.7 + wobble + jitter).astype(np.float32)
    out.flush()
    del out


def write_blob(path: str, side: int, noise: float) -> None:
    """`make_blob` in a child process: a child's peak RSS (wait4) counts its parent's peak at the spawn
    (vfork, then exec: Linux keeps the larger mark), and writing a 512^3 volume here took this
    process to 0.59 GB, which every measured run then reported as its own peak."""
    code = f"import sys; sys.path.insert(0, {os.path.dirname(os.path.abspath(__file__))!r}); import bench_data; " \
           f"bench_data.make_blob({path!r}, {side}, noise={noise!r})"
    subprocess.run([sys.executable, "-c", code], check=True)


# the children's environment (`main` sets it): Python's bytecode cached, as in a user's install
CHILD_ENV: dict[str, str] | None = None


def bytecode_env(folder: str) -> dict[str, str]:
    """This environment with Python's bytecode cache on, in ``folder`` (not the source tree): a
    sandbox that sets PYTHONDONTWRITEBYTECODE=1 made every gcmh run compile its own modules from
    source (0.3 s; gcmh_core is installed editable, pyvista came with its bytecode)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPYCACHEPREFIX"] = folder
    return env


def run_measured(argv: list[str]) -> tuple[float, int, str]:
    """(wall seconds, peak RSS bytes, stdout) of one child, its rusage from wait4."""
    with tempfile.TemporaryFile(mode="w+") as out, tempfile.TemporaryFile(mode="w+") as err:
        t = time.perf_counter()
        proc = subprocess.Popen(argv, stdout=out, stderr=err, text=True, env=CHILD_ENV)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        text = out.read()
        if proc.returncode:
            raise SystemExit(f"{' '.join(argv[:5])}... failed ({proc.returncode}): {err.read().strip()[-400:]}")
    return wall, usage.ru_maxrss * 1024, text


def gcmh_argv(path: str, *extra: str) -> list[str]:
    return [sys.executable, "-m", "gcmh_core.cli", "extract", "--data", path, "--level", "0", "--json", "-q", *extra]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=256)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--big", type=int, default=0, help="also a side^3 volume's estimate against its peak RSS")
    parser.add_argument("--noise", type=float, default=0.001, help="the noise's standard deviation (box [-1, 1]^3)")
    parser.add_argument("--keep", help="folder for the volumes (default: a temporary one, removed)")
    parser.add_argument("--environment-as-is", action="store_true",
                        help="run the children in this environment (default: with Python's bytecode cache on, "
                             "in FOLDER/pycache, even where PYTHONDONTWRITEBYTECODE is set)")
    args = parser.parse_args()

    folder = args.keep or tempfile.mkdtemp(prefix="gcmh-bench-data-")
    os.makedirs(folder, exist_ok=True)
    global CHILD_ENV
    CHILD_ENV = None if args.environment_as_is else bytecode_env(os.path.join(folder, "pycache"))
    path = os.path.join(folder, f"blob{args.side}-{args.noise:g}.npy")
    if not os.path.exists(path):
        write_blob(path, args.side, args.noise)
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
        f.write(VTK_SCRIPT)
        script = f.name
    if args.rounds:
        compare(path, script, args)
    if args.big:
        big_run(folder, args)
    os.unlink(script)
    if not args.keep:
        import shutil

        shutil.rmtree(folder, ignore_errors=True)
    return 0


def compare(path: str, script: str, args) -> None:
    """Alternating rounds of the gcmh command and the flying edges script on the same file."""
    run_measured(gcmh_argv(path))  # (numba's cache filled, the file in the page cache: both sides warm)
    run_measured([sys.executable, script, path])
    rows: dict[str, list] = {"gcmh": [], "vtk": []}
    load = [os.getloadavg()[0]]
    for r in range(args.rounds):
        for name in (("gcmh", "vtk") if r % 2 == 0 else ("vtk", "gcmh")):
            argv = gcmh_argv(path) if name == "gcmh" else [sys.executable, script, path]
            wall, rss, out = run_measured(argv)
            rows[name].append((wall, rss))
            if name == "gcmh":
                s = json.loads(out)
                detail = f"{s['vertices']} vertices, {s['cells'][-1]} faces, engine {s['seconds']:.3f} s"
            else:
                points, cells = out.split()
                detail = f"{points} points, {cells} triangles"
            print(f"round {r + 1} {name:4}: {wall:6.2f} s, peak RSS {rss / 1e6:7.0f} MB  ({detail})", flush=True)
    load.append(os.getloadavg()[0])
    ratios = sorted(g / v for (g, _), (v, _) in zip(rows["gcmh"], rows["vtk"]))
    med = {name: statistics.median(w for w, _ in rows[name]) for name in rows}
    print(f"\n{args.side}^3 float32 (noise {args.noise:g}), {args.rounds} rounds: gcmh {med['gcmh']:.2f} s, "
          f"flying edges {med['vtk']:.2f} s (medians of the wall times): ratio {med['gcmh'] / med['vtk']:.2f} "
          f"(each round's: {ratios[0]:.2f} to {ratios[-1]:.2f}); load average {load[0]:.1f} then {load[1]:.1f}")
    print(f"peak RSS: gcmh {max(m for _, m in rows['gcmh']) / 1e6:.0f} MB, "
          f"flying edges {max(m for _, m in rows['vtk']) / 1e6:.0f} MB")



def big_run(folder: str, args) -> None:
    """A side^3 volume: the dry run's estimated peak against the run's measured peak RSS."""
    big = os.path.join(folder, f"blob{args.big}-{args.noise:g}.npy")
    if not os.path.exists(big):
        write_blob(big, args.big, args.noise)
    _, _, out = run_measured(gcmh_argv(big, "--dry-run"))
    estimate = json.loads(out)
    _, idle, _ = run_measured([sys.executable, "-c", IDLE_SCRIPT])
    wall, rss, out = run_measured(gcmh_argv(big))
    s = json.loads(out)
    print(f"\n{args.big}^3 float32 ({os.path.getsize(big) / 1e9:.2f} GB): estimated peak "
          f"{estimate['peak_bytes'] / 1e9:.2f} GB of {estimate['available_bytes'] / 1e9:.1f} GB available; "
          f"measured peak RSS {rss / 1e9:.2f} GB, less an idle process's {idle / 1e9:.2f} GB: "
          f"{(rss - idle) / 1e9:.2f} GB; {wall:.1f} s, {s['vertices']} vertices", flush=True)


if __name__ == "__main__":
    sys.exit(main())
