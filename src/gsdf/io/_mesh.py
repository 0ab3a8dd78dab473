"""Reading and writing triangle meshes and polygon soups: OBJ, OFF, PLY, STL.

The text parsers (OBJ, OFF, ASCII PLY, and the point formats of :mod:`gsdf.io._points`) share
:class:`_Table`: the file is split into non-empty lines with numpy, each block of lines with the
same number of values (vertices, triangles) is converted by a single ``np.loadtxt`` call, and
only irregular blocks (mixed polygon sizes, colours on some lines) fall back to a token-wise
gather.  Binary PLY goes through ``plyfile``; STL (binary or ASCII) is read with numpy.

Conventions shared by every reader:

* polygons are **fan-triangulated**: a face ``(a, b, c, d, ...)`` becomes ``(a, b, c)``,
  ``(a, c, d)``, ...; ``triangulate=False`` keeps the polygons instead;
* degenerate and duplicate faces are **kept** (the winding-number and distance code handles
  them); faces with fewer than 3 vertices are kept as polygons but give no triangle;
* problems raise ``FileNotFoundError`` (missing file) or a ``ValueError`` whose message starts
  with the file path and, for text formats, names the offending line.
"""

from __future__ import annotations

import codecs
import io
import os
import re

import numpy as np

from gsdf._checks import as_faces, as_points, as_values, flag, readable_file
from gsdf.io._external import MESHIO_FORMATS, TRIMESH_FORMATS, error_words, read_external
from gsdf.io._safe_write import atomic_output

__all__ = ["read_mesh", "write_mesh", "read_vertex_data"]

#: Formats gsdf parses itself (exactly as stored: order, duplicates, unreferenced vertices, polygons).
MESH_FORMATS = (".obj", ".off", ".ply", ".stl")
#: Every extension :func:`read_mesh` accepts (the others through trimesh / meshio, :mod:`gsdf.io._external`).
MESH_READ_FORMATS = MESH_FORMATS + TRIMESH_FORMATS + MESHIO_FORMATS
#: Every extension :func:`write_mesh` accepts (``.vtk``/``.vtu`` through meshio).
MESH_WRITE_FORMATS = MESH_FORMATS + (".vtk", ".vtu")

# ----------------------------------------------------------------------------------------------
# helpers shared with points_io
# ----------------------------------------------------------------------------------------------


def _extension(path, supported, what: str) -> tuple[str, str]:
    """Return ``(path as str, lower-case extension)`` or raise for an unsupported extension."""
    try:
        p = os.fsdecode(os.fspath(path))
    except TypeError:
        raise ValueError(f"path: expected a file name, got {type(path).__name__} {path!r:.40}") from None
    ext = os.path.splitext(p)[1].lower()
    if ext not in supported:
        raise ValueError(
            f"{p}: unsupported {what} file extension {ext or '(none)'!r}; supported: {', '.join(supported)}"
        )
    return p, ext


def _check_file(p: str) -> None:
    """Raise FileNotFoundError for a missing path, ValueError for anything but a readable regular file of a size
    that fits in memory (:func:`gsdf._checks.readable_file`) and for an empty file."""
    readable_file(p)
    if os.path.getsize(p) == 0:
        raise ValueError(f"{p}: file is empty")


def _read_bytes(p: str) -> bytes:
    _check_file(p)
    with open(p, "rb") as fh:
        return fh.read()


