"""Sampled data from files: F's components are data values minus levels, on the file's grid.

public functions -> one reader per format -> `DataField` (values never copied here):

* ``.npy``: memory-mapped (``np.load(mmap_mode="r")``), never read whole; index coordinates.
* ``file.npz:name`` (``name,name2`` for several fields): read at once (zip members can't be mapped).
* VTK image data -- ``.vti``, ``.vtk`` (legacy structured points), ``.nrrd``/``.nhdr``, ``.mha``/``.mhd``
  -- through VTK's readers (pyvista's VTK), ``file.vti:array`` picks a point array; bounds from the
  image's origin and spacing; a vector array gives one component per entry.
* NIfTI ``.nii``/``.nii.gz`` (nibabel): bounds from the affine (a note when it is not axis-aligned),
  units from the header; a 4D file is space and time (n = 4).
* HDF5 ``file.h5:/path`` (h5py): contiguous datasets memory-mapped; axis names and bounds from
  dimension labels and scales, or from ``origin``/``spacing`` attributes.

Every mistake is one `InputError` naming the file: missing, unreadable, corrupt, a header that
promises more data than the file holds (or than this machine's memory), values that are not real
numbers, fields of different shapes, a level outside the data's range (M would be empty).

`load_components` makes F's values: (d1, ..., dn, k) float64, data minus level per component,
written slab by slab; a grid too large for memory goes to a temporary file, memory-mapped, which
the sweep reads slab by slab (`sweep`).  `extract_data` runs `extract` on them -- or, for files
that are all memory-mapped and a whole-grid method, on `MappedValues`: F's values computed from the
maps for each slab the sweep reads (each block a cluster's worker reads), never written whole.

The optional readers (VTK, nibabel, h5py) are imported when a file needs them: ``import
gcmh_core`` stays numpy, numba and sympy only.
"""

from __future__ import annotations

import functools
import math
import os
import tempfile
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import cast

import numpy as np

from ._memory import available_memory, format_bytes
from .errors import InputError

__all__ = ["DataField", "SampledData", "read_data", "read_fields", "load_components", "estimate_data",
           "extract_data", "field_ranges", "parse_levels", "DATA_SUFFIXES"]

NPY = (".npy",)
NPZ = (".npz",)
VTK_IMAGE = (".vti", ".vtk", ".nrrd", ".nhdr", ".mha", ".mhd")
NIFTI = (".nii", ".nii.gz")
HDF5 = (".h5", ".hdf5", ".hdf")
DATA_SUFFIXES = NPY + NPZ + VTK_IMAGE + NIFTI + HDF5

# F's values are held in memory up to this share of the available memory; above it they go to a
# memory-mapped temporary file (the sweep reads them slab by slab; the page cache holds what fits)
IN_MEMORY_SHARE = 0.25
# A NIfTI series whose frames are this many seconds apart or more gets a note: fMRI repetition times are
# 0.5-3 s, and old writers put milliseconds in a header that says seconds (nibabel's example4d.nii.gz: 2000)
_LONG_FRAME_SECONDS = 100.0
# values converted per step: a slab of this many samples (keeps the temporaries small)
_SLAB_SAMPLES = 1 << 18  # (a slab's data stay in the cache between its range and its subtraction)


@dataclass
class DataField:
    """One field read from a file.

    values : (d1, ..., dn) or, with components, (d1, ..., dn, c) array -- often a read-only memory
        map of the file, never copied by the reader (its axes may be reversed views: a flipped axis).
    bounds : (n, 2) float64, the physical box of the samples (first and last sample per axis).
    axis_names, units : n names ("x", "y", "z", "t") and units (None where the file has none).
    """

    source: str
    path: str
    member: str | None
    values: np.ndarray
    bounds: np.ndarray
    axis_names: list[str]
    units: list[str | None]
    components: int = 1
    notes: list[str] = field(default_factory=list)
    physical: bool = True  # False: index coordinates (a plain .npy)

    @property
    def n(self) -> int:
        return len(self.bounds)

    @property
    def grid_shape(self) -> tuple[int, ...]:
        return tuple(int(d) for d in self.values.shape[: self.n])


@dataclass
class SampledData:
    """F's values from files: ``values`` (d1, ..., dn, k) float64 (data minus level; or a `MappedValues`
    that computes them from the files' maps for the slices asked for), on the box
    ``bounds`` (n, 2); ``ranges`` the finite data range of each component; ``nonfinite`` the
    samples (grid points) where some component is NaN or infinite (no cell of M touches them)."""

    values: np.ndarray | MappedValues
    bounds: np.ndarray
    variables: list[str]
    units: list[str | None]
    fields: list[DataField]
    levels: list[float]
    ranges: list[tuple[float, float]]
    nonfinite: int
    notes: list[str]
    on_disk: bool

    @property
    def n(self) -> int:
        return len(self.bounds)

    @property
    def k(self) -> int:
        return int(self.values.shape[-1])

    @property
    def memory_bytes(self) -> int:
        """Bytes of F's values held in memory (0 when they are memory-mapped from disk, or read from the
        files' maps as the run asks for them: `MappedValues`)."""
        return 0 if self.on_disk or isinstance(self.values, MappedValues) else int(self.values.nbytes)

    def describe(self) -> dict:
        """What the run was made of, for a result's meta and the command line's JSON."""
        comps = []
        j = 0
        for f in self.fields:
            for c in range(f.components):
                comps.append(dict(source=f.source, component=c if f.components > 1 else None,
                                  level=self.levels[j], range=list(self.ranges[j])))
                j += 1
        return dict(files=[f.source for f in self.fields], components=comps,
                    shape=list(self.values.shape[:-1]), bounds=self.bounds.tolist(),
                    variables=list(self.variables), units=list(self.units), nonfinite_samples=self.nonfinite,
                    notes=list(self.notes), values_on_disk=bool(self.on_disk),
                    values_from_maps=isinstance(self.values, MappedValues))


