"""Mesh files for drawings, read defensively: regular files only, a size cap, parsed first.

A URDF's mesh may be missing, a FIFO or a device (``/dev/zero``), huge, or corrupt. Sent
as-is, the browser's mesh loader throws and the whole page stays empty. Here every mesh
is checked before it is embedded:

- :func:`os.stat` first: only a regular file is opened (a FIFO would block, a device
  would never end);
- at most :data:`MAX_MESH_BYTES` bytes (default 64 MB; override with ``max_mesh_bytes=``
  or the ``ROBODYN_MAX_MESH_MB`` environment variable);
- parsed with trimesh (STL, OBJ, DAE): it must hold finite vertices; their bounds frame
  the camera.

A mesh that fails becomes a :class:`MeshFileError`; the scene draws a placeholder box
in its place and warns (:class:`MeshWarning`), so a recording never shows an empty page.
"""

from __future__ import annotations

import functools
import io
import os
import stat
from pathlib import Path
from typing import cast

import meshcat.geometry as mg
import numpy as np
import umsgpack

from robodyn.exceptions import MeshFileError

#: Largest mesh file drawn, in bytes (``ROBODYN_MAX_MESH_MB`` overrides, in MB).
MAX_MESH_BYTES = int(float(os.environ.get("ROBODYN_MAX_MESH_MB", "64")) * 1_000_000)
FORMATS = {".stl": "stl", ".obj": "obj", ".dae": "dae"}


def read_mesh(path: str | os.PathLike, *, max_bytes: int = MAX_MESH_BYTES) -> tuple[mg.MeshGeometry, np.ndarray]:
    """The meshcat geometry of a mesh file and its vertices' bounds.

    Args:
        path: An STL, OBJ or DAE file.
        max_bytes: Largest accepted file size in [byte].

    Returns:
        The geometry and the bounds, shape (2, 3): lowest and highest corner in the mesh's
        own frame, in the file's units (before the URDF's ``scale``).

    Raises:
        MeshFileError: If the file is not a regular file, is empty or larger than
            ``max_bytes``, has an unknown extension or does not parse to finite vertices.
    """
    path = Path(path)
    try:
        info = os.stat(path)
    except OSError as error:
        raise MeshFileError(path, f"cannot be read ({error.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        raise MeshFileError(path, "is not a regular file")
    if info.st_size > max_bytes:
        raise MeshFileError(path, f"has {info.st_size} bytes, over the cap of {max_bytes} (max_mesh_bytes / ROBODYN_MAX_MESH_MB)")
    if info.st_size == 0:
        raise MeshFileError(path, "is empty")
    kind = FORMATS.get(path.suffix.lower())
    if kind is None:
        raise MeshFileError(path, f"has an extension robodyn cannot draw ({path.suffix!r}; STL, OBJ, DAE are drawn)")
    return _parsed(str(path), info.st_size, info.st_mtime_ns, kind, max_bytes)


@functools.lru_cache(maxsize=256)
def _parsed(path: str, size: int, mtime_ns: int, kind: str, max_bytes: int) -> tuple[mg.MeshGeometry, np.ndarray]:
    try:
        with open(path, "rb", buffering=0) as handle:
            if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):  # swapped since the stat
                raise MeshFileError(Path(path), "is not a regular file")
            data = handle.read(max_bytes + 1)
    except OSError as error:
        raise MeshFileError(Path(path), f"cannot be read ({error.strerror})") from None
    if len(data) > max_bytes:
        raise MeshFileError(Path(path), f"grew over the cap of {max_bytes} bytes while read")
    bounds = _bounds(data, kind, Path(path))
    if kind == "stl":
        contents = umsgpack.Ext(0x12, data)  # meshcat's tag for a uint8 array, as StlMeshGeometry sends it
        return mg.MeshGeometry(contents, "stl"), bounds
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise MeshFileError(Path(path), "is not UTF-8 text") from None
    return mg.MeshGeometry(text, kind), bounds


def _bounds(data: bytes, kind: str, path: Path) -> np.ndarray:
    import logging

    import trimesh

    logging.getLogger("trimesh").setLevel(logging.ERROR)
    try:
        # force="mesh" makes the Geometry trimesh.load is typed to return a Trimesh
        mesh = cast("trimesh.Trimesh", trimesh.load(io.BytesIO(data), file_type=kind, force="mesh"))
        vertices = np.asarray(mesh.vertices, dtype=float)
    except Exception as error:  # trimesh and its parsers raise many kinds
        raise MeshFileError(path, f"is not a valid {kind.upper()} file ({type(error).__name__})") from None
    if vertices.ndim != 2 or len(vertices) == 0 or not np.isfinite(vertices).all():
        raise MeshFileError(path, f"is not a valid {kind.upper()} file (no finite vertices)")
    return np.array([vertices.min(axis=0), vertices.max(axis=0)])