class _Table:
    """A text file as rows: its non-empty lines, after removing ``#`` comments.

    Row ``r`` is line ``lines[r]`` of the file and holds ``counts[r]`` whitespace-separated
    tokens, ``tokens[start[r]:start[r + 1]]`` (the token list is built only when needed).
    """

    def __init__(self, path: str, data: bytes, comments: bool = True, line_offset: int = 0):
        if data.startswith(codecs.BOM_UTF8):
            data = data[len(codecs.BOM_UTF8):]
        if comments and b"#" in data:
            data = re.sub(rb"#[^\n]*", b"", data)
        if b"\n" not in data and b"\r" in data:  # old Mac line endings
            data = data.replace(b"\r", b"\n")
        b = np.frombuffer(data, np.uint8)
        ws = (b == 32) | ((b >= 9) & (b <= 13))  # exactly the bytes that bytes.split() splits on
        first = ~ws
        first[1:] &= ws[:-1]
        self.tokpos = np.flatnonzero(first)  # byte offset of every token
        self.newlines = np.flatnonzero(b == 10)
        ends = np.searchsorted(self.tokpos, self.newlines)  # tokens before each newline
        per_line = np.diff(ends, prepend=0, append=len(self.tokpos))
        self.keep = np.flatnonzero(per_line)  # 0-based line index of each row
        self.lines = self.keep + 1 + line_offset
        self.counts = per_line[self.keep]
        self.start = np.concatenate(([0], np.cumsum(self.counts)))
        self.path, self.data, self._tokens = path, data, None

    def __len__(self) -> int:
        return len(self.counts)

    @property
    def tokens(self) -> list:
        if self._tokens is None:
            self._tokens = self.data.split()
        return self._tokens

    def row_tokens(self, r: int) -> list:
        """The tokens of row ``r`` (without splitting the whole file)."""
        return self.data[self.tokpos[self.start[r]]: self._row_end(r)].split()

    def _row_end(self, r: int) -> int:
        line = self.keep[r]
        return int(self.newlines[line]) if line < len(self.newlines) else len(self.data)

    def error(self, row, msg: str) -> ValueError:
        return ValueError(f"{self.path}: line {self.lines[row]}: {msg}")

    def keyword_rows(self, word: bytes) -> np.ndarray:
        """Rows whose first token is exactly ``word`` (e.g. ``b"v"`` in OBJ)."""
        b = np.frombuffer(self.data + b" " * (len(word) + 1), np.uint8)
        pos = self.tokpos[self.start[:-1]]
        hit = np.ones(len(pos), bool)
        for i, c in enumerate(word):
            hit &= b[pos + i] == c
        nxt = b[pos + len(word)]
        return np.flatnonzero(hit & ((nxt == 32) | ((nxt >= 9) & (nxt <= 13))))

    def numbers(self, idx) -> np.ndarray:
        """Tokens at ``idx`` (a slice or an index array) as float64; names the line of a bad one."""
        tok = self.tokens
        toks = tok[idx] if isinstance(idx, slice) else [tok[i] for i in np.asarray(idx).ravel().tolist()]
        try:
            return np.array(toks, dtype=np.float64)
        except ValueError:
            pass
        for j, t in enumerate(toks):
            try:
                float(t)
            except ValueError:
                break
        k = idx.start + j if isinstance(idx, slice) else int(np.asarray(idx).ravel()[j])
        row = int(np.searchsorted(self.start, k, side="right")) - 1
        raise self.error(row, f"non-numeric value {t.decode(errors='replace')!r}") from None

    def columns(self, rows, skip: int, ncol: int, what: str) -> np.ndarray:
        """(len(rows), ncol) float64: values ``skip .. skip + ncol - 1`` of each row."""
        rows = np.asarray(rows, dtype=np.int64)
        short = np.flatnonzero(self.counts[rows] < skip + ncol)
        if short.size:
            r = rows[short[0]]
            raise self.error(r, f"{what}: expected {ncol} values, got {self.counts[r] - skip}")
        if rows.size and np.all(self.counts[rows] == self.counts[rows[0]]) and np.all(np.diff(rows) == 1):
            A = self._loadtxt(rows[0], rows[-1] + 1, range(skip, skip + ncol))
            if A is not None and A.shape == (len(rows), ncol):
                return A
        idx = self.start[rows][:, None] + skip + np.arange(ncol)  # irregular rows or a parse error
        return self.numbers(idx).reshape(-1, ncol)

    def _loadtxt(self, r0: int, r1: int, usecols) -> np.ndarray | None:
        """Fast path: parse rows r0..r1-1 with one ``np.loadtxt`` call (None on failure)."""
        a, b = self.tokpos[self.start[r0]], self._row_end(r1 - 1)
        try:
            return np.loadtxt(io.BytesIO(self.data[a:b]), dtype=np.float64, comments=None,
                              usecols=usecols, ndmin=2, encoding="latin1")
        except ValueError:
            return None

    def integers(self, values: np.ndarray, rows_of_values: np.ndarray, what: str) -> np.ndarray:
        """Check parsed floats are integral (and not absurdly large) and return them as int64."""
        bad = np.flatnonzero(~(np.abs(values) < 2.0**53) | (values != np.floor(values)))
        if bad.size:
            raise self.error(rows_of_values[bad[0]], f"{what} must be an integer, got {float(values[bad[0]])!r}")
        return values.astype(np.int64)

    def ragged(self, rows, first_offset, sizes) -> np.ndarray:
        """Concatenated ``sizes[i]`` values of each row, starting at token ``first_offset[i]``."""
        offs = np.arange(int(sizes.sum())) - np.repeat(np.cumsum(sizes) - sizes, sizes)
        return self.numbers(np.repeat(self.start[rows] + first_offset, sizes) + offs)


def _format_rows(A: np.ndarray, prefix: str = "") -> str:
    """Rows of ``A`` as text lines; floats are printed with ``repr`` (exact round trip)."""
    if A.shape[0] == 0:
        return ""
    vals = A.ravel().tolist()
    if A.dtype.kind == "f":
        vals = list(map(repr, vals))
    return ((prefix + " ".join(["%s"] * A.shape[1]) + "\n") * A.shape[0]) % tuple(vals)


def _write_text(p: str, text: str) -> None:
    with open(p, "w", encoding="ascii", newline="\n") as fh:
        fh.write(text)


# ----------------------------------------------------------------------------------------------
# PLY (shared with points_io): ASCII parsed with _Table, binary with plyfile
# ----------------------------------------------------------------------------------------------

_FACE_LISTS = ("vertex_indices", "vertex_index")


def _ply_header(p: str, data: bytes):
    """Parse the header: (format, [(element, count, [(property, is_list)])], body offset, lines)."""
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError(f"{p}: not a PLY file (missing 'ply' magic line or 'end_header')")
    eol = data.find(b"\n", end)
    body = len(data) if eol < 0 else eol + 1
    fmt, elements = None, []
    lines = data[:end].decode("ascii", errors="replace").splitlines()
    for i, line in enumerate(lines[1:], start=2):
        w = line.split()
        try:
            if not w or w[0] in ("comment", "obj_info"):
                continue
            if w[0] == "format":
                fmt = w[1]
            elif w[0] == "element":
                count = int(w[2])
                if count < 0:
                    raise ValueError(f"{p}: line {i}: negative element count {count} for PLY element {w[1]!r}")
                elements.append((w[1], count, []))
            elif w[0] == "property":
                elements[-1][2].append((w[-1], w[1] == "list"))
            else:
                raise ValueError
        except (ValueError, IndexError) as exc:
            if str(exc).startswith(p):
                raise
            raise ValueError(f"{p}: line {i}: malformed PLY header line {line.strip()!r}") from None
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise ValueError(f"{p}: unknown PLY format {fmt!r}")
    return fmt, elements, body, len(lines) + 1