# ----------------------------------------------------------------------------- specs
def split_spec(spec: str) -> tuple[str, list[str]]:
    """"file.npz:u,v" -> ("file.npz", ["u", "v"]); a path that exists as given is taken whole
    (a colon may be part of a file name)."""
    spec = os.fspath(spec)
    if not isinstance(spec, str) or not spec.strip():
        raise InputError(f"a data file must be a path, got {spec!r}")
    if os.path.exists(spec):
        return spec, []
    path, sep, names = spec.rpartition(":")
    if sep and path and (os.path.exists(path) or _suffix(path) in DATA_SUFFIXES):
        members = [m.strip() for m in names.split(",") if m.strip()]
        if not members:
            raise InputError(f"{spec}: name a field after the colon, e.g. {path}:values")
        return path, members
    return spec, []


def _suffix(path: str) -> str:
    low = path.lower()
    return ".nii.gz" if low.endswith(".nii.gz") else os.path.splitext(low)[1]


# ----------------------------------------------------------------------------- public readers
def read_fields(spec: str, components: bool | None = None) -> list[DataField]:
    """The fields a data spec names: "vol.npy", "run.npz:u,v", "scan.nii.gz", "sim.h5:/a/p",
    "img.vti:density".  components: True takes each array's last axis as F's components (not a
    grid axis); None (default) does so only where the file says so (a VTK vector array, a 5D NIfTI)."""
    path, members = split_spec(spec)
    if not os.path.exists(path):
        raise InputError(f"{path}: no such file")
    if os.path.isdir(path):
        raise InputError(f"{path}: is a folder, not a data file")
    if not os.access(path, os.R_OK):
        raise InputError(f"{path}: cannot be read (permission denied)")
    suffix = _suffix(path)
    one = {**dict.fromkeys(NPY, "a .npy file holds one array"),
           **dict.fromkeys(NIFTI, "a NIfTI file holds one image")}.get(suffix)
    if members and one:
        raise InputError(f"{spec}: {one}; drop ':{','.join(members)}'")
    if suffix in NPY:
        out = [_read_npy(spec, path)]
    elif suffix in NPZ:
        out = _read_npz(spec, path, members)
    elif suffix in VTK_IMAGE:
        out = _read_vtk(spec, path, members)
    elif suffix in NIFTI:
        out = [_read_nifti(spec, path)]
    elif suffix in HDF5:
        out = _read_hdf5(spec, path, members)
    else:
        raise InputError(f"{path}: unknown data format {suffix or '(no suffix)'!r}; "
                         f"use one of {', '.join(DATA_SUFFIXES)}")
    return [_finish(f, components) for f in out]


def read_data(spec: str, components: bool | None = None) -> DataField:
    """The one field a data spec names (see `read_fields`)."""
    fields = read_fields(spec, components)
    if len(fields) != 1:
        raise InputError(f"{spec} names {len(fields)} fields; read_fields returns them all")
    return fields[0]


def _finish(f: DataField, components: bool | None) -> DataField:
    """Checks shared by every format: real numbers, at least 2 samples per axis (axes of one
    sample dropped, with a note), the component axis as asked."""
    v = f.values
    if v.dtype.kind == "c":
        raise InputError(f"{f.source}: complex values ({v.dtype}); save the real part or the modulus")
    if v.dtype.kind not in "fiu":
        raise InputError(f"{f.source}: values of type {v.dtype} are not numbers (need integers or floats)")
    if components and f.components == 1:
        if v.ndim < 3:
            raise InputError(f"{f.source}: a component axis needs at least 2 grid axes, shape {v.shape}")
        f.components = int(v.shape[-1])
        f.bounds = f.bounds[: v.ndim - 1]
        f.axis_names, f.units = f.axis_names[: v.ndim - 1], f.units[: v.ndim - 1]
    flat = [a for a in range(f.n) if v.shape[a] == 1]
    if flat:  # (a 2D image stored as 3D with one slice, a 4D series of one frame)
        keep = [a for a in range(f.n) if a not in flat]
        index = tuple(0 if a in flat else slice(None) for a in range(f.n))
        f.values = v[index]
        f.notes.append("axis " + ", ".join(f.axis_names[a] for a in flat) + " has one sample: left out")
        f.bounds = f.bounds[keep]
        f.axis_names = [f.axis_names[a] for a in keep]
        f.units = [f.units[a] for a in keep]
    if f.n < 2:
        raise InputError(f"{f.source}: need at least 2 grid axes with 2 or more samples, got shape {v.shape}")
    small = [a for a in range(f.n) if f.values.shape[a] < 2]
    if small:
        raise InputError(f"{f.source}: need at least 2 samples per axis, got shape {v.shape}")
    return f


def _index_field(source, path, member, values, physical=False, notes=None) -> DataField:
    n = values.ndim
    bounds = np.array([[0.0, float(d - 1)] for d in values.shape], np.float64)
    names = ["x", "y", "z", "t"][:n] if n <= 4 else [f"x{i + 1}" for i in range(n)]
    return DataField(source, path, member, values, bounds, names, [None] * n, 1, list(notes or []), physical)


# ----------------------------------------------------------------------------- numpy
def _npy_header(fp, source):
    """(shape, fortran order, dtype) of an .npy stream, or one InputError."""
    try:
        version = np.lib.format.read_magic(fp)
        if version == (1, 0):
            return np.lib.format.read_array_header_1_0(fp)
        return np.lib.format.read_array_header_2_0(fp)
    except (ValueError, OSError, EOFError, SyntaxError) as err:
        raise InputError(f"{source}: not a valid .npy file ({_first_line(err)})") from None


