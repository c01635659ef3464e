"""Sessions and exports of GCMH Studio, without Qt.

A session is a JSON file (format ``gcmh-session/1``): the title, the Manifold
tab's system, the View tab's view, the camera and whether the user held it
("keep camera"; files written before it was saved load as not held). Exports write the cell
complex (.npz or .vtu) or the projected 3D mesh (.ply, .obj, .vtp, .stl,
.vtk). The window asks for the paths and reports; the files are written here.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from .session_schema import SESSION_FORMAT

MESH_FORMATS = (".ply", ".obj", ".vtp", ".stl", ".vtk")


def camera_state(camera) -> dict:
    """A pyvista camera as plain numbers."""
    return {"position": list(camera.position), "focal_point": list(camera.focal_point), "up": list(camera.up),
            "parallel_scale": float(camera.parallel_scale), "view_angle": float(camera.view_angle)}


def apply_camera(camera, state: dict) -> None:
    """Put a :func:`camera_state` back on a pyvista camera (view angle and scale when given)."""
    camera.position = state["position"]
    camera.focal_point = state["focal_point"]
    camera.up = state["up"]
    camera.view_angle = state.get("view_angle", camera.view_angle)
    camera.parallel_scale = state.get("parallel_scale", camera.parallel_scale)


def valid_camera(state) -> dict | None:
    """``state`` if it is a usable :func:`camera_state` (three finite numbers for the position, focal
    point and up, an eye apart from the focal point, a positive view angle and scale if given), else None:
    a hand-edited file must not put a traceback or a blank view on the screen."""
    import math

    if not isinstance(state, dict):
        return None

    def vec(key):
        v = state.get(key)
        if not isinstance(v, (list, tuple)) or len(v) != 3:
            return None
        try:
            v = [float(x) for x in v]
        except (TypeError, ValueError):
            return None
        return v if all(math.isfinite(x) for x in v) else None

    pos, focal, up = vec("position"), vec("focal_point"), vec("up")
    if pos is None or focal is None or up is None or pos == focal or not any(up):
        return None
    out = {"position": pos, "focal_point": focal, "up": up}
    for key, hi in (("view_angle", 179.0), ("parallel_scale", math.inf)):
        if key in state:
            try:
                x = float(state[key])
            except (TypeError, ValueError):
                return None
            if not (0.0 < x < hi):
                return None
            out[key] = x
    return out


def session_dict(model, camera: dict) -> dict:
    """The session of an :class:`gcmh_studio.model.StudioModel` with a :func:`camera_state` and its "keep camera"
    toggle (the camera is saved either way; opening puts it back exactly when it was held)."""
    return {"format": SESSION_FORMAT, "title": model.title, "system": dict(model.system), "view": model.view_state(),
            "camera": camera, "keep_camera": bool(model.style.keep_camera)}


def session_camera(session: dict) -> tuple[dict | None, bool]:
    """(camera, keep) of a :func:`read_session` result: the saved camera (None if there is none or it is
    not usable) and whether the user held it (False for files saved before the toggle was)."""
    keep = session.get("keep_camera", False)
    return valid_camera(session.get("camera")), keep if isinstance(keep, bool) else False


def write_session(path, session: dict) -> Path:
    """Write ``session`` to ``path`` atomically: a full disk or an interrupted write leaves the old file as it was
    and no temporary (OSError, or InputError for a path that cannot be written)."""
    from gcmh_core.safe_io import atomic_write

    data = (json.dumps(session, indent=2, allow_nan=False) + "\n").encode("utf-8")

    def write(temp):
        with open(temp, "wb") as f:
            f.write(data)

    atomic_write(path, write, ".json", what=str(path))
    return Path(path)


def read_session(path) -> dict:
    """The session in ``path``, checked whole (:func:`gcmh_studio.session_schema.validate_session`); ValueError
    with a one-line message if it is not one that can be opened (OSError if unreadable)."""
    from .session_schema import MAX_SESSION_BYTES, SessionError, validate_session

    with open(path, "rb") as f:   # (a 100 MB title is refused by its size, not read)
        raw = f.read(MAX_SESSION_BYTES + 1)
    if len(raw) > MAX_SESSION_BYTES:
        raise SessionError(f"the file is larger than {MAX_SESSION_BYTES >> 20} MB: not a session the app wrote")
    try:
        d = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise SessionError(f"not a text file ({e.reason} at byte {e.start})") from None
    except json.JSONDecodeError as e:
        raise SessionError(str(e)) from None
    except RecursionError:
        raise SessionError("nested too deeply: not a session the app wrote") from None
    except ValueError as e:   # (an integer of more than 4300 digits)
        raise SessionError(str(e)) from None
    validate_session(d)
    if d.get("data") is not None:   # (a data source: its files where the session says, or one line saying not)
        from .data_source import moved_file

        problem = moved_file(d["data"])
        if problem:
            raise SessionError(problem)
    d["camera"], d["keep_camera"] = session_camera(d)
    return d


def export_complex(cx, path) -> str:
    """Write ``cx`` as .vtu (VTK) or .npz (the library's format; added when the name has neither); returns the path."""
    if cx is None:
        raise ValueError("nothing to export: no result yet")
    path = str(path)
    if path.lower().endswith(".vtu"):
        cx.save_vtu(path)
    else:
        if not path.lower().endswith(".npz"):
            path += ".npz"
        cx.save(path)
    return path


def export_mesh(mesh, path, dim: int | None) -> str:
    """Write a projected pyvista mesh; surfaces are triangulated for .ply, .obj and .stl.

    Colours: a mesh with ``RGB`` (V, 3) uint8 point data (the colours on screen) writes them as the
    PLY's vertex colours and as the OBJ's ``v x y z r g b`` (the extension MeshLab and Blender read)."""
    path = str(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in MESH_FORMATS:
        raise ValueError(f"unknown mesh format {ext!r}: use .ply, .obj or .vtp")
    if ext in (".ply", ".obj", ".stl") and dim is not None and dim >= 2:
        mesh = mesh.triangulate()
    rgb = "RGB" in mesh.point_data.keys()
    if ext == ".ply" and rgb:
        mesh.save(path, texture="RGB")
    elif ext == ".obj" and rgb:
        write_obj(mesh, path)
    else:
        mesh.save(path)
    return path


def _cells(arr, prefix: str, f) -> None:
    """Write a VTK legacy cell array (``[m, v.., m, v..]``) as OBJ rows ``prefix v1 .. vm`` (1-based)."""
    import numpy as np

    arr = np.asarray(arr, dtype=np.int64)
    if len(arr) == 0:
        return
    m = int(arr[0])
    if len(arr) % (m + 1) == 0 and np.all(arr[:: m + 1] == m):   # all of one size: at once
        np.savetxt(f, arr.reshape(-1, m + 1)[:, 1:] + 1, fmt=prefix + " %d" * m)
        return
    i = 0
    while i < len(arr):
        m = int(arr[i])
        f.write(prefix + " " + " ".join(str(int(v) + 1) for v in arr[i + 1:i + 1 + m]) + "\n")
        i += m + 1


def write_obj(mesh, path) -> None:
    """A Wavefront OBJ with vertex colours: ``v x y z r g b`` (r, g, b in 0..1), then the faces or lines."""
    import numpy as np

    P = np.asarray(mesh.points, dtype=np.float64)
    C = np.asarray(mesh.point_data["RGB"], dtype=np.float64)[:, :3] / 255.0
    with open(path, "w", encoding="ascii") as f:
        f.write("# GCMH Studio: the projected mesh, vertex colours as on screen\n")
        np.savetxt(f, np.hstack([P, C]), fmt="v %.7g %.7g %.7g %.4f %.4f %.4f")
        _cells(mesh.faces, "f", f)
        _cells(mesh.lines, "l", f)
