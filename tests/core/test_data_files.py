"""Reading sampled data from files (`gcmh_core.data_files`): every format the tests write, nibabel's
real scans, physical coordinates, memory maps, and one clear InputError per bad file."""

import os
import subprocess
import sys

import numpy as np
import pytest

from gcmh_core import CellComplex, InputError
from gcmh_core.data_files import estimate_data, extract_data, load_components, read_data, read_fields

# an ellipsoid with three different semi-axes on a box that is not a cube: a swapped or
# reversed axis, or a wrong origin or spacing, moves the vertices off it
SEMI = np.array([1.0, 0.7, 0.45])
ORIGIN = np.array([-1.2, -0.9, -0.6])
SPACING = np.array([0.1, 0.075, 0.05])
DIMS = (25, 25, 25)


def ellipsoid(dtype=np.float32):
    axes = [ORIGIN[a] + SPACING[a] * np.arange(DIMS[a]) for a in range(3)]
    X = np.meshgrid(*axes, indexing="ij")
    return sum((X[a] / SEMI[a]) ** 2 for a in range(3)).astype(dtype)


def on_ellipsoid(V, tol=0.03):
    """Every vertex (V, 3) on the ellipsoid (linear interpolation along a grid edge: near it)."""
    r = np.sqrt(((V / SEMI) ** 2).sum(axis=1))
    return len(V) > 50 and np.abs(r - 1).max() < tol


def assert_valid(cx: CellComplex, n, k, box=None):
    """A surface: every edge in two faces, or in one where M leaves the box (its ends on the
    box's boundary); a curve: every vertex in two edges (or one on the boundary)."""
    assert (cx.n, cx.k) == (n, k)
    V = cx.vertices
    assert len(V) > 0 and np.isfinite(V).all()
    if box is None:
        box = np.stack([V.min(axis=0), V.max(axis=0)], axis=1)
    on_box = (np.abs(V - box[:, 0]) < 1e-9).any(axis=1) | (np.abs(V - box[:, 1]) < 1e-9).any(axis=1)
    if n - k == 2:
        counts = np.bincount(cx.cells[2][1], minlength=len(cx.edges))
        assert np.all((counts == 2) | ((counts == 1) & on_box[cx.edges].all(axis=1)))
    if n - k == 1:
        counts = np.bincount(cx.edges.reshape(-1), minlength=len(V))
        assert np.all((counts == 2) | ((counts == 1) & on_box))


def vti(path, values, origin=ORIGIN, spacing=SPACING, name="rho", extra=None):
    pv = pytest.importorskip("pyvista")
    img = pv.ImageData(dimensions=values.shape[:3], spacing=tuple(spacing), origin=tuple(origin))
    img.point_data[name] = values.reshape(-1, *values.shape[3:], order="F") if values.ndim == 3 else \
        values.transpose(2, 1, 0, 3).reshape(-1, values.shape[3])
    for key, v in (extra or {}).items():
        img.point_data[key] = v.ravel(order="F")
    img.save(str(path))
    return str(path)


# ---------------------------------------------------------------- formats
def test_npy_is_memory_mapped_in_index_coordinates(tmp_path):
    path = tmp_path / "e.npy"
    np.save(path, ellipsoid())
    f = read_data(str(path))
    assert isinstance(f.values, np.memmap) and not f.physical
    assert f.bounds.tolist() == [[0.0, 24.0]] * 3
    cx = extract_data(str(path), 1.0)
    assert_valid(cx, 3, 1)
    # index coordinates: i = (x - origin) / spacing
    assert on_ellipsoid(ORIGIN + cx.vertices * SPACING)
    # --bounds gives the physical box
    box = np.stack([ORIGIN, ORIGIN + SPACING * 24], axis=1)
    cx2 = extract_data(str(path), 1.0, bounds=box)
    assert on_ellipsoid(cx2.vertices)
    assert cx2.meta["data"]["files"] == [str(path)]