def _check_size(source, shape, dtype, have: int | None):
    """A header's shape against the bytes the file holds and the memory this machine has."""
    need = math.prod(int(d) for d in shape) * np.dtype(dtype).itemsize
    if have is not None and need > have:
        raise InputError(f"{source}: the header says {'x'.join(map(str, shape))} {np.dtype(dtype)} "
                         f"({format_bytes(need)}) but the file holds only {format_bytes(have)}: truncated or corrupt")
    return need


def _read_npy(source, path) -> DataField:
    with open(path, "rb") as fp:
        shape, _, dtype = _npy_header(fp, source)
        offset = fp.tell()
    if dtype.hasobject:
        raise InputError(f"{source}: holds Python objects, not numbers")
    _check_size(source, shape, dtype, os.path.getsize(path) - offset)
    try:
        values = np.load(path, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError) as err:
        raise InputError(f"{source}: cannot read ({_first_line(err)})") from None
    return _index_field(source, path, None, values)


def _read_npz(source, path, members) -> list[DataField]:
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError) as err:
        raise InputError(f"{source}: not a valid .npz file ({_first_line(err)})") from None
    with archive:
        names = [i.filename[:-4] for i in archive.infolist() if i.filename.endswith(".npy")]
        if not members:
            if len(names) != 1:
                listed = ", ".join(names[:12]) or "none"
                raise InputError(f"{source}: holds {len(names)} arrays ({listed}); name one: {path}:NAME")
            members = names
        out = []
        for m in members:
            if m not in names:
                raise InputError(f"{source}: no array {m!r} (it holds {', '.join(names[:12]) or 'none'})")
            info = archive.getinfo(m + ".npy")
            try:
                with archive.open(info) as fp:
                    shape, fortran, dtype = _npy_header(fp, f"{path}:{m}")
                    header = fp.tell() if fp.seekable() else None
                    if dtype.hasobject:
                        raise InputError(f"{path}:{m}: holds Python objects, not numbers")
                    _check_size(f"{path}:{m}", shape, dtype, info.file_size - (header or 0))
                    _check_memory(f"{path}:{m}", shape, dtype)
                with archive.open(info) as fp:
                    values = np.lib.format.read_array(fp, allow_pickle=False)
            except (zipfile.BadZipFile, ValueError, OSError, EOFError) as err:
                raise InputError(f"{path}:{m}: cannot read ({_first_line(err)})") from None
            out.append(_index_field(f"{path}:{m}", path, m, values))
        return out


def _check_memory(source, shape, dtype):
    """A file that must be read whole (compressed, zipped) must fit in memory with room for F."""
    need = math.prod(int(d) for d in shape) * np.dtype(dtype).itemsize
    if need > available_memory() // 2:
        raise InputError(f"{source}: {'x'.join(map(str, shape))} {np.dtype(dtype)} is {format_bytes(need)}, more "
                         f"than half the {format_bytes(available_memory())} of memory available, and this format "
                         "is read whole: save it as an uncompressed .npy (memory-mapped)")


# ----------------------------------------------------------------------------- VTK
_VTK_READERS = {".vti": "vtkXMLImageDataReader", ".vtk": "vtkStructuredPointsReader",
                ".nrrd": "vtkNrrdReader", ".nhdr": "vtkNrrdReader", ".mha": "vtkMetaImageReader",
                ".mhd": "vtkMetaImageReader"}


def _optional(module: str, what: str):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        extra = {"nibabel": "nibabel", "h5py": "h5py"}.get(module.split(".")[0])
        hint = f"pip install {extra} (or pip install gcmh[data])" if extra else "pip install pyvista"
        raise InputError(f"reading {what} needs {module.split('.')[0]}: {hint}") from None