def _ply_pick(p: str, names: list, get):
    """(V, N or None) from vertex properties, ``get(i)`` giving column i of the vertex element."""
    if not all(c in names for c in "xyz"):
        raise ValueError(f"{p}: PLY vertex element lacks x, y, z properties")
    V = np.column_stack([get(names.index(c)) for c in "xyz"]).astype(np.float64)
    for trio in (("nx", "ny", "nz"), ("normal_x", "normal_y", "normal_z")):
        if all(c in names for c in trio):
            return V, np.column_stack([get(names.index(c)) for c in trio]).astype(np.float64)
    return V, None


def _ply_ascii(p: str, data: bytes, elements, body: int, header_lines: int):
    tab = _Table(p, data[body:], comments=False, line_offset=header_lines)
    V = N = flat = sizes = None
    row = 0
    for name, count, props in elements:
        if row + count > len(tab):
            raise ValueError(f"{p}: PLY element {name!r} announces {count} lines but the file ends after "
                             f"{len(tab) - row}")
        rows = np.arange(row, row + count)
        if name == "vertex":
            if any(is_list for _, is_list in props):
                raise ValueError(f"{p}: list properties in the PLY vertex element are not supported")
            bad = np.flatnonzero(tab.counts[rows] != len(props))
            if bad.size:
                raise tab.error(rows[bad[0]], f"vertex: expected {len(props)} values, got {tab.counts[rows[bad[0]]]}")
            A = tab.columns(rows, 0, len(props), "vertex")
            V, N = _ply_pick(p, [n for n, _ in props], lambda i: A[:, i])
        elif name == "face" and count:
            flat, sizes = _ply_ascii_faces(tab, rows, props)
        row += count
    if V is None:
        raise ValueError(f"{p}: PLY file has no 'vertex' element")
    return V, N, flat, sizes


def _ply_ascii_faces(tab: _Table, rows, props):
    """Walk the properties of every face line at once (one pointer per line)."""
    ptr = np.zeros(len(rows), np.int64)
    flat = sizes = None
    for name, is_list in props:
        if np.any(ptr >= tab.counts[rows]):
            r = rows[np.argmax(ptr >= tab.counts[rows])]
            raise tab.error(r, f"face: missing value for property {name!r}")
        if not is_list:
            ptr += 1
            continue
        n = tab.integers(tab.numbers(tab.start[rows] + ptr), rows, "list length")
        over = np.flatnonzero((n < 0) | (ptr + 1 + n > tab.counts[rows]))
        if over.size:
            raise tab.error(rows[over[0]], f"face: list {name!r} announces {n[over[0]]} values, line is too short")
        if name in _FACE_LISTS and flat is None:
            sizes = n
            flat = tab.integers(tab.ragged(rows, ptr + 1, n), np.repeat(rows, n), "face vertex index")
        ptr += 1 + n
    extra = np.flatnonzero(ptr != tab.counts[rows])
    if extra.size:
        raise tab.error(rows[extra[0]], "face: more values than the header's properties")
    if flat is None:
        raise ValueError(f"{tab.path}: PLY face element has no 'vertex_indices' property")
    return flat, sizes


def _trailing_bytes(p: str, ply, body: int) -> None:
    """Refuse bytes after the binary elements the header declares (beyond a final run of whitespace): a byte
    inserted into the data shifts every value after it, and only the file's length shows it. Checked when every
    element has fixed-size records (plyfile then maps them; their sizes give the end)."""
    try:
        ends = [e.data.nbytes for e in ply.elements]
        if any(e.data.dtype.hasobject for e in ply.elements):
            return
    except (AttributeError, TypeError):
        return
    end = body + sum(ends)
    size = os.path.getsize(p)
    if size > end:
        with open(p, "rb") as fh:
            fh.seek(end)
            tail = fh.read(min(size - end, 1 << 16))
        if tail.strip(b" \t\r\n") or size - end > len(tail):
            raise ValueError(f"{p}: {size - end} bytes after the PLY elements the header declares (a byte "
                             "inserted or a count too small?)")


def _ply_binary(p: str, head: bytes):
    import plyfile

    known = {"face": {n: 3 for n in _FACE_LISTS}}  # lets plyfile memory-map triangle lists
    try:
        try:
            ply = plyfile.PlyData.read(p, mmap="c", known_list_len=known)
        except plyfile.PlyElementParseError as exc:
            if "unexpected list length" not in str(exc):
                raise
            from gsdf.io._ply_binary import read_binary_ply

            fast = read_binary_ply(p, head)  # mixed polygon sizes: one compiled scan of the face records
            if fast is not None:
                v, flat, sizes = fast
                V, N = _ply_pick(p, list(v.dtype.names), lambda i: v[v.dtype.names[i]])
                return V, N, (flat if len(sizes) else None), (sizes if len(sizes) else None)
            ply = plyfile.PlyData.read(p, mmap="c")  # other layouts: plyfile's slower row-by-row path
    except OSError:
        raise
    except Exception as exc:  # plyfile raises PlyParseError and assorted errors on broken files
        raise ValueError(f"{p}: malformed PLY file ({error_words(exc)})") from exc
    if "vertex" not in ply:
        raise ValueError(f"{p}: PLY file has no 'vertex' element")
    _trailing_bytes(p, ply, _ply_header(p, head)[2])
    v = ply["vertex"].data
    V, N = _ply_pick(p, list(v.dtype.names), lambda i: v[v.dtype.names[i]])
    if "face" not in ply or ply["face"].count == 0:
        return V, N, None, None
    face = ply["face"].data
    name = next((n for n in _FACE_LISTS if n in face.dtype.names), None)
    if name is None:
        raise ValueError(f"{p}: PLY face element has no 'vertex_indices' property")
    lists = face[name]
    if lists.dtype != object:
        lists = np.asarray(lists).reshape(len(face), -1)
        return V, N, lists.astype(np.int64).ravel(), np.full(len(lists), lists.shape[1])
    sizes = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
    return V, N, np.concatenate(list(lists)).astype(np.int64), sizes