def test_npz_members_are_components(tmp_path):
    e = ellipsoid(np.float64)
    axes = [ORIGIN[a] + SPACING[a] * np.arange(DIMS[a]) for a in range(3)]
    z = np.broadcast_to(axes[2][None, None, :], DIMS)
    path = tmp_path / "two.npz"
    np.savez(path, e=e, z=z)
    with pytest.raises(InputError, match="holds 2 arrays"):
        read_fields(str(path))
    box = np.stack([ORIGIN, ORIGIN + SPACING * 24], axis=1)
    cx = extract_data(f"{path}:e,z", "1,0.1", bounds=box)
    assert_valid(cx, 3, 2)  # a curve: the ellipsoid at z = 0.1
    assert np.allclose(cx.vertices[:, 2], 0.1) and on_ellipsoid(cx.vertices, tol=0.06)
    assert [c["level"] for c in cx.meta["data"]["components"]] == [1.0, 0.1]


def test_vti_and_legacy_vtk_physical_coordinates(tmp_path):
    pytest.importorskip("pyvista")
    for suffix in (".vti", ".vtk"):
        path = vti(tmp_path / f"e{suffix}", ellipsoid())
        f = read_data(path)
        assert np.allclose(f.bounds, np.stack([ORIGIN, ORIGIN + SPACING * 24], axis=1))
        assert f.axis_names == ["x", "y", "z"]
        cx = extract_data(path, 1.0)
        assert_valid(cx, 3, 1)
        assert on_ellipsoid(cx.vertices)


def test_vti_vector_array_gives_components_and_names_pick_arrays(tmp_path):
    e = ellipsoid(np.float64)
    z = np.broadcast_to((ORIGIN[2] + SPACING[2] * np.arange(25))[None, None, :], DIMS)
    path = vti(tmp_path / "v.vti", np.stack([e, z], axis=-1), name="ez", extra={"other": e})
    with pytest.raises(InputError, match=r"no point array 'rho' \(it holds ez, other\)"):
        read_data(path + ":rho")
    pv = pytest.importorskip("pyvista")
    assert read_data(path).member == pv.read(path).active_scalars_name  # (unnamed: the image's scalars)
    f = read_data(path + ":ez")
    assert f.components == 2 and f.values.shape == (*DIMS, 2)
    cx = extract_data(path + ":ez", [1.0, 0.0])
    assert_valid(cx, 3, 2)
    assert np.allclose(cx.vertices[:, 2], 0.0, atol=1e-9) and on_ellipsoid(cx.vertices, tol=0.06)


def write_nrrd(path, values, origin, spacing):
    header = ("NRRD0004\ntype: float\ndimension: 3\n"
              f"sizes: {' '.join(map(str, values.shape))}\n"
              f"space directions: ({spacing[0]},0,0) (0,{spacing[1]},0) (0,0,{spacing[2]})\n"
              f"space origin: ({origin[0]},{origin[1]},{origin[2]})\n"
              "space: left-posterior-superior\nkinds: domain domain domain\nendian: little\nencoding: raw\n\n")
    with open(path, "wb") as fp:
        fp.write(header.encode())
        fp.write(np.asarray(values, "<f4").transpose(2, 1, 0).tobytes())  # x fastest
    return str(path)


def test_nrrd_and_metaimage(tmp_path):
    pytest.importorskip("vtk")
    from vtkmodules.vtkIOImage import vtkMetaImageWriter

    path = write_nrrd(tmp_path / "e.nrrd", ellipsoid(), ORIGIN, SPACING)
    cx = extract_data(path, 1.0)
    assert_valid(cx, 3, 1)
    assert on_ellipsoid(cx.vertices)
    pv = pytest.importorskip("pyvista")
    img = pv.ImageData(dimensions=DIMS, spacing=tuple(SPACING), origin=tuple(ORIGIN))
    img.point_data["rho"] = ellipsoid().ravel(order="F")
    w = vtkMetaImageWriter()
    w.SetFileName(str(tmp_path / "e.mha"))
    w.SetInputData(img)
    w.Write()
    cx = extract_data(str(tmp_path / "e.mha"), 1.0)
    assert on_ellipsoid(cx.vertices)


def test_nifti_affine_with_a_reversed_axis(tmp_path):
    nib = pytest.importorskip("nibabel")
    # x runs from +1.2 down to -1.2 in the file (negative spacing, as in radiological order)
    affine = np.diag([-SPACING[0], SPACING[1], SPACING[2], 1.0])
    affine[:3, 3] = [-ORIGIN[0], ORIGIN[1], ORIGIN[2]]
    data = ellipsoid()[::-1]
    path = tmp_path / "e.nii.gz"
    img = nib.Nifti1Image(np.ascontiguousarray(data), affine)
    img.header.set_xyzt_units("mm", "sec")
    nib.save(img, path)
    f = read_data(str(path))
    assert np.allclose(f.bounds, np.stack([ORIGIN, ORIGIN + SPACING * 24], axis=1))
    assert f.units == ["mm"] * 3 and not f.notes
    cx = extract_data(str(path), 1.0)
    assert_valid(cx, 3, 1)
    assert on_ellipsoid(cx.vertices)
    assert cx.meta["units"] == ["mm"] * 3