def _read_vtk(source, path, members) -> list[DataField]:
    suffix = _suffix(path)
    io = _optional("vtkmodules.vtkIOXML" if suffix == ".vti" else "vtkmodules.vtkIOImage"
                   if suffix in (".nrrd", ".nhdr", ".mha", ".mhd") else "vtkmodules.vtkIOLegacy", f"{suffix} files")
    from vtkmodules.util.numpy_support import vtk_to_numpy

    reader = getattr(io, _VTK_READERS[suffix])()
    reader.SetFileName(path)
    with _vtk_messages() as messages:
        if suffix == ".vtk" and not reader.IsFileStructuredPoints():
            raise InputError(f"{source}: not VTK image data (structured points); the legacy reader here takes "
                             "images only")
        # the header first: the extent promised, checked against memory before any data is read
        reader.UpdateInformation()
        if _vtk_failed(reader, messages):
            raise InputError(f"{source}: not a readable {suffix} file ({_vtk_message(messages)})")
        info = reader.GetOutputInformation(0)
        from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp

        extent = info.Get(sddp.WHOLE_EXTENT()) if info is not None and info.Has(sddp.WHOLE_EXTENT()) else None
        if extent is not None:
            dims = [extent[2 * a + 1] - extent[2 * a] + 1 for a in range(3)]
            if min(dims) < 1:
                raise InputError(f"{source}: the header gives an empty image (extent {tuple(extent)})")
            need = math.prod(dims) * 8  # (at least one float64 per sample once read)
            if need > available_memory() // 2:
                raise InputError(f"{source}: the header says {'x'.join(map(str, dims))} samples ({format_bytes(need)} "
                                 f"as floats), more than half the {format_bytes(available_memory())} of memory "
                                 "available: wrong header, or save it as an uncompressed .npy (memory-mapped)")
        reader.Update()
        if _vtk_failed(reader, messages):
            raise InputError(f"{source}: not a readable {suffix} file ({_vtk_message(messages)})")
    image = reader.GetOutput()
    if image is None or not hasattr(image, "GetDimensions"):
        raise InputError(f"{source}: not VTK image data")
    dims = image.GetDimensions()
    pd = image.GetPointData()
    arrays = [pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays()) if pd.GetArray(i) is not None]
    if not arrays:
        raise InputError(f"{source}: holds no point data arrays (values at the image's samples)")
    if not members:
        if len(arrays) > 1:
            scalars = pd.GetScalars()
            if scalars is None:
                raise InputError(f"{source}: holds {len(arrays)} arrays ({', '.join(arrays[:12])}); name one: "
                                 f"{path}:NAME")
            members = [scalars.GetName()]
        else:
            members = arrays
    origin, spacing = np.array(image.GetOrigin(), float), np.array(image.GetSpacing(), float)
    notes = []
    direction = image.GetDirectionMatrix() if hasattr(image, "GetDirectionMatrix") else None
    if direction is not None and not direction.IsIdentity():
        notes.append("the image has a direction matrix (rotated axes): the bounds follow the array's axes")
    out = []
    for m in members:
        arr = pd.GetArray(m)
        if arr is None:
            raise InputError(f"{source}: no point array {m!r} (it holds {', '.join(map(str, arrays[:12]))})")
        c = arr.GetNumberOfComponents()
        try:
            flat = vtk_to_numpy(arr)
        except (ValueError, TypeError) as err:
            raise InputError(f"{source}:{m}: values that are not numbers ({_first_line(err)})") from None
        if flat.shape[0] != math.prod(dims):
            raise InputError(f"{source}:{m}: {flat.shape[0]} values for {'x'.join(map(str, dims))} samples")
        # VTK stores x fastest: (z, y, x[, c]) in C order, seen as (x, y, z[, c]) without a copy
        grid = flat.reshape(dims[::-1] + ((c,) if c > 1 else ()))
        values = np.moveaxis(grid, (0, 1, 2), (2, 1, 0))
        bounds = np.stack([origin, origin + spacing * (np.array(dims) - 1)], axis=1)
        name = f"{path}:{m}" if len(members) > 1 or len(arrays) > 1 else source
        f = DataField(name, path, m, values, bounds, ["x", "y", "z"], [None] * 3, c, list(notes))
        out.append(_positive_axes(f, spacing))
    return out


def _positive_axes(f: DataField, spacing) -> DataField:
    """Axes with a negative spacing reversed (a view), so that every lo < hi."""
    flip = [a for a in range(len(spacing)) if spacing[a] < 0]
    if flip:
        index = tuple(slice(None, None, -1) if a in flip else slice(None) for a in range(f.values.ndim))
        f.values = f.values[index]
        f.bounds[flip] = f.bounds[flip][:, ::-1]
    if np.any(np.asarray(spacing) == 0):
        raise InputError(f"{f.source}: a spacing of 0 along an axis")
    return f


class _vtk_messages:
    """VTK's error and warning text while reading, kept (not printed): VTK reports a bad file
    there, not by an exception."""

    def __enter__(self):
        from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow

        self.previous = vtkOutputWindow.GetInstance()
        self.verbosity = vtkLogger.GetCurrentVerbosityCutoff()
        self.window = vtkStringOutputWindow()
        vtkOutputWindow.SetInstance(self.window)
        vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
        return self

    def __exit__(self, *exc):
        from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow

        vtkOutputWindow.SetInstance(self.previous)
        vtkLogger.SetStderrVerbosity(self.verbosity)

    def errors(self) -> list[str]:
        text = self.window.GetOutput() or ""
        return [block for block in text.split("\n\n") if block.strip().startswith("ERROR")]


def _vtk_failed(reader, messages) -> bool:
    return bool(messages.errors()) or bool(hasattr(reader, "GetErrorCode") and reader.GetErrorCode())


def _vtk_message(messages) -> str:
    for block in messages.errors():
        lines = [line for line in block.strip().splitlines()[1:] if line.strip()]
        if lines:  # "vtkXMLDataParser (0x...): Error parsing XML ..." -> the words after the object
            return lines[0].split("): ", 1)[-1].strip()[:200]
    return "VTK could not read it"


# ----------------------------------------------------------------------------- NIfTI
_SPACE_NAMES = ["x", "y", "z"]


