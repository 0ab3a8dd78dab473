"""Mesh formats read through the field's libraries: trimesh (GLB/GLTF, 3MF) and meshio (VTK, VTU, Gmsh, Medit,
Abaqus, Nastran, SU2).

These readers return the raw ``(V, flat, sizes)`` polygon soup that :func:`gsdf.io.read_mesh` validates and
(optionally) fan-triangulates, exactly as for its own OBJ/OFF/PLY/STL parsers. Nothing is merged, reordered or
dropped: trimesh is called with ``process=False`` and every mesh of a scene is placed by its node transform and
appended in scene order; meshio's surface cells (triangles, quads, polygons, and the corner vertices of
higher-order triangles and quads) are taken block by block in file order, its points as stored (2D points get
z = 0). Volume cells (tetrahedra, hexahedra, ...) are not a surface and are ignored, except in a file whose only
cells are tetrahedra: its surface is then the boundary of the tets (the triangles used by one tet, outward). A
file with other volume cells only is refused with a message saying so. Gmsh element or node data that meshio
cannot attach to the cells (data over the tets of a file that also has triangles) is skipped.

OBJ, OFF, PLY and STL stay with gsdf's own parsers (:mod:`gsdf.io._mesh`): trimesh with ``process=False`` still
drops unreferenced OBJ vertices and regroups OFF faces by polygon size, and meshio refuses OFF polygons and OBJ
texture coordinates that do not match the vertex count — while gsdf must give back broken soups exactly as
stored, with their polygons.
"""

from __future__ import annotations

import re

import numpy as np

__all__ = ["TRIMESH_FORMATS", "MESHIO_FORMATS", "read_external"]

#: Read with trimesh (``.3mf`` needs trimesh's optional dependencies lxml and networkx).
TRIMESH_FORMATS = (".glb", ".gltf", ".3mf")
#: Read with meshio.
MESHIO_FORMATS = (".vtk", ".vtu", ".msh", ".mesh", ".inp", ".bdf", ".nas", ".su2")

# meshio cell type -> number of corner vertices that form the polygon (higher-order cells: their corners first)
_SURFACE_CELLS = {"triangle": 3, "triangle6": 3, "triangle7": 3, "quad": 4, "quad8": 4, "quad9": 4}


def read_external(p: str, ext: str):
    """``(V (n, 3) float64, flat int64, sizes int64)`` of the polygons in ``p`` (an extension listed above)."""
    if ext in TRIMESH_FORMATS:
        return _read_trimesh(p, ext)
    return _read_meshio(p, ext)


def _read_trimesh(p: str, ext: str):
    import trimesh

    try:
        scene = trimesh.load(p, file_type=ext[1:], process=False, force="scene")
    except ImportError as exc:
        raise ValueError(f"{p}: reading {ext} files needs an optional package trimesh uses ({exc.name or exc}); "
                         "install it, e.g. pip install lxml networkx") from exc
    except Exception as exc:  # trimesh raises many types for malformed files: report them as bad input
        raise ValueError(f"{p}: not a readable {ext[1:].upper()} file ({error_words(exc)})") from exc
    Vs, Fs, offset = [], [], 0
    rank = {name: i for i, name in enumerate(scene.geometry)}  # the file's mesh order
    nodes = sorted(scene.graph.nodes_geometry, key=lambda n: (rank.get(scene.graph[n][1], len(rank)), str(n)))
    for node in nodes:
        transform, name = scene.graph[node]
        geom = scene.geometry.get(name)
        if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
            continue  # point clouds, paths
        V = np.asarray(geom.vertices, dtype=np.float64)
        V = V @ transform[:3, :3].T + transform[:3, 3]
        Vs.append(V)
        Fs.append(np.asarray(geom.faces, dtype=np.int64) + offset)
        offset += len(V)
    if not Vs:
        raise ValueError(f"{p}: no faces; is this a point cloud? use read_points")
    F = np.concatenate(Fs)
    return np.concatenate(Vs), F.ravel(), np.full(len(F), 3, dtype=np.int64)


def _read_meshio(p: str, ext: str):
    m = _read_meshio_raw(p, ext)
    P = np.asarray(m.points, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] not in (2, 3):
        raise ValueError(f"{p}: expected 2D or 3D points, got an array of shape {P.shape}")
    if P.shape[1] == 2:
        P = np.column_stack([P, np.zeros(len(P))])
    flats, sizes, volume = [], [], set()
    for block in m.cells:
        data = np.asarray(block.data)
        if block.type in _SURFACE_CELLS:
            k = _SURFACE_CELLS[block.type]
        elif block.type.startswith("polygon") and data.ndim == 2:
            k = data.shape[1]
        else:
            if block.type not in ("vertex", "line", "line3"):
                volume.add(block.type)
            continue
        if len(data) == 0:
            continue
        flats.append(data[:, :k].astype(np.int64).ravel())
        sizes.append(np.full(len(data), k, dtype=np.int64))
    if not flats:
        if volume == {"tetra"}:
            T = np.concatenate([np.asarray(b.data, dtype=np.int64) for b in m.cells if b.type == "tetra"])
            F = tet_boundary(P, T)
            return P, F.ravel(), np.full(len(F), 3, dtype=np.int64)
        if volume:
            raise ValueError(f"{p}: has only volume cells ({', '.join(sorted(volume))}), no surface faces")
        raise ValueError(f"{p}: no faces; is this a point cloud? use read_points")
    return P, np.concatenate(flats), np.concatenate(sizes)