def test_nifti_rotated_affine_is_noted(tmp_path):
    nib = pytest.importorskip("nibabel")
    c, s = np.cos(0.2), np.sin(0.2)
    affine = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    nib.save(nib.Nifti1Image(ellipsoid(), affine), tmp_path / "r.nii")
    f = read_data(str(tmp_path / "r.nii"))
    assert any("not axis-aligned" in note and "11.5 degrees" in note for note in f.notes)
    assert isinstance(f.values, np.memmap)  # (uncompressed, unscaled: mapped)


def test_hdf5_contiguous_mapped_scales_and_compressed(tmp_path):
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "e.h5"
    with h5py.File(path, "w") as h5:
        ds = h5.create_dataset("/fields/rho", data=ellipsoid())
        ds.attrs["origin"] = ORIGIN
        ds.attrs["spacing"] = SPACING
        zc = h5.create_dataset("/fields/zc", data=ellipsoid(), compression="gzip", chunks=(5, 5, 5))
        for a, name in enumerate("xyz"):
            scale = h5.create_dataset(f"/coords/{name}", data=ORIGIN[a] + SPACING[a] * np.arange(25))
            scale.attrs["units"] = "cm"
            scale.make_scale(name)
            zc.dims[a].attach_scale(scale)
            zc.dims[a].label = name.upper()
    with pytest.raises(InputError, match="holds 5 datasets"):
        read_data(str(path))
    f = read_data(f"{path}:/fields/rho")
    assert isinstance(f.values, np.memmap)
    assert np.allclose(f.bounds, np.stack([ORIGIN, ORIGIN + SPACING * 24], axis=1))
    g = read_data(f"{path}:/fields/zc")
    assert g.axis_names == ["X", "Y", "Z"] and g.units == ["cm"] * 3
    assert np.allclose(g.bounds, f.bounds)
    for spec in (f"{path}:/fields/rho", f"{path}:/fields/zc"):
        cx = extract_data(spec, 1.0)
        assert on_ellipsoid(cx.vertices)


def test_trailing_component_axis_of_a_plain_array(tmp_path):
    e = ellipsoid(np.float64)
    y = np.broadcast_to((ORIGIN[1] + SPACING[1] * np.arange(25))[None, :, None], DIMS)
    np.save(tmp_path / "c.npy", np.stack([e, y], axis=-1))
    assert read_data(str(tmp_path / "c.npy")).n == 4  # (without the flag: a fourth grid axis)
    f = read_data(str(tmp_path / "c.npy"), components=True)
    assert f.n == 3 and f.components == 2
    box = np.stack([ORIGIN, ORIGIN + SPACING * 24], axis=1)
    cx = extract_data(str(tmp_path / "c.npy"), [1, 0.2], box, components=True)
    assert_valid(cx, 3, 2)
    assert np.allclose(cx.vertices[:, 1], 0.2) and on_ellipsoid(cx.vertices, tol=0.06)


def test_on_disk_values_give_the_same_bytes(tmp_path):
    np.save(tmp_path / "e.npy", ellipsoid())
    a = load_components(str(tmp_path / "e.npy"), 1.0, on_disk=False)
    b = load_components(str(tmp_path / "e.npy"), 1.0, on_disk=True)
    assert b.on_disk and isinstance(b.values, np.memmap) and b.memory_bytes == 0
    cx_a = extract_data(None, data=a)
    cx_b = extract_data(None, data=b)
    assert cx_a.vertices.tobytes() == cx_b.vertices.tobytes()
    assert all(np.array_equal(x, y) for x, y in zip(cx_a.cells[2], cx_b.cells[2]))


def test_estimate_counts_the_values_held(tmp_path):
    np.save(tmp_path / "e.npy", ellipsoid())
    np.savez(tmp_path / "e.npz", e=ellipsoid())
    mapped = estimate_data(str(tmp_path / "e.npy"), 1.0)  # F's values computed from the map, slab by slab
    whole = estimate_data(str(tmp_path / "e.npz"), 1.0)   # the file read whole, F's values written
    assert whole.grid_bytes - mapped.grid_bytes == 25**3 * (8 + 4)  # (float64 values, the float32 read)
    assert 500 < mapped.candidate_cubes < 5000