def _read_nifti(source, path) -> DataField:
    nib = _optional("nibabel", "NIfTI files")
    try:
        img = nib.load(path, mmap=True)
    except Exception as err:  # noqa: BLE001  (nibabel raises many kinds for a bad file)
        raise InputError(f"{source}: not a readable NIfTI file ({_first_line(err)})") from None
    header = img.header
    shape = tuple(int(d) for d in img.shape)
    dtype = header.get_data_dtype()
    if dtype.kind not in "fiu":
        raise InputError(f"{source}: values of type {dtype} are not real numbers")
    if not path.lower().endswith(".gz"):
        offset = int(header.get_data_offset())
        _check_size(source, shape, dtype, os.path.getsize(path) - offset)
    else:
        _check_memory(source, shape, dtype)
    try:
        values = np.asanyarray(img.dataobj)  # (a memory map of the file when unscaled and uncompressed)
    except Exception as err:  # noqa: BLE001
        raise InputError(f"{source}: cannot read the data ({_first_line(err)})") from None
    space_unit, time_unit = header.get_xyzt_units()
    space_unit = None if space_unit in (None, "unknown") else space_unit
    time_unit = None if time_unit in (None, "unknown") else time_unit
    affine = np.asarray(img.affine, float)
    n = min(values.ndim, 4)
    components = values.ndim == 5  # (dims 5: a vector or several values per sample)
    if values.ndim > 5:
        raise InputError(f"{source}: {values.ndim} dimensions; at most 3 of space, time and a component axis")
    lin = affine[:3, :3]
    spacing = np.linalg.norm(lin, axis=0)
    if np.any(spacing == 0):
        raise InputError(f"{source}: the affine maps an axis to a point (a zero column)")
    notes = []
    off = np.abs(lin - np.diag(np.diag(lin)))
    if np.any(off > 1e-6 * spacing[None, :]):
        cosine = np.clip(np.abs(np.diag(lin)) / spacing, -1, 1)
        angle = float(np.degrees(np.arccos(cosine.min())))
        notes.append(f"the affine is not axis-aligned (axes turned by up to {angle:.1f} degrees): the bounds take "
                     "the voxel sizes and origin along the array's axes; scanner coordinates need the affine")
    sign = np.where(np.diag(lin) < 0, -1.0, 1.0)
    steps = spacing * sign
    origin = affine[:3, 3]
    bounds = [[origin[a], origin[a] + steps[a] * (shape[a] - 1)] for a in range(min(3, values.ndim))]
    names = _SPACE_NAMES[: len(bounds)]
    units: list[str | None] = [space_unit] * len(bounds)
    if n == 4:
        zooms = header.get_zooms()
        dt = float(zooms[3]) if len(zooms) > 3 and zooms[3] > 0 else 1.0
        t0 = float(header.get("toffset", 0.0) or 0.0)
        bounds.append([t0, t0 + dt * (shape[3] - 1)])
        names.append("t")
        units.append(time_unit)
        if time_unit == "sec" and dt >= _LONG_FRAME_SECONDS:   # (a repetition time written in ms, labelled s)
            notes.append(f"a frame every {dt:g} s: if the header's time step is in milliseconds, give the time "
                         "axis its bounds in seconds with --bounds")
        steps = np.r_[steps, dt]
    f = DataField(source, path, None, values, np.array(bounds, float), names, units,
                  int(shape[4]) if components else 1, notes)
    return _positive_axes(f, steps)


# ----------------------------------------------------------------------------- HDF5
def _read_hdf5(source, path, members) -> list[DataField]:
    h5py = _optional("h5py", "HDF5 files")
    try:
        h5 = h5py.File(path, "r")
    except Exception as err:  # noqa: BLE001  (h5py raises OSError and others for a bad file)
        raise InputError(f"{source}: not a readable HDF5 file ({_first_line(err)})") from None
    with h5:
        if not members:
            found: list[str] = []
            h5.visititems(lambda name, obj: found.append("/" + name) if isinstance(obj, h5py.Dataset) else None)
            if len(found) != 1:
                raise InputError(f"{source}: holds {len(found)} datasets ({', '.join(found[:12]) or 'none'}); "
                                 f"name one: {path}:/PATH")
            members = found
        return [_hdf5_field(h5py, h5, path, m, source if len(members) == 1 else f"{path}:{m}") for m in members]


def _hdf5_field(h5py, h5, path, member, source) -> DataField:
    obj = h5.get(member)
    if obj is None:
        raise InputError(f"{source}: no dataset {member!r} in the file")
    if not isinstance(obj, h5py.Dataset):
        raise InputError(f"{source}: {member!r} is a group, not a dataset")
    ds = obj
    if ds.dtype.kind not in "fiu":
        raise InputError(f"{source}: values of type {ds.dtype} are not real numbers")
    shape = tuple(int(d) for d in ds.shape)
    offset = ds.id.get_offset()
    if offset is not None and ds.chunks is None and ds.compression is None:  # contiguous: map the file
        _check_size(source, shape, ds.dtype, os.path.getsize(path) - offset)
        values = np.memmap(path, dtype=ds.dtype, mode="r", offset=offset, shape=shape)
    else:
        _check_memory(source, shape, ds.dtype)
        try:
            values = ds[()]
        except Exception as err:  # noqa: BLE001
            raise InputError(f"{source}: cannot read the data ({_first_line(err)})") from None
    f = _index_field(source, path, member, values)
    attrs = ds.attrs
    spacing = np.ones(len(shape))
    if "origin" in attrs or "spacing" in attrs:
        origin = np.asarray(attrs.get("origin", np.zeros(len(shape))), float).reshape(-1)
        spacing = np.asarray(attrs.get("spacing", np.ones(len(shape))), float).reshape(-1)
        if len(origin) != len(shape) or len(spacing) != len(shape):
            raise InputError(f"{source}: the origin and spacing attributes need {len(shape)} entries each")
        f.bounds = np.stack([origin, origin + spacing * (np.array(shape) - 1)], axis=1)
    for a, dim in enumerate(ds.dims):
        if dim.label:
            f.axis_names[a] = str(dim.label)
        if len(dim):  # a dimension scale: its samples are the axis's coordinates
            scale = np.asarray(dim[0][()], float).reshape(-1)
            if len(scale) == shape[a] and len(scale) > 1:
                step = np.diff(scale)
                if not np.allclose(step, step[0], rtol=1e-6, atol=0):
                    f.notes.append(f"axis {f.axis_names[a]}: its scale is not evenly spaced; the grid uses its ends")
                f.bounds[a] = scale[0], scale[-1]
                spacing[a] = step[0]
                unit = dim[0].attrs.get("units")
                if unit is not None:
                    f.units[a] = unit.decode() if isinstance(unit, bytes) else str(unit)
    units = attrs.get("units")
    if isinstance(units, (list, tuple, np.ndarray)) and len(units) == len(shape):
        f.units = [u.decode() if isinstance(u, bytes) else str(u) for u in units]
    f.physical = True
    return _positive_axes(f, spacing)