def _read_ply(p: str):
    """Return (V, N or None, flat face indices or None, face sizes or None)."""
    _check_file(p)
    with open(p, "rb") as fh:
        data = fh.read(1 << 16)
        if b"end_header" not in data:
            data += fh.read()
        fmt, elements, body, header_lines = _ply_header(p, data)
        if fmt == "ascii":
            data += fh.read()
    if fmt == "ascii":
        return _ply_ascii(p, data, elements, body, header_lines)
    return _ply_binary(p, data)


def _write_ply(p: str, vertex_fields: dict, faces=None, binary: bool = True) -> None:
    """Write a PLY file: ``vertex_fields`` maps property name -> (n,) array (stored as double),
    ``faces`` is ``(flat, sizes)`` or None.  Written with numpy (plyfile's writer loops per face)."""
    n = len(next(iter(vertex_fields.values())))
    head = ["ply", f"format {'binary_little_endian' if binary else 'ascii'} 1.0", "comment written by gsdf",
            f"element vertex {n}"] + [f"property double {k}" for k in vertex_fields]
    if faces is not None:
        flat, sizes = faces
        ltype, lname = ("u1", "uchar") if sizes.max() < 256 else ("<i4", "int")
        head += [f"element face {len(sizes)}", f"property list {lname} int vertex_indices"]
    head = ("\n".join(head + ["end_header"]) + "\n").encode("ascii")
    if binary:
        vert = np.empty(n, dtype=[(k, "<f8") for k in vertex_fields])
        for k, a in vertex_fields.items():
            vert[k] = a
        body = vert.tobytes() + (b"" if faces is None else _ply_face_bytes(flat, sizes, ltype))
    else:
        body = _format_rows(np.column_stack(list(vertex_fields.values())))
        body = (body + ("" if faces is None else _polygon_lines(flat, sizes, "", 0, True))).encode("ascii")
    with open(p, "wb") as fh:
        fh.write(head)
        fh.write(body)