# ---------------------------------------------------------------- nibabel's real scans
def nib_file(name):
    nib_testing = pytest.importorskip("nibabel.testing")
    return os.path.join(nib_testing.data_path, name)


def edge_values(V, data, lo, step):
    """The data linearly interpolated at points V (m, n) on edges of the grid's Kuhn simplices (a grid
    edge, or a diagonal from a cube corner c to a corner above it, where a cube was refined into
    simplicial cells): the fractional parts of V's grid coordinates are 0 or one common t.  lo, step:
    the grid's first sample and spacing per axis."""
    g = (V - lo) / step
    base = np.floor(g + 1e-7).astype(int)
    frac = np.clip(g - base, 0, None)
    d = frac > 1e-7
    t = frac.max(axis=1)
    assert np.all(np.abs(np.where(d, frac, t[:, None]) - t[:, None]) < 1e-6)  # (on one Kuhn edge)
    top = np.minimum(base + d, np.array(data.shape) - 1)
    return (1 - t) * data[tuple(base.T)] + t * data[tuple(top.T)]


def test_anatomical_scan_physical_coordinates():
    nib = pytest.importorskip("nibabel")
    path = nib_file("anatomical.nii")
    img = nib.load(path)
    level = 9000.5  # (between the int16 data's values)
    cx = extract_data(path, level)
    assert_valid(cx, 3, 1)
    V = cx.vertices
    assert cx.meta["units"] == ["mm"] * 3
    # each vertex, taken to voxel indices through the file's own affine, lies on a voxel edge where
    # the data interpolate to the level
    ijk = (np.linalg.inv(img.affine) @ np.c_[V, np.ones(len(V))].T)[:3].T
    data = np.asanyarray(img.dataobj).astype(float)
    vals = edge_values(ijk, data, np.zeros(3), np.ones(3))
    assert np.allclose(vals, level, rtol=0, atol=1e-6 * level)


def test_4d_series_is_a_3_manifold_whose_time_sections_are_surfaces():
    nib = pytest.importorskip("nibabel")
    path = nib_file("example4d.nii.gz")
    level = 400.5  # (between the int16 data's values: no sample exactly on M)
    f = read_data(path)
    assert f.axis_names == ["x", "y", "z", "t"] and f.units == ["mm", "mm", "mm", "sec"]
    assert any("not axis-aligned" in note for note in f.notes)
    # (its header says a frame every 2000 s: milliseconds, most likely)
    assert f.bounds[3].tolist() == [0.0, 2000.0] and any("a frame every 2000 s" in note for note in f.notes)
    cx = extract_data(path, level, check_cells=False)
    assert (cx.n, cx.k) == (4, 1) and sorted(cx.cells) == [2, 3] and len(cx.cells[3][0]) > 1
    t0, t1 = f.bounds[3]
    img = nib.load(path)
    assert img.affine[0, 0] < 0  # (x runs backwards in the file: the grid has it reversed)
    data = np.asanyarray(img.dataobj).astype(float)[::-1]
    step = (f.bounds[:, 1] - f.bounds[:, 0]) / (np.array(f.grid_shape) - 1)
    assert np.allclose(edge_values(cx.vertices, data, f.bounds[:, 0], step), level, atol=1e-6 * level)
    for t, frame in ((t0, 0), (t1, 1)):
        # the section at a frame's time: the 2-cells with every vertex there, a closed surface,
        # the same vertices as the frame's own isosurface in R^3
        on = np.abs(cx.vertices[:, 3] - t) < 1e-9
        offsets, faces = cx.cells[2]
        e_on = on[cx.edges].all(axis=1)
        f_on = np.array([e_on[faces[offsets[i]:offsets[i + 1]]].all() for i in range(len(offsets) - 1)])
        sec_faces = np.concatenate([faces[offsets[i]:offsets[i + 1]] for i in np.flatnonzero(f_on)])
        counts = np.bincount(sec_faces, minlength=len(e_on))[e_on]
        # (an edge in one face: where M leaves the scan's box in space)
        V3 = cx.vertices[:, :3]
        on_box = ((np.abs(V3 - f.bounds[:3, 0]) < 1e-9) | (np.abs(V3 - f.bounds[:3, 1]) < 1e-9)).any(axis=1)
        open_edge = on_box[cx.edges[e_on]].all(axis=1)
        assert len(counts) > 1000 and np.all((counts == 2) | ((counts == 1) & open_edge))
        # the frame's own isosurface in R^3: its vertices are the section's, but for those on the
        # diagonals of the cubes whose cells were refined into simplicial ones (not balls)
        frame3 = extract_data(None, data=load_components_from(data[..., frame], f.bounds[:3], level))
        section = set(map(tuple, np.round(cx.vertices[on, :3], 9)))
        own = set(map(tuple, np.round(frame3.vertices, 9)))
        assert own <= section
        extra = np.array(sorted(section - own)).reshape(-1, 3)
        frac = (extra - f.bounds[:3, 0]) / step[:3]
        frac = frac - np.floor(frac + 1e-7)
        assert np.all((frac > 1e-7).sum(axis=1) >= 2) and cx.meta["non_ball_split"] > 0