# ----------------------------------------------------------------------------- F's values
def parse_levels(text: str | Sequence[float] | float | None) -> list[float] | None:
    """"0.5" or "0.5,120" (constants like pi allowed) -> [0.5, 120.0]; numbers pass through."""
    if text is None:
        return None
    from ._validate import _number

    if isinstance(text, str):
        parts = [p.strip() for p in text.split(",")]
        if any(not p for p in parts):
            raise InputError(f"--level: expected C or C1,C2,..., got {text!r}")
        return [_number(p, "level") for p in parts]
    if isinstance(text, (int, float, np.integer, np.floating)):
        return [_number(text, "level")]   # (a bool: refused there, "must be a number")
    return [_number(v, "level") for v in text]


def load_components(specs: str | Sequence[str], levels=None, bounds=None, *,
                    components: bool | None = None, on_disk: bool | None = None) -> SampledData:
    """F's values from data files: component j is field j minus levels[j].

    specs : one spec or several ("a.npy", "run.npz:u,v", "scan.nii.gz", "sim.h5:/p", "img.vti:rho");
        the fields they name (and each field's components) are F's components in order.
    levels : one number for every component, one per component, or "C1,C2" text (default 0).
    bounds : the box, overriding the files' (any form `extract` takes).
    on_disk : True writes F's values to a memory-mapped temporary file (read slab by slab by
        the sweep); None does so when they take more than `IN_MEMORY_SHARE` of the free memory.

    Refused with one InputError: fields of different grid shapes, a count of levels that is
    neither 1 nor k, a level outside a component's data range (M would be empty), all values NaN.
    """
    return _load(_plan(specs, levels, bounds, components), on_disk)


def _load(plan: _Plan, on_disk: bool | None, mapped: bool = False) -> SampledData:
    """F's values written (in memory, or to a temporary file when on_disk), or with ``mapped`` read from
    the files' memory maps as the run asks for them (`MappedValues`: one pass here for the ranges)."""
    fields, lv = plan.fields, plan.levels
    values: np.ndarray | MappedValues
    if mapped:
        values, on_disk = MappedValues(plan), True
        ranges, nonfinite = _fill(None, fields, lv)
    else:
        if on_disk is None:
            on_disk = plan.value_bytes > IN_MEMORY_SHARE * available_memory()
        written = _output(plan.shape, on_disk)
        ranges, nonfinite = _fill(written, fields, lv)
        values = written
    notes = list(plan.notes)
    for j, (lo, hi) in enumerate(ranges):
        src = _component_name(fields, j)
        if not math.isfinite(lo):
            raise InputError(f"{src}: every value is NaN or infinite")
        if not lo <= lv[j] <= hi:
            raise InputError(f"level {lv[j]:g} is outside the data's range [{lo:g}, {hi:g}] of {src}: M is empty "
                             "(choose a level inside the range)")
    if nonfinite:
        notes.append(f"{nonfinite} samples are NaN or infinite: treated as outside M (no cell touches them)")
    return SampledData(values, plan.bounds, list(fields[0].axis_names), list(fields[0].units), fields, lv, ranges,
                       nonfinite, notes, bool(on_disk))


@dataclass
class _Plan:
    """The fields of a run and what their values will take, known from the headers alone."""

    fields: list[DataField]
    levels: list[float]
    bounds: np.ndarray
    shape: tuple[int, ...]  # F's values: (d1, ..., dn, k)
    notes: list[str]
    recipe: tuple = ()  # (absolute specs, levels, components): what reopens the same fields elsewhere

    @property
    def mappable(self) -> bool:
        """Every field is a memory map of its file: F's values can be read from them slice by slice."""
        return all(_mapped(f.values) for f in self.fields)

    @property
    def value_bytes(self) -> int:
        return math.prod(self.shape) * 8

    @property
    def read_bytes(self) -> int:
        """Bytes of the fields held in memory (read whole: compressed or zipped files); a memory map is not."""
        return sum(int(f.values.nbytes) for f in self.fields if not _mapped(f.values))


def _mapped(a) -> bool:
    while a is not None:
        if isinstance(a, np.memmap):
            return True
        a = a.base if isinstance(a, np.ndarray) else None
    return False


def _plan(specs, levels, bounds, components) -> _Plan:
    if isinstance(specs, (str, os.PathLike)):
        specs = [os.fspath(specs)]
    if not specs:
        raise InputError("no data files given")
    fields = [f for s in specs for f in read_fields(s, components)]
    first = fields[0]
    for f in fields[1:]:
        if f.grid_shape != first.grid_shape:
            raise InputError(f"the data have different grid shapes: {first.source} is "
                             f"{'x'.join(map(str, first.grid_shape))}, {f.source} is "
                             f"{'x'.join(map(str, f.grid_shape))}")
    n = first.n
    k = sum(f.components for f in fields)
    lv = parse_levels(levels) or [0.0]
    if len(lv) == 1:
        lv = lv * k
    if len(lv) != k:
        raise InputError(f"{len(lv)} levels for {k} components of F (give one, or one per component)")
    if not 1 <= k < n:
        raise InputError(f"{k} components on a grid of {n} axes: M = F^-1(0) needs fewer components than axes "
                         "(k < n)")
    notes = [f"{f.source}: {note}" for f in fields for note in f.notes]
    if bounds is not None:
        from ._validate import as_bounds

        box = as_bounds(bounds, n)
    else:
        box = first.bounds.copy()
        for f in fields[1:]:
            if f.physical and first.physical and not np.allclose(f.bounds, box, rtol=1e-6, atol=1e-9):
                notes.append(f"{f.source} has other bounds than {first.source}: the first file's are used")
    recipe = (tuple(os.path.abspath(s) for s in specs), tuple(lv), components)
    return _Plan(fields, lv, box, first.grid_shape + (k,), notes, recipe)