def tet_boundary(P, T):
    """The triangles of tets ``T`` used by exactly one tet, oriented outward (a tet of negative volume has its
    faces reversed), in tet order."""
    T = np.asarray(T, dtype=np.int64).reshape(-1, 4)
    a, b, c, d = (P[T[:, i]] for i in range(4))
    neg = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    Fc = np.stack([T[:, [1, 2, 3]], T[:, [0, 3, 2]], T[:, [0, 1, 3]], T[:, [0, 2, 1]]], axis=1)
    Fc[neg] = Fc[neg][:, :, ::-1]
    Fc = Fc.reshape(-1, 3)
    _, inv, cnt = np.unique(np.sort(Fc, axis=1), axis=0, return_inverse=True, return_counts=True)
    return Fc[cnt[inv.reshape(-1)] == 1]


def _read_meshio_raw(p: str, ext: str):
    """meshio.read with its prints and sys.exit turned into a ValueError naming the file."""
    import contextlib
    import io
    import logging
    import warnings

    import meshio

    if ext in (".vtk", ".vtu"):
        _check_vtk_counts(p, ext)
    said = io.StringIO()
    log = logging.getLogger("meshio")
    level = log.level
    try:
        # meshio prints its complaints and calls sys.exit(1) when no reader succeeds: capture both
        log.setLevel(logging.CRITICAL)
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                m = meshio.read(p)
            except Exception:
                m = _read_gmsh_without_data(meshio, p) if ext == ".msh" else None
                if m is None:
                    raise
    except (Exception, SystemExit) as exc:  # ReadError, ValueError, KeyError, struct errors, SystemExit ...
        why = " ".join(said.getvalue().split()) or error_words(exc)
        raise ValueError(f"{p}: not a readable {ext[1:].upper()} file ({why})") from None
    finally:
        log.setLevel(level)
    return m


def error_words(exc: BaseException) -> str:
    """What a library's exception on a malformed file means, in words (not Python's text for the decoding and
    allocation failures)."""
    if isinstance(exc, UnicodeDecodeError):
        bad = exc.object[exc.start:exc.start + 1].hex() if exc.start < len(exc.object) else "?"
        return f"a line that should be text holds a byte that is not text (0x{bad})"
    m = re.search(r"cannot reshape array of size (\d+) into shape (\([^)]*\))", str(exc))
    if isinstance(exc, ValueError) and m:
        return (f"its counts declare an array of shape {m.group(2)} but it stores {int(m.group(1)):,} values; the "
                "file is corrupt or truncated")
    if isinstance(exc, IndexError):
        return "an index or a count in the file does not match its data; the file is corrupt or truncated"
    if isinstance(exc, MemoryError):
        return "a count in the file asks for more memory than there is; the file is corrupt or truncated"
    return f"{type(exc).__name__}: {exc}"


#: legacy VTK keywords followed by counts: the values each count stands for (POINTS n: 3n coordinates; the cell
#: sections' last number is the size of their index list)
_VTK_COUNTS = re.compile(rb"(?m)^[ \t]*(POINTS|CELLS|POLYGONS|LINES|VERTICES|TRIANGLE_STRIPS|CELL_TYPES|"
                         rb"POINT_DATA|CELL_DATA)[ \t]+(\d+)(?:[ \t]+(\d+))?")
#: the counts of a VTU piece
_VTU_COUNTS = re.compile(rb"(NumberOfPoints|NumberOfCells)\s*=\s*[\"'](-\d+)")


def _check_vtk_counts(p: str, ext: str) -> None:
    """Refuse a VTK file whose counts cannot be right, before meshio allocates arrays of that size or takes
    them: a legacy ``.vtk`` count larger than the file could hold (every value takes at least one byte, in text
    and binary files alike), a negative ``.vtu`` point or cell count (VTU data may be compressed, so only the
    sign of its counts can be checked here)."""
    import mmap
    import os

    size = os.path.getsize(p)
    if size == 0:
        return
    with open(p, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
        if ext == ".vtu":
            m = _VTU_COUNTS.search(data)
            if m:
                raise ValueError(f"{p}: not a readable VTU file ({m.group(1).decode()} is negative: "
                                 f"{m.group(2).decode()})")
            return
        for m in _VTK_COUNTS.finditer(data):
            key, n = m.group(1).decode(), int(m.group(2))
            values = 3 * n if key == "POINTS" else max(n, int(m.group(3) or 0))
            if values > size:
                raise ValueError(f"{p}: not a readable VTK file ({key} {m.group(2).decode()} declares {values:,} "
                                 f"values, more than the {size:,} bytes of the file hold; it is corrupt or "
                                 "truncated)")


_GMSH_DATA = (b"ElementData", b"NodeData", b"ElementNodeData")


def _read_gmsh_without_data(meshio, p: str):
    """A Gmsh file meshio refuses because of its data sections (e.g. element data over the tets of a file that
    also has triangles: "Incompatible cell data"), read again without them; None when it has none."""
    import os
    import re
    import tempfile

    with open(p, "rb") as fh:
        data = fh.read()
    pat = rb"(^|\n)\$(" + b"|".join(_GMSH_DATA) + rb")\r?\n.*?\$End\2\r?\n"
    stripped, n = re.subn(pat, rb"\1", data, flags=re.S)
    if n == 0:
        return None
    fd, tmp = tempfile.mkstemp(suffix=".msh")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(stripped)
        return meshio.read(tmp, file_format="gmsh")
    finally:
        os.unlink(tmp)