def load_components_from(values, bounds, level, tmp=None):
    import tempfile

    d = tempfile.mkdtemp()
    np.save(os.path.join(d, "frame.npy"), values)
    return load_components(os.path.join(d, "frame.npy"), level, bounds)


# ---------------------------------------------------------------- bad files
def test_bad_files_one_message_each(tmp_path):
    e = ellipsoid()
    np.save(tmp_path / "ok.npy", e)
    cases = {}
    cases["missing"] = (str(tmp_path / "nope.npy"), "no such file")
    (tmp_path / "junk.npy").write_bytes(b"this is not numpy at all")
    cases["corrupt"] = (str(tmp_path / "junk.npy"), "not a valid .npy")
    raw = (tmp_path / "ok.npy").read_bytes()
    (tmp_path / "cut.npy").write_bytes(raw[: len(raw) // 2])
    cases["truncated"] = (str(tmp_path / "cut.npy"), "but the file holds only")
    # a header that promises a huge array: refused from the header, nothing allocated
    header = raw[: raw.index(b"\n") + 1].replace(b"(25, 25, 25)", b"(25000, 25000, 25000)")
    (tmp_path / "huge.npy").write_bytes(header + raw[len(header):])
    cases["lying header"] = (str(tmp_path / "huge.npy"), "but the file holds only")
    np.save(tmp_path / "obj.npy", np.array([[1, "a"], [2, "b"]], dtype=object), allow_pickle=True)
    cases["objects"] = (str(tmp_path / "obj.npy"), "Python objects")
    np.save(tmp_path / "c.npy", e.astype(np.complex64))
    cases["complex"] = (str(tmp_path / "c.npy"), "complex values")
    np.save(tmp_path / "s.npy", np.array(["a", "b"] * 8).reshape(4, 4))
    cases["strings"] = (str(tmp_path / "s.npy"), "not numbers")
    (tmp_path / "junk.vti").write_text("<VTKFile type='ImageData'> broken")
    cases["corrupt vti"] = (str(tmp_path / "junk.vti"), "not a readable .vti")
    (tmp_path / "junk.nii").write_bytes(b"\0" * 400)
    cases["corrupt nii"] = (str(tmp_path / "junk.nii"), "not a readable NIfTI")
    (tmp_path / "junk.h5").write_bytes(b"nope")
    cases["corrupt h5"] = (str(tmp_path / "junk.h5"), "not a readable HDF5")
    (tmp_path / "x.csv").write_text("1,2")
    cases["unknown"] = (str(tmp_path / "x.csv"), "unknown data format")
    cases["npz member"] = (str(tmp_path / "ok.npy") + ":a", "holds one array")
    for what, (spec, words) in cases.items():
        with pytest.raises(InputError, match=words) as info:
            load_components(spec, 1.0)
        assert "\n" not in str(info.value), what


def test_shapes_levels_and_nan(tmp_path):
    e = ellipsoid()
    np.save(tmp_path / "a.npy", e)
    np.save(tmp_path / "b.npy", e[:-1])
    with pytest.raises(InputError, match="different grid shapes: .*25x25x25.*24x25x25"):
        load_components([str(tmp_path / "a.npy"), str(tmp_path / "b.npy")], 1.0)
    with pytest.raises(InputError, match=r"level 7 is outside the data's range \[.*\].*M is empty"):
        load_components(str(tmp_path / "a.npy"), 7.0)
    with pytest.raises(InputError, match="3 levels for 1 components"):
        load_components(str(tmp_path / "a.npy"), "1,2,3")
    with pytest.raises(InputError, match="k < n"):
        load_components([str(tmp_path / "a.npy")] * 3, 1.0)
    # a NaN region: counted, left out of M (no cell touches it), the rest extracted
    holes = e.copy()
    holes[:, :, 20:] = np.nan
    np.save(tmp_path / "h.npy", holes)
    d = load_components(str(tmp_path / "h.npy"), 1.0)
    assert d.nonfinite == 25 * 25 * 5 and any("NaN" in note for note in d.notes)
    cx = extract_data(None, data=d)
    assert cx.meta["nonfinite_vertices"] == 25 * 25 * 5
    step = SPACING[2]
    z = ORIGIN[2] + cx.vertices[:, 2] * step
    assert z.max() < ORIGIN[2] + 19 * step + 1e-9 and on_ellipsoid(ORIGIN + cx.vertices * SPACING)
    np.save(tmp_path / "n.npy", np.full((4, 4, 4), np.nan, np.float32))
    with pytest.raises(InputError, match="every value is NaN"):
        load_components(str(tmp_path / "n.npy"), 0.0)


def test_a_data_run_does_not_import_sympy(tmp_path):
    # plain levels are read by float(); the formula parser (and its sympy) is for constants like pi/2
    np.save(tmp_path / "e.npy", ellipsoid())
    code = (f"import sys; from gcmh_core.data_files import extract_data, parse_levels; "
            f"cx = extract_data({str(tmp_path / 'e.npy')!r}, '1.0'); "
            "assert len(cx.vertices) > 50 and parse_levels(' -1e3, +.5 ,2.') == [-1000.0, 0.5, 2.0]; "
            "assert 'sympy' not in sys.modules, 'sympy imported'; "
            "import math; assert parse_levels('pi/2') == [math.pi / 2] and 'sympy' in sys.modules")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_sampled_values_of_another_type_are_read_slice_by_slice(monkeypatch):
    # a float32 volume (or int16 scan data) passed to extract in process: the sweep reads float64 slices
    # of it (`_validate.Float64Slices`) instead of a whole float64 copy, with the same bytes
    import functools
    import importlib

    from gcmh_core import _validate, extract

    extract_module = importlib.import_module("gcmh_core.extract")

    t = np.linspace(-1.0, 1.0, 41)
    x, y, z = np.meshgrid(t, t, t, indexing="ij")
    smooth = (x * x + 1.5 * y * y + 2 * z * z).astype(np.float32) - np.float32(0.5)
    smooth[:4, :4, :6] = np.nan
    smooth = smooth[..., None]
    scan = np.round(1000 * (x * x + y * y - z)).astype(np.int16)
    cases = [(smooth, {}), (smooth, {"method": "cms"}), (scan[..., None].transpose(1, 0, 2, 3), {})]
    wanted = [extract(v, (-1, 1), **kw) for v, kw in cases]
    monkeypatch.setattr(extract_module, "prepare", functools.partial(_validate.prepare, slices=True))
    monkeypatch.setattr(_validate.Float64Slices, "__array__", lambda *a, **k: pytest.fail("converted whole"))
    for (v, kw), want in zip(cases, wanted):
        got = extract(v, (-1, 1), **kw)
        assert got.vertices.tobytes() == want.vertices.tobytes() and got.edges.tobytes() == want.edges.tobytes()
        assert all(a.tobytes() == b.tobytes() for r in want.cells for a, b in zip(got.cells[r], want.cells[r]))
        assert got.meta["nonfinite_vertices"] == want.meta["nonfinite_vertices"]
    _, _, _, _, _, sampled = _validate.prepare(smooth, None, None, None, (-1, 1), None, slices=True)
    assert isinstance(sampled, _validate.Float64Slices)
    assert sampled[3:5, ::2, 7].dtype == np.float64 and sampled[3:5, ::2, 7].tobytes() == \
        smooth.astype(np.float64)[3:5, ::2, 7].tobytes()
    # float64 in C order is taken as it is, wrapped or not
    plain = smooth.astype(np.float64)
    assert _validate.prepare(plain, None, None, None, (-1, 1), None, slices=True)[5] is plain