class MappedValues:
    """F's values (data minus levels, float64) computed for the slices asked for only, from the fields
    as read (memory maps of the files, where the format allows): what the budget's probe reads (a
    strided subgrid), a sweep slab by slab and a cluster's tasks block by block, without F's values
    ever whole in memory.  Indexed like the (d1, ..., dn, k) array it stands for: one index per grid
    axis (slices or integers), then optionally the components'.  Pickles as its plan's recipe (the
    files, levels, components): a worker process reopens the memory maps (once) and reads its block."""

    dtype = np.dtype(np.float64)
    reads_slices = True  # (`_validate.prepare` passes it on as it is)

    def __init__(self, plan: _Plan):
        self.plan = plan
        self.shape = plan.shape
        self.ndim = len(plan.shape)

    def __reduce__(self):
        return _reopen, (self.plan.recipe,)

    def __array__(self, dtype=None, copy=None):
        return self[()] if dtype is None else self[()].astype(dtype)

    def __getitem__(self, index) -> np.ndarray:
        index = index if isinstance(index, tuple) else (index,)
        n = self.ndim - 1
        if len(index) > n + 1 or any(i is Ellipsis or i is None for i in index):
            raise IndexError(f"index {index!r}: one index per grid axis, then the component's")
        grid = index[:n]
        wanted = range(self.shape[-1])[index[n]] if len(index) > n else range(self.shape[-1])
        columns = [wanted] if isinstance(wanted, int) else list(wanted)
        if not columns:
            raise IndexError(f"index {index!r} selects no component")
        out = None
        j = 0
        for f in self.plan.fields:
            sub = f.values[grid]
            for c in range(f.components):
                if j in columns:
                    part = sub[..., c] if f.components > 1 else sub
                    if out is None:
                        out = np.empty(part.shape + (len(columns),), np.float64)
                    # (as `_fill` does: the same bytes as F's values written whole)
                    np.subtract(part, self.plan.levels[j], out=out[..., columns.index(j)], dtype=np.float64,
                                casting="unsafe")
                j += 1
        for f in self.plan.fields:
            _drop_pages(f.values)
        assert out is not None   # (every index names at least one component)
        return out[..., 0] if isinstance(wanted, int) else out


@functools.lru_cache(maxsize=4)
def _reopen(recipe) -> MappedValues:
    """The `MappedValues` of a recipe, made once per process (a cluster's worker reads every block of a
    run from the same memory maps)."""
    specs, levels, components = recipe
    return MappedValues(_plan(list(specs), list(levels), None, components))


def estimate_data(specs, levels=None, bounds=None, *, components: bool | None = None, method: str = "gcmh",
                  scheduler=None):
    """What `extract_data` with these arguments will cost (`budget.Estimate`), from the files' headers
    and a probe of a coarse subgrid (no pass over the whole data): the run's estimate plus F's values
    (when they fit in memory) and the fields a format makes us read whole, in ``grid_bytes`` and the peak."""
    return _estimate(_plan(specs, levels, bounds, components), method, scheduler)


def _estimate(plan: _Plan, method, scheduler, probe: bool | None = True):
    """The run's estimate plus the data held; probe: True probes a coarse subgrid of F's values (reading
    the files strided), None takes M to cross the grid like a plane (`budget.estimate_run` without F).
    A run that reads F's values from the files' memory maps (`_reads_maps`) holds none of them."""
    from dataclasses import replace

    from .budget import estimate_run

    n = len(plan.bounds)
    div = [d - 1 for d in plan.shape[:-1]]
    sampled = MappedValues(plan) if probe else None
    cost = estimate_run(n, plan.shape[-1], div, method=method, bounds=plan.bounds, sampled=sampled,
                        scheduler=scheduler, probe=probe)
    on_disk = _reads_maps(plan, method) or plan.value_bytes > IN_MEMORY_SHARE * available_memory()
    held = (0 if on_disk else plan.value_bytes) + plan.read_bytes
    return replace(cost, grid_bytes=cost.grid_bytes + held, peak_bytes=cost.peak_bytes + held)


def _reads_maps(plan: _Plan, method) -> bool:
    """A whole-grid method on memory-mapped files reads F's values from the maps (`MappedValues`): the
    sweep slab by slab, a cluster's workers block by block; otherwise they are written whole first
    (`_load`).  (Continuation reads any cube's values at any time: it takes them written.)  At 256^3
    float32 this holds 130 MB less than F's values written (225 against 356 MB peak RSS) and took 0.9x
    the time of the whole command."""
    from ._methods import CONTINUATION_METHODS

    return method not in CONTINUATION_METHODS and plan.mappable


def field_ranges(f: DataField) -> list[tuple[float, float]]:
    """Each component's finite (min, max) over a field, slab by slab (a memory map is read once, its
    pages released as it goes); (inf, -inf) for a component with no finite value."""
    out = []
    layer = math.prod(f.values.shape[1:])
    step = max(1, _SLAB_SAMPLES // max(1, layer))
    for c in range(f.components):
        lo, hi = math.inf, -math.inf
        for i0 in range(0, f.values.shape[0], step):
            part = f.values[i0:i0 + step]
            part = part[..., c] if f.components > 1 else part
            a, b = float(part.min()), float(part.max())
            if not (math.isfinite(a) and math.isfinite(b)):  # (NaN or inf: only floats have them)
                finite = np.isfinite(part)
                a = float(part.min(initial=np.inf, where=finite))
                b = float(part.max(initial=-np.inf, where=finite))
            lo, hi = min(lo, a), max(hi, b)
        _drop_pages(f.values)
        out.append((lo, hi))
    return out


def _component_name(fields, j) -> str:
    for f in fields:
        if j < f.components:
            return f.source if f.components == 1 else f"{f.source} (component {j})"
        j -= f.components
    return "?"


def _output(shape, on_disk: bool) -> np.ndarray:
    if not on_disk:
        return np.empty(shape, np.float64)
    # a temporary file that is gone from the folder at once (the mapping keeps it while in use)
    fd, path = tempfile.mkstemp(prefix="gcmh-data-", suffix=".npy")
    os.close(fd)
    try:
        return np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=shape)
    finally:
        os.unlink(path)


