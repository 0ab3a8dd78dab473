"""Binary PLY faces of mixed polygon sizes, fast: numpy for the fixed-size records, one numba scan for the lists.

plyfile reads variable-length face lists row by row in Python (~10x slower than the rest of the file). A binary
face record is ``[scalars before] count [count indices] [scalars after]``; the start of record k+1 depends on the
count of record k, so the offsets come from one sequential scan (compiled); the indices are then gathered with
numpy. Only the layout gsdf needs is handled — every element before ``face`` made of scalar properties, one list
property ``vertex_indices``/``vertex_index`` in ``face`` — anything else returns ``None`` and the caller uses
plyfile.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
          "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
          "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}
_LISTS = ("vertex_indices", "vertex_index")


def _header(data: bytes):
    """[(element, count, [(name, scalar dtype or None, (count dtype, item dtype) or None)])], body offset, endian."""
    end = data.find(b"end_header")
    eol = data.find(b"\n", end)
    if end < 0 or eol < 0:
        return None
    fmt, elements = None, []
    for line in data[:end].decode("ascii", errors="replace").splitlines()[1:]:
        w = line.split()
        if not w or w[0] in ("comment", "obj_info"):
            continue
        if w[0] == "format" and len(w) >= 2:
            fmt = w[1]
        elif w[0] == "element" and len(w) == 3:
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property" and elements and len(w) == 3 and w[1] in _TYPES:
            elements[-1][2].append((w[2], _TYPES[w[1]], None))
        elif w[0] == "property" and elements and len(w) == 5 and w[1] == "list" and w[2] in _TYPES \
                and w[3] in _TYPES:
            elements[-1][2].append((w[4], None, (_TYPES[w[2]], _TYPES[w[3]])))
        else:
            return None
    if fmt not in ("binary_little_endian", "binary_big_endian"):
        return None
    return elements, eol + 1, "<" if fmt == "binary_little_endian" else ">"


@njit(cache=True)
def _scan(buf, start, n, pre, csize, csigned, isize, post, big):
    """Offsets of the first index and the count of each of ``n`` list records from byte ``start``.
    Returns (offsets, counts, end); end = -1 if the data ends early, -2 for a negative count."""
    offs = np.empty(n, np.int64)
    counts = np.empty(n, np.int64)
    pos = start
    size = buf.shape[0]
    for k in range(n):
        pos += pre
        if pos + csize > size:
            return offs, counts, -1
        c = 0
        for b in range(csize):
            byte = np.int64(buf[pos + (csize - 1 - b if big else b)])
            c |= byte << (8 * b)
        if csigned and c >= (np.int64(1) << (8 * csize - 1)):
            return offs, counts, -2
        pos += csize
        offs[k] = pos
        counts[k] = c
        pos += c * isize + post
        if pos > size:
            return offs, counts, -1
    return offs, counts, pos


def read_binary_ply(p: str, data_head: bytes):
    """``(vertex structured array, flat indices int64, sizes int64)`` or ``None`` when the layout is not the
    simple one (the caller then uses plyfile). Raises ValueError naming ``p`` for truncated or broken data."""
    h = _header(data_head)
    if h is None:
        return None
    elements, body, endian = h
    names = [e[0] for e in elements]
    if "vertex" not in names or "face" not in names or names.index("vertex") > names.index("face"):
        return None
    buf = np.fromfile(p, dtype=np.uint8)
    pos = body
    vertex = None
    for name, count, props in elements:
        if count < 0:
            raise ValueError(f"{p}: negative element count {count} for PLY element {name!r}")
        if name == "face":
            break
        if any(t is None for _, t, _ in props):
            return None  # a list property before the faces: leave it to plyfile
        dt = np.dtype([(pn, endian + t) for pn, t, _ in props])
        nbytes = count * dt.itemsize
        if pos + nbytes > len(buf):
            raise ValueError(f"{p}: PLY element {name!r} announces {count} records but the file ends early")
        if name == "vertex":
            vertex = np.frombuffer(buf, dtype=dt, count=count, offset=pos) if count else np.zeros(0, dt)
        pos += nbytes
    fname, fcount, fprops = elements[names.index("face")]
    lists = [i for i, (pn, t, lt) in enumerate(fprops) if lt is not None]
    if len(lists) != 1 or fprops[lists[0]][0] not in _LISTS:
        return None
    j = lists[0]
    pre = sum(np.dtype(t).itemsize for _, t, _ in fprops[:j])
    post = sum(np.dtype(t).itemsize for _, t, _ in fprops[j + 1:])
    ctype, itype = fprops[j][2]
    cdt, idt = np.dtype(ctype), np.dtype(endian + itype)
    if idt.kind not in "iu" or cdt.kind not in "iu":
        return None
    offs, counts, end = _scan(buf, pos, fcount, pre, cdt.itemsize, cdt.kind == "i", idt.itemsize, post,
                              endian == ">")
    if end == -1:
        raise ValueError(f"{p}: PLY face element announces {fcount} faces but the file ends early")
    if end == -2:
        raise ValueError(f"{p}: PLY face element has a negative vertex count")
    total = int(counts.sum())
    first = np.repeat(offs, counts)
    within = np.arange(total, dtype=np.int64) - np.repeat(np.cumsum(counts) - counts, counts)
    at = first + within * idt.itemsize
    raw = buf[at[:, None] + np.arange(idt.itemsize)]
    flat = np.ascontiguousarray(raw).view(idt).ravel().astype(np.int64)
    return vertex, flat, counts