def _ply_face_bytes(flat: np.ndarray, sizes: np.ndarray, ltype: str) -> bytes:
    """Binary PLY face records: a length (``ltype``) then int32 indices, for every polygon."""
    if np.all(sizes == sizes[0]):
        rec = np.empty(len(sizes), dtype=[("n", ltype), ("i", "<i4", (int(sizes[0]),))])
        rec["n"], rec["i"] = sizes, flat.reshape(len(sizes), -1)
        return rec.tobytes()
    lb = np.dtype(ltype).itemsize
    reclen = lb + 4 * sizes
    offs = np.cumsum(reclen) - reclen
    buf = np.zeros(int(reclen.sum()), np.uint8)
    buf[offs[:, None] + np.arange(lb)] = sizes.astype(ltype).view(np.uint8).reshape(-1, lb)
    local = np.arange(len(flat)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    pos = np.repeat(offs + lb, sizes) + 4 * local
    buf[pos[:, None] + np.arange(4)] = flat.astype("<i4").view(np.uint8).reshape(-1, 4)
    return buf.tobytes()


# ----------------------------------------------------------------------------------------------
# polygons
# ----------------------------------------------------------------------------------------------


def _fan(flat: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Fan-triangulate polygons given as a flat index array and per-polygon sizes."""
    if sizes.size and np.all(sizes == 3):
        return flat.reshape(-1, 3)
    starts = np.cumsum(sizes) - sizes
    ntri = np.maximum(sizes - 2, 0)
    poly = np.repeat(np.arange(len(sizes)), ntri)
    j = np.arange(int(ntri.sum())) - np.repeat(np.cumsum(ntri) - ntri, ntri)
    s = starts[poly]
    return np.stack([flat[s], flat[s + j + 1], flat[s + j + 2]], axis=1)


def _finish(p: str, V, flat, sizes, triangulate: bool):
    if sizes is None or len(sizes) == 0:
        raise ValueError(f"{p}: no faces; is this a point cloud? use read_points")
    V = as_points(V, f"{p}: vertices")
    flat = np.asarray(flat, dtype=np.int64)
    sizes = np.asarray(sizes, dtype=np.int64)
    bad = np.flatnonzero((flat < 0) | (flat >= len(V)))
    if bad.size:
        raise ValueError(f"{p}: face vertex index {flat[bad[0]]} out of range for {len(V)} vertices")
    if not triangulate:
        return V, np.split(flat, np.cumsum(sizes)[:-1])
    F = _fan(flat, sizes)
    if len(F) == 0:
        raise ValueError(f"{p}: no faces with 3 or more vertices")
    return V, np.ascontiguousarray(F)


# ----------------------------------------------------------------------------------------------
# readers
# ----------------------------------------------------------------------------------------------

_OFF_KEY = re.compile(rb"(ST)?(C)?(N)?(4)?(n)?OFF", re.IGNORECASE)


def _parse_off(p: str, data: bytes, with_faces: bool = True):
    """Parse OFF text: return (V, N or None (NOFF normals), flat indices, polygon sizes)."""
    tab = _Table(p, data)
    if not len(tab):
        raise ValueError(f"{p}: file is empty (no data lines)")
    head = [t for r in range(min(2, len(tab))) for t in tab.row_tokens(r)]
    key = _OFF_KEY.fullmatch(head[0])
    normals = False
    if key:
        if key.group(4) or key.group(5):
            raise tab.error(0, f"{head[0].decode()} (4D or n-dimensional OFF) is not supported")
        if tab.counts[0] > 1 and head[1].upper() == b"BINARY":
            raise tab.error(0, "binary OFF is not supported")
        normals = bool(key.group(3))
        crow, skip = (0, 1) if tab.counts[0] > 1 else (1, 0)
    else:
        crow, skip = 0, 0
    if crow >= len(tab):
        raise ValueError(f"{p}: missing the 'nvertices nfaces nedges' line after the OFF header")
    try:
        nv, nf = (int(t) for t in head[tab.start[crow] + skip: tab.start[crow] + skip + 2])
        if nv < 0 or nf < 0 or tab.counts[crow] - skip < 2:
            raise ValueError
    except ValueError:
        raise tab.error(crow, "expected the counts 'nvertices nfaces [nedges]'") from None
    v0, f0 = crow + 1, crow + 1 + nv
    nf = nf if with_faces else 0
    if len(tab) < f0 + nf:
        raise ValueError(f"{p}: header announces {nv} vertices and {nf} faces, "
                         f"but the file has only {len(tab) - v0} data lines after the header")
    V = tab.columns(np.arange(v0, f0), 0, 6 if normals else 3, "vertex")
    V, N = (V[:, :3], V[:, 3:]) if normals else (V, None)
    if nf == 0:
        return V, N, None, None
    rows = np.arange(f0, f0 + nf)
    c = tab.counts[rows]
    if np.all(c == c[0]):  # same number of values on every face line: one loadtxt call
        A = tab.columns(rows, 0, int(c[0]), "face")
        sizes = tab.integers(A[:, 0], rows, "face size")
        if np.all(sizes == sizes[0]) and 0 <= sizes[0] < c[0]:
            k = int(sizes[0])
            flat = tab.integers(A[:, 1:k + 1].ravel(), np.repeat(rows, k), "face vertex index")
            return V, N, _off_range(tab, flat, np.repeat(rows, k), nv), sizes
    sizes = tab.integers(tab.numbers(tab.start[rows]), rows, "face size")
    short = np.flatnonzero((sizes < 0) | (c < sizes + 1))
    if short.size:
        return V, N, *_off_faces_across_lines(tab, f0, nf, nv)
    row_of = np.repeat(rows, sizes)
    flat = tab.integers(tab.ragged(rows, 1, sizes), row_of, "face vertex index")
    return V, N, _off_range(tab, flat, row_of, nv), sizes


def _off_faces_across_lines(tab: _Table, f0: int, nf: int, nv: int):
    """Face records read as a stream of numbers, as libigl's reader does: a record is its size and that many
    indices, which may continue on the following lines; the rest of the line holding its last index (colour
    values) is skipped. Returns (flat, sizes)."""
    tok = tab.tokens
    end = int(tab.start[-1])
    k = int(tab.start[f0])
    firsts, sizes = [], []
    for _ in range(nf):
        if k >= end:
            raise ValueError(f"{tab.path}: the file ends after {len(sizes)} of the {nf} faces its header announces")
        r = int(np.searchsorted(tab.start, k, side="right")) - 1
        n = int(tab.integers(tab.numbers([k]), np.array([r]), "face size")[0])
        if n < 0 or k + n >= end:
            raise tab.error(r, f"face announces {n} vertices but the file ends after {end - k - 1} more values")
        firsts.append(k + 1)
        sizes.append(n)
        last = int(np.searchsorted(tab.start, k + n, side="right")) - 1  # the line of its last index
        k = int(tab.start[last + 1])
    sizes = np.array(sizes, dtype=np.int64)
    idx = np.repeat(np.array(firsts, dtype=np.int64), sizes) + (np.arange(int(sizes.sum()))
                                                                  - np.repeat(np.cumsum(sizes) - sizes, sizes))
    row_of = np.searchsorted(tab.start, idx, side="right") - 1
    flat = tab.integers(tab.numbers(idx), row_of, "face vertex index")
    return _off_range(tab, flat, row_of, nv), sizes


def _off_range(tab: _Table, flat, row_of, nv: int):
    bad = np.flatnonzero((flat < 0) | (flat >= nv))
    if bad.size:
        raise tab.error(row_of[bad[0]], f"face vertex index {flat[bad[0]]} out of range for {nv} vertices")
    return flat


def _parse_obj(p: str, data: bytes, with_faces: bool = True):
    """Parse OBJ text: return (V, flat, sizes, table)."""
    if with_faces and b"/" in data:
        data = re.sub(rb"/\S*", b"", data)  # i/t/n, i//n, i/t -> i  (only f and l lines contain '/')
    tab = _Table(p, data)
    if not len(tab):
        raise ValueError(f"{p}: file is empty (no data lines)")
    vrows = tab.keyword_rows(b"v")
    V = tab.columns(vrows, 1, 3, "'v' line")
    if not with_faces:
        return V, None, None, tab
    rows = tab.keyword_rows(b"f")
    if not rows.size:
        return V, None, None, tab
    sizes = tab.counts[rows] - 1
    row_of = np.repeat(rows, sizes)
    if np.all(sizes == sizes[0]) and sizes[0] > 0:
        idx = tab.columns(rows, 1, int(sizes[0]), "'f' line").ravel()
    else:
        idx = tab.ragged(rows, 1, sizes)
    idx = tab.integers(idx, row_of, "face vertex index")
    before = np.searchsorted(vrows, row_of)  # vertices defined before each face line
    flat = np.where(idx > 0, idx - 1, before + idx)
    bad = np.flatnonzero((idx == 0) | (idx > len(vrows)) | (flat < 0))
    if bad.size:
        i, r = idx[bad[0]], row_of[bad[0]]
        if i == 0:
            raise tab.error(r, "face vertex index 0 is invalid (OBJ indices start at 1)")
        n = len(vrows) if i > 0 else before[bad[0]]
        raise tab.error(r, f"face vertex index {i} out of range for {n} vertices")
    return V, flat, sizes, tab


def _read_stl(p: str):
    """Read STL triangles (binary or ASCII) and merge exactly equal corners."""
    data = _read_bytes(p)
    n = int(np.frombuffer(data[80:84], "<u4")[0]) if len(data) >= 84 else -1
    ascii = data.lstrip()[:5].lower() == b"solid"
    if len(data) == 84 + 50 * n or (not ascii and n >= 0 and len(data) > 84 + 50 * n):  # binary (maybe padded)
        rec = np.frombuffer(data, dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")], count=n, offset=84)
        with np.errstate(invalid="ignore"):  # NaN payloads of damaged files: refused below as non-finite
            soup = rec["v"].reshape(-1, 3).astype(np.float64)
    elif ascii:  # only the 'vertex x y z' lines matter
        tab = _Table(p, data, comments=False)
        rows = np.union1d(tab.keyword_rows(b"vertex"), tab.keyword_rows(b"VERTEX"))
        if len(rows) % 3:
            raise ValueError(f"{p}: malformed STL file: {len(rows)} 'vertex' lines, not a multiple of 3")
        soup = tab.columns(rows, 1, 3, "'vertex' line")
    else:
        raise ValueError(f"{p}: malformed STL file: neither ASCII ('solid ...') nor a binary STL "
                         f"of consistent size ({len(data)} bytes for {n} facets)")
    soup = as_points(soup, f"{p}: vertices", allow_empty=True)
    if len(soup) == 0:
        return np.zeros((0, 3)), None, None
    V, inv = _merge_equal_rows(soup)
    return V, inv, np.full(len(soup) // 3, 3)


def _merge_equal_rows(X: np.ndarray):
    """Merge exactly equal rows of (n, 3) ``X``: ``(U, inv)`` with ``U[inv] == X`` and U in order of
    first appearance.  Sorts 1-d integer keys column by column (much faster than
    ``np.unique(axis=0)``); ``-0.0`` and ``0.0`` are merged."""
    bits = np.ascontiguousarray(X + 0.0).view(np.int64)
    key = np.unique(bits[:, 0], return_inverse=True)[1].reshape(-1)
    for c in (1, 2):  # key stays < n, so key * n + column id cannot overflow
        col = np.unique(bits[:, c], return_inverse=True)[1].reshape(-1)
        key = np.unique(key * len(X) + col, return_inverse=True)[1].reshape(-1)
    _, first, inv = np.unique(key, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return X[first[order]], rank[inv.reshape(-1)]


def read_mesh(path, triangulate: bool = True):
    """Read a triangle or polygon mesh (or soup) exactly as stored: vertex order, duplicate and degenerate
    faces, unreferenced vertices all kept.

    Parameters
    ----------
    path : str or os.PathLike
        File to read; the format is chosen from the (case-insensitive) extension:
        ``.obj``, ``.off``, ``.ply`` (ASCII or binary), ``.stl`` (ASCII or binary) — parsed by gsdf —;
        ``.glb``, ``.gltf``, ``.3mf`` through trimesh (``process=False``; scene meshes placed by their
        transforms, in scene order); ``.vtk``, ``.vtu``, ``.msh``, ``.mesh``, ``.inp``, ``.bdf``, ``.nas``,
        ``.su2`` through meshio (triangle, quad and polygon cells in file order; volume cells ignored).
        ``MESH_READ_FORMATS`` lists them.
    triangulate : bool, default True
        Fan-triangulate polygons: ``(a, b, c, d, ...)`` gives ``(a, b, c), (a, c, d), ...``.
        With ``False`` the polygons are returned unchanged.

    Returns
    -------
    V : (n, 3) float64 ndarray
        Vertex positions.
    F : (m, 3) int64 ndarray, or list of int64 ndarrays
        Triangles (0-based vertex indices), or one index array per polygon if
        ``triangulate=False``.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        Message starting with the path, for an unsupported extension, an empty file, a
        malformed line (with its line number), a face index out of range, NaN/inf coordinates,
        or a file without faces (use :func:`gsdf.io.read_points` for point clouds).

    Notes
    -----
    * OBJ: ``v`` and ``f`` lines; ``f`` accepts ``i``, ``i/t``, ``i/t/n``, ``i//n`` and negative
      (relative) indices. Other statements (``vt vn g o s usemtl mtllib l`` ...) are ignored.
    * OFF: ``OFF``/``COFF``/``NOFF`` headers, counts on the header line or the next one, ``#``
      comments, per-vertex and per-face colours (ignored).
    * STL stores independent triangles: the 3 corners of every facet are read, then exactly equal
      positions are merged; V lists the distinct corners in order of first appearance.
    * Degenerate and duplicate faces are kept.  Faces with fewer than 3 vertices are kept with
      ``triangulate=False`` and give no triangle otherwise.
    * Malformed files of any format (binary garbage, truncated data, negative PLY counts) raise a
      ``ValueError`` naming the file (and, for gsdf's text parsers, the line).

    Examples
    --------
    >>> V, F = read_mesh("bunny.off")                                # doctest: +SKIP
    >>> V, polys = read_mesh("quads.obj", triangulate=False)         # doctest: +SKIP
    """
    p, ext = _extension(path, MESH_READ_FORMATS, "mesh")
    triangulate = flag(triangulate, "triangulate")
    if ext not in MESH_FORMATS:
        _check_file(p)
        if os.path.isdir(p):
            raise ValueError(f"{p}: is a directory, not a mesh file")
        V, flat, sizes = read_external(p, ext)
    elif ext == ".off":
        V, _, flat, sizes = _parse_off(p, _read_bytes(p))
    elif ext == ".obj":
        V, flat, sizes, _ = _parse_obj(p, _read_bytes(p))
    elif ext == ".ply":
        V, _, flat, sizes = _read_ply(p)
    else:
        V, flat, sizes = _read_stl(p)
    return _finish(p, V, flat, sizes, triangulate)


def read_vertex_data(path) -> dict:
    """Per-vertex properties stored with a mesh: PLY vertex properties other than x, y, z (e.g. the
    ``distance`` that ``gsdf heat-surface`` writes; scalars, so an (n, k) array written by :func:`write_mesh`
    comes back as ``name_0`` ... ``name_{k-1}``), or VTK/VTU point data (an (n, k) array for k components).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.ply`` (ASCII or binary), ``.vtk`` or ``.vtu`` file.

    Returns
    -------
    dict of str -> (n,) or (n, k) float64 ndarray
        In file order; aligned with the ``V`` of :func:`read_mesh` on the same file.

    Raises
    ------
    ValueError
        A malformed file, or a property holding NaN, infinite or non-numeric values.

    Examples
    --------
    >>> write_mesh("m.ply", V, F, vertex_data={"distance": d})      # doctest: +SKIP
    >>> read_vertex_data("m.ply")["distance"]                       # doctest: +SKIP
    """
    p, ext = _extension(path, (".ply", ".vtk", ".vtu"), "vertex data")
    _check_file(p)
    if os.path.isdir(p):
        raise ValueError(f"{p}: is a directory, not a mesh file")
    if ext == ".ply":
        import plyfile

        with open(p, "rb") as fh:                # gsdf's header checks first (counts, format), as read_mesh
            head = fh.read(1 << 16)
            if b"end_header" not in head:
                head += fh.read()
        fmt, _, body, _ = _ply_header(p, head)
        try:
            ply = plyfile.PlyData.read(p)
        except Exception as exc:  # plyfile raises PlyParseError and assorted errors on broken files
            raise ValueError(f"{p}: malformed PLY file ({error_words(exc)})") from exc
        if "vertex" not in ply:
            raise ValueError(f"{p}: PLY file has no 'vertex' element")
        if fmt != "ascii":
            _trailing_bytes(p, ply, body)
        v = ply["vertex"].data
        out = {}
        for name in v.dtype.names:
            if name in ("x", "y", "z"):
                continue
            if v[name].dtype == object:
                raise ValueError(f"{p}: vertex property {name!r} is a list, not a scalar")
            out[name] = as_values(v[name], f"{p}: vertex property {name!r}", allow_empty=True)
        return out
    from gsdf.io._external import _read_meshio_raw

    m = _read_meshio_raw(p, ext)
    out = {}
    for name, a in m.point_data.items():
        a = np.asarray(a)
        if a.ndim == 1 or (a.ndim == 2 and a.shape[1] == 1):
            out[name] = as_values(a.reshape(-1), f"{p}: point data {name!r}", allow_empty=True)
        elif a.ndim == 2:
            out[name] = as_values(a, f"{p}: point data {name!r}", allow_empty=True)
    return out


# ----------------------------------------------------------------------------------------------
# writer
# ----------------------------------------------------------------------------------------------


def _faces_arg(F, nv: int):
    """Validate ``F`` (an (m, k) array or a list of polygons): return (flat int64, sizes int64)."""
    if isinstance(F, np.ndarray) and F.dtype != object:
        A = as_faces(F, nv, "F", corners=F.shape[-1] if F.ndim == 2 else 3)
        if A.shape[1] < 3:
            raise ValueError(f"F: faces need at least 3 vertices, got shape {A.shape}")
        return A.ravel(), np.full(len(A), A.shape[1], dtype=np.int64)
    polys = []
    for i, poly in enumerate(F):
        a = np.asarray(poly)
        if a.ndim != 1 or a.size < 3:
            raise ValueError(f"F: polygon {i} must be a 1-d sequence of at least 3 indices, got shape {a.shape}")
        polys.append(a)
    if not polys:
        raise ValueError("F: is empty (0 faces)")
    flat = as_faces(np.concatenate(polys).reshape(1, -1), nv, "F", corners=None).ravel()
    return flat, np.array([len(a) for a in polys], dtype=np.int64)


def _vertex_data(vertex_data, n: int) -> dict:
    """name -> (n,) or (n, k) float64 arrays, validated."""
    if vertex_data is not None and not isinstance(vertex_data, dict):
        raise ValueError(f"vertex_data: expected a dict of name -> per-vertex values, got {type(vertex_data).__name__}")
    out = {}
    for name, values in (vertex_data or {}).items():
        if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) or name in ("x", "y", "z"):
            raise ValueError(f"vertex_data: invalid property name {name!r} (an identifier other than x, y, z)")
        a = np.asarray(values)
        if (a.ndim not in (1, 2) or a.shape[0] != n or (a.ndim == 2 and a.shape[1] == 0)
                or not (np.issubdtype(a.dtype, np.number) or a.dtype == bool)):
            raise ValueError(f"vertex_data[{name!r}]: expected a numeric array of shape ({n},) or ({n}, k), "
                             f"got {a.dtype} {a.shape}")
        out[name] = as_values(a.astype(np.uint8) if a.dtype == bool else a, f"vertex_data[{name!r}]")
    return out


def _ply_columns(extra: dict) -> dict:
    """PLY properties are scalars: an (n, k) entry ``name`` becomes ``name_0`` ... ``name_{k-1}``."""
    out = {}
    for name, a in extra.items():
        cols = {name: a} if a.ndim == 1 else {f"{name}_{j}": a[:, j] for j in range(a.shape[1])}
        for c, col in cols.items():
            if c in out or c in extra and c != name:
                raise ValueError(f"vertex_data: property {c!r} given twice (an (n, k) entry {name!r} writes "
                                 f"{name}_0 ... {name}_{a.shape[1] - 1 if a.ndim == 2 else 0})")
            out[c] = col
    return out


def _polygon_lines(flat: np.ndarray, sizes: np.ndarray, prefix: str, base: int, with_size: bool) -> str:
    """Polygons as text lines: ``prefix [k] i0 i1 ...`` with indices shifted by ``base``."""
    if np.all(sizes == sizes[0]):
        rows = flat.reshape(len(sizes), -1) + base
        return _format_rows(np.column_stack([sizes, rows]) if with_size else rows, prefix)
    polys = np.split(flat + base, np.cumsum(sizes)[:-1])
    size = (lambda q: f"{len(q)} ") if with_size else (lambda q: "")
    return "".join(prefix + size(q) + " ".join(map(str, q.tolist())) + "\n" for q in polys)


def _write_stl(p: str, V: np.ndarray, F: np.ndarray) -> None:
    tri = V[F]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)
    rec = np.zeros(len(F), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"], rec["v"] = n, tri
    with open(p, "wb") as fh:
        fh.write(b"binary STL written by gsdf".ljust(80, b" "))
        fh.write(np.array(len(F), "<u4").tobytes())
        fh.write(rec.tobytes())


def _write_meshio(p: str, ext: str, V, flat, sizes, extra: dict) -> None:
    """VTK/VTU through meshio; runs of equal-size polygons become cell blocks, so the face order is kept."""
    import meshio

    names = {3: "triangle", 4: "quad"}
    cuts = np.flatnonzero(np.diff(sizes)) + 1
    starts = np.concatenate(([0], cuts))
    ends = np.concatenate((cuts, [len(sizes)]))
    offsets = np.concatenate(([0], np.cumsum(sizes)))
    cells = []
    for a, b in zip(starts, ends):
        k = int(sizes[a])
        cells.append((names.get(k, "polygon"), flat[offsets[a]:offsets[b]].reshape(b - a, k)))
    meshio.write(p, meshio.Mesh(V, cells, point_data=extra or None), file_format=ext[1:])


def write_mesh(path, V, F, vertex_data=None, *, binary: bool = True) -> None:
    """Write a mesh to an OBJ, OFF, PLY, STL, VTK or VTU file (chosen by extension), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Output file: ``.obj``, ``.off``, ``.ply``, ``.stl`` (binary STL), ``.vtk``/``.vtu`` (meshio; polygon
        cells, face order kept). Any other extension is a ValueError listing these; the name is never changed
        and the file appears only when complete (:mod:`gsdf.io._safe_write`).
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, k) array_like of int, or list of 1-d int sequences
        Faces (0-based).  A list of polygons of varying size is accepted for OBJ, OFF and PLY;
        STL stores triangles only, so polygons are fan-triangulated for it.
    vertex_data : dict of str -> (n,) or (n, k) float array, optional
        Extra per-vertex values (e.g. a distance field, or normals as one (n, 3) array) written as PLY vertex
        properties (doubles; an (n, k) entry ``name`` as the k properties ``name_0`` ... ``name_{k-1}``), or as
        VTK/VTU point data (an (n, k) entry as one k-component array).  Other formats raise ValueError, and so do NaN,
        infinite or complex values (a reader could not tell them from data: fill them explicitly).
    binary : bool, default True
        PLY only: binary little-endian (default) or ASCII.

    Notes
    -----
    Text formats print coordinates with ``repr``, so reading gives back the exact floats;
    PLY stores doubles; STL stores float32 (and ``read_mesh`` merges its duplicate corners).

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> write_mesh("tet.ply", V, F, vertex_data={"d": V[:, 0]})     # doctest: +SKIP
    """
    p, ext = _extension(path, MESH_WRITE_FORMATS, "mesh")
    binary = flag(binary, "binary")
    V = as_points(V, "V")
    flat, sizes = _faces_arg(F, len(V))
    if vertex_data and ext not in (".ply", ".vtk", ".vtu"):
        raise ValueError(f"{p}: vertex_data: only PLY, VTK and VTU files store vertex data")
    extra = _vertex_data(vertex_data, len(V))
    with atomic_output(p, extensions=MESH_WRITE_FORMATS) as tmp:
        if ext in (".vtk", ".vtu"):
            _write_meshio(tmp, ext, V, flat, sizes, extra)
        elif ext == ".off":
            _write_text(tmp, f"OFF\n{len(V)} {len(sizes)} 0\n" + _format_rows(V)
                        + _polygon_lines(flat, sizes, "", 0, True))
        elif ext == ".obj":
            _write_text(tmp, _format_rows(V, "v ") + _polygon_lines(flat, sizes, "f ", 1, False))
        elif ext == ".ply":
            _write_ply(tmp, {"x": V[:, 0], "y": V[:, 1], "z": V[:, 2], **_ply_columns(extra)}, (flat, sizes),
                       binary=binary)
        else:
            _write_stl(tmp, V, _fan(flat, sizes))