def _fill(out: np.ndarray | None, fields, levels) -> tuple[list[tuple[float, float]], int]:
    """out[..., j] = component j - level j, slab by slab along axis 0 (out None: nothing written);
    returns each component's finite (min, max) of the data and the count of grid points where some
    value is not finite."""
    grid = fields[0].grid_shape
    d0 = grid[0]
    layer = math.prod(grid[1:])
    step = max(1, _SLAB_SAMPLES // max(layer, 1))
    k = len(levels)
    lo = np.full(k, np.inf)
    hi = np.full(k, -np.inf)
    bad = 0
    for i0 in range(0, d0, step):
        i1 = min(d0, i0 + step)
        slab = None if out is None else out[i0:i1]
        j = 0
        bad_points = None  # (grid points of the slab where some component is not finite)
        for f in fields:
            src = f.values[i0:i1]
            for c in range(f.components):
                part = src[..., c] if f.components > 1 else src
                try:
                    # the data's range in their own type (float32: half the bytes of F's values)
                    a, b = float(part.min()), float(part.max())
                    if slab is not None:
                        np.subtract(part, levels[j], out=slab[..., j], dtype=np.float64, casting="unsafe")
                except OSError as err:  # (a memory-mapped file that shrank or a read error)
                    raise InputError(f"{f.source}: cannot read the data ({_first_line(err)})") from None
                if not (math.isfinite(a) and math.isfinite(b)):  # (NaN or inf: min or max says so)
                    finite = np.isfinite(part)
                    bad_points = ~finite if bad_points is None else bad_points | ~finite
                    a = float(part.min(initial=np.inf, where=finite))
                    b = float(part.max(initial=-np.inf, where=finite))
                lo[j] = min(lo[j], a)
                hi[j] = max(hi[j], b)
                j += 1
        if bad_points is not None:
            bad += int(np.count_nonzero(bad_points))
        for f in fields:
            _drop_pages(f.values)
    return [(float(a), float(b)) for a, b in zip(lo, hi)], bad


def _drop_pages(values) -> None:
    """Unmap the pages of a memory-mapped file this process has read (they stay in the page cache): a
    volume larger than memory is then read slab by slab without the whole file counting as this
    process's memory (its RSS) at the end."""
    import mmap

    a = values
    while isinstance(a, np.ndarray):
        m = getattr(a, "_mmap", None)
        if m is not None:
            if hasattr(m, "madvise") and hasattr(mmap, "MADV_DONTNEED"):
                try:
                    m.madvise(mmap.MADV_DONTNEED)
                except (OSError, ValueError):  # (a closed or odd mapping: only memory use is at stake)
                    pass
            return
        a = a.base


# ----------------------------------------------------------------------------- the run
def extract_data(specs, levels=None, bounds=None, *, components: bool | None = None, data: SampledData | None = None,
                 variables: Sequence[str] | None = None, **kwargs):
    """`extract` on F's values from data files (`load_components`); kwargs go to `extract`
    (method, seed, scheduler, progress, force, ...).  The run is estimated from the headers first
    (`estimate_data`: a run that won't fit is refused before the data are read).  The result's meta
    names the files and levels ("data"), the axes and their units ("variables", "units").
    ``data``: values already loaded (the app's level slider reuses them); ``variables``: names for the
    axes instead of the file's ("x", "y", "z", "t")."""
    from .budget import check_budget
    from .errors import TooLargeError
    from .extract import extract

    try:
        if data is None:
            plan = _plan(specs, levels, bounds, components)
            # before reading the data: with M taken to cross the grid like a plane (`extract` then probes F's
            # values itself); what refuses here is data too large to hold with the run
            check_budget(_estimate(plan, kwargs.get("method", "gcmh"), kwargs.get("scheduler"), probe=None),
                         bool(kwargs.get("force", False)))
            if variables is not None:
                _check_names(variables, len(plan.bounds))
            data = _load(plan, None, _reads_maps(plan, kwargs.get("method", "gcmh")))
        names = list(data.variables) if variables is None else _check_names(variables, data.n)
        # (MappedValues reads as an array where the run asks: `_validate.prepare` passes it through)
        cx = extract(cast(np.ndarray, data.values), data.bounds, **kwargs)
    except TooLargeError as e:
        raise TooLargeError(_data_remedies(str(e))) from None
    cx.meta["variables"] = names
    cx.meta["units"] = list(data.units)
    cx.meta["data"] = {**data.describe(), "variables": names}
    return cx


def _data_remedies(message: str) -> str:
    """The budget's refusal with what can change for data: the grid is the file's (no div to make smaller),
    and continuation would write F's values whole (more memory, not less)."""
    head, sep, _ = message.rpartition("); ")
    if not sep:
        return message
    return (f"{head}); the grid is the file's samples: subsample the volume (e.g. save vol[::2, ::2, ::2] as "
            ".npy), run it on a cluster (--scheduler), or --force (force=True) to run anyway")


def _check_names(names, n: int) -> list[str]:
    names = [str(v) for v in names]
    if len(names) != n:
        raise InputError(f"{len(names)} axis names for data with {n} axes")
    return names


def _first_line(err) -> str:
    text = str(err).strip().splitlines()
    return text[0][:200] if text else type(err).__name__
