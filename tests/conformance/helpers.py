"""Helpers of the conformance suite: where the peers' assets are, small geometry utilities.

Only gsdf's public API (``import gsdf``) is exercised by the tests; the helpers here are plain numpy/scipy
re-statements of what the peers' tests compute around their calls (face normals, Euler characteristic, ...).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
DATA = HERE / "data"
REFS = DATA / "refs"


def ref(peer: str) -> dict:
    """The peer's own outputs recorded once by record_refs.py (data/refs/<peer>.npz)."""
    p = REFS / f"{peer}.npz"
    with np.load(p, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


# ---------------------------------------------------------------------------------------------------------------
# geometry helpers (numpy re-statements of what the peers' tests compute around the calls under test)
# ---------------------------------------------------------------------------------------------------------------


def face_normals(V, F, unit=True):
    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    if unit:
        n = n / np.linalg.norm(n, axis=1, keepdims=True)
    return n


def undirected_edges(F):
    F = np.asarray(F, np.int64)
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    return np.unique(E, axis=0, return_counts=True)


def exterior_edge_count(F):
    """libigl's exterior_edges: directed edges whose count minus their opposite's count is nonzero."""
    F = np.asarray(F, np.int64)
    if len(F) == 0:
        return 0
    D = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    key = np.sort(D, axis=1)
    sign = np.where(D[:, 0] < D[:, 1], 1, -1)
    u, inv = np.unique(key, axis=0, return_inverse=True)
    tot = np.zeros(len(u), np.int64)
    np.add.at(tot, inv.reshape(-1), sign)
    return int((tot != 0).sum())


def is_edge_manifold(F):
    _, c = undirected_edges(F)
    return bool((c <= 2).all())


def is_vertex_manifold(F):
    """Every vertex's faces form one fan (connected through shared edges around the vertex)."""
    F = np.asarray(F, np.int64)
    from collections import defaultdict

    vf = defaultdict(list)
    for f, tri in enumerate(F):
        for v in tri:
            vf[int(v)].append(f)
    for v, faces in vf.items():
        # union-find over the faces around v, joined when they share an edge (v, w)
        parent = {f: f for f in faces}

        def find(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        by_w = defaultdict(list)
        for f in faces:
            for w in F[f]:
                if w != v:
                    by_w[int(w)].append(f)
        for fs in by_w.values():
            for a in fs[1:]:
                parent[find(a)] = find(fs[0])
        if len({find(f) for f in faces}) > 1:
            return False
    return True


def euler_characteristic(V, F):
    """V - E + F over the vertices referenced by F (libigl's assert_genus_eq counts all rows of V)."""
    u, _ = undirected_edges(F)
    return len(np.unique(np.asarray(F).ravel())) - len(u) + len(F)


def enclosed_volume(V, F):
    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    if len(F) == 0:
        return 0.0
    t = V[F]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def surface_area(V, F):
    return float(0.5 * np.linalg.norm(face_normals(V, F, unit=False), axis=1).sum())


def normalize_points(V, center=None):
    """gpytoolbox.normalize_points: centre the bounding box at ``center`` (default 0) and scale its longest side
    to 1."""
    V = np.asarray(V, float)
    lo, hi = V.min(0), V.max(0)
    out = (V - 0.5 * (lo + hi)) / (hi - lo).max()
    if center is not None:
        out = out + np.asarray(center, float)
    return out


def box_mesh(lo, hi):
    """Closed outward triangulated box (8 vertices, 12 faces), vertex order of libigl's cube.obj."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    V = np.array([[lo[0], lo[1], lo[2]], [hi[0], lo[1], lo[2]], [hi[0], hi[1], lo[2]], [lo[0], hi[1], lo[2]],
                  [lo[0], lo[1], hi[2]], [hi[0], lo[1], hi[2]], [hi[0], hi[1], hi[2]], [lo[0], hi[1], hi[2]]])
    F = np.array([[0, 2, 1], [0, 3, 2], [5, 0, 1], [5, 4, 0], [2, 6, 1], [3, 6, 2], [5, 1, 6], [5, 6, 4],
                  [0, 7, 3], [0, 4, 7], [3, 7, 6], [6, 7, 4]], dtype=np.int64)
    return V, F


def rel_l2(a, b):
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(np.asarray(b)))


def upsample(V, F, n=1):
    """libigl's upsample (midpoint 1-to-4 subdivision, shared edge midpoints), ``n`` times."""
    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    for _ in range(n):
        E = np.sort(np.concatenate([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]]), axis=1)
        u, inv = np.unique(E, axis=0, return_inverse=True)
        inv = inv.reshape(3, -1).T + len(V)          # midpoint index opposite corner 0, 1, 2
        V = np.vstack([V, 0.5 * (V[u[:, 0]] + V[u[:, 1]])])
        a, b, c = F.T
        m0, m1, m2 = inv.T
        F = np.vstack([np.column_stack([a, m2, m1]), np.column_stack([b, m0, m2]),
                       np.column_stack([c, m1, m0]), np.column_stack([m0, m1, m2])])
    return V, F


def icosahedron():
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], np.int64)
    return V, F


# ---------------------------------------------------------------------------------------------------------------
# stand-ins for libigl-tests-data files (that repository has no licence file, so its files are not vendored):
# generated geometry written in the same file layout as the file the libigl test reads
# ---------------------------------------------------------------------------------------------------------------


def cube_obj_text():
    """cube.obj's layout: 8 ``v`` lines of the cube [-0.5, 0.5]^3, 12 triangle ``f`` lines (1-based)."""
    V, F = box_mesh([-0.5] * 3, [0.5] * 3)
    return "".join(f"v {x} {y} {z}\n" for x, y, z in V) + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)


CUBE_QUADS = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])


def cube_with_material_obj_text():
    """cubewithmaterial.obj's layout: a material library, 8 vertices, texture coordinates and normals, 6 quads
    ``f v/vt/vn`` in two ``usemtl`` groups."""
    V, _ = box_mesh([-0.5] * 3, [0.5] * 3)
    out = ["mtllib cube.mtl", "o Cube"] + [f"v {x} {y} {z}" for x, y, z in V]
    out += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
    out += ["vn 0 0 -1", "vn 0 0 1", "vn 0 -1 0", "vn 1 0 0", "vn 0 1 0", "vn -1 0 0"]
    for q, quad in enumerate(CUBE_QUADS):
        if q in (0, 3):
            out += [f"usemtl Material.{q // 3 + 1:03d}", "s off"]
        out.append("f " + " ".join(f"{v + 1}/{c + 1}/{q + 1}" for c, v in enumerate(quad)))
    return "\n".join(out) + "\n"


def cube_off_text():
    """cube.off's layout: ``OFF``, counts, 8 vertex lines, 12 ``3 a b c`` lines."""
    V, F = box_mesh([-0.5] * 3, [0.5] * 3)
    return ("OFF\n8 12 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in V)
            + "".join(f"3 {a} {b} {c}\n" for a, b, c in F))


def grid_quads(n, m, lift=None):
    """(V, Q): an (n + 1) x (m + 1) grid of quads on [0, 1]^2, z = lift(x, y) (0 by default)."""
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, m + 1), indexing="ij")
    z = np.zeros_like(x) if lift is None else lift(x, y)
    V = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a = (i * (m + 1) + j).ravel()
    Q = np.column_stack([a, a + m + 1, a + m + 2, a + 1])
    return V, Q


def wrapped_off_text(V, Q):
    """inspired_mesh_quads_Conjugate.off's layout: ``OFF``, counts, one vertex per line, then every face record
    written one token per line (``4 887 ``, ``46 ``, ``888 ``, ``0 ``)."""
    out = ["OFF", f"{len(V)} {len(Q)} 0"] + [f"{float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in V]
    for q in Q:
        out += [f"{len(q)} {q[0]} "] + [f"{v} " for v in q[1:]]
    return "\n".join(out) + "\n"


def subdivided_box_faces(lo, hi, n):
    """The 6 faces of the box [lo, hi] as separate n x n triangulated grids (unwelded along the box's edges),
    outward. Returns a list of (V, F)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    g, Q = grid_quads(n, n)
    T = np.vstack([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    out = []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, 1):
            X = np.empty((len(g), 3))
            X[:, axis] = hi[axis] if side else lo[axis]
            X[:, u] = lo[u] + g[:, 0] * (hi[u] - lo[u])
            X[:, v] = lo[v] + g[:, 1] * (hi[v] - lo[v])
            out.append((X, T if side else T[:, ::-1]))
    return out


def two_boxes_bad_self_union():
    """two-boxes-bad-self-union.ply's geometry: two overlapping boxes, [-0.5, 0.5]^3 and [0, 1] x [-0.25, 0.25]^2,
    in one mesh whose 12 box faces are separate unwelded grids (the mesh crosses itself where the boxes meet)."""
    parts = subdivided_box_faces([-0.5] * 3, [0.5] * 3, 4) + subdivided_box_faces([0, -0.25, -0.25],
                                                                                   [1, 0.25, 0.25], 3)
    V, F, off = [], [], 0
    for X, T in parts:
        V.append(X)
        F.append(T + off)
        off += len(X)
    return np.vstack(V), np.vstack(F)


def cube_with_fold_ply(path):
    """cube_with_fold.ply's layout (binary little-endian, double x y z, ``list uchar int vertex_indices``): the
    cube [-1, 1]^3 with each side split 2 x 2 (26 vertices, 48 triangles) and one face centre pushed in (the
    fold)."""
    sides = []
    for X, T in subdivided_box_faces([-1] * 3, [1] * 3, 2):
        sides.append((X, T))
    V = np.vstack([X for X, _ in sides])
    F = np.vstack([T + 9 * i for i, (_, T) in enumerate(sides)])
    key = np.round(V, 9)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    V = V[first[order]]
    F = rank[inv.reshape(-1)][F]
    V[np.argmin(np.linalg.norm(V - [0, 0, 1], axis=1))] = [0, 0, 0.6]     # the fold
    head = ("ply\nformat binary_little_endian 1.0\ncomment generated stand-in\n"
            f"element vertex {len(V)}\nproperty double x\nproperty double y\nproperty double z\n"
            f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    rec = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    rec["n"], rec["i"] = 3, F
    with open(path, "wb") as fh:
        fh.write(head + V.astype("<f8").tobytes() + rec.tobytes())
    return len(V), len(F)


def stanford_ply(path, V, F, seed=0):
    """bunny.ply's layout (the Stanford scanner's ``zipper output``): ASCII, ``float32 x y z confidence
    intensity``, ``list uint8 int32 vertex_indices``. Returns the (confidence, intensity) columns written."""
    rng = np.random.default_rng(seed)
    conf = np.round(rng.random(len(V)), 6)
    inten = np.full(len(V), 0.5)
    head = ("ply\nformat ascii 1.0\ncomment zipper output\ncomment modified by flipply\n"
            f"element vertex {len(V)}\nproperty float32 x\nproperty float32 y\nproperty float32 z\n"
            "property float32 confidence\nproperty float32 intensity\n"
            f"element face {len(F)}\nproperty list uint8 int32 vertex_indices\nend_header\n")
    rows = "".join(f"{x:g} {y:g} {z:g} {c:g} {i:g} \n" for (x, y, z), c, i in zip(V, conf, inten))
    faces = "".join(f"3 {a} {b} {c} \n" for a, b, c in F)
    with open(path, "w") as fh:
        fh.write(head + rows + faces)
    return conf, inten


def tet_cube(n=3):
    """(V, T): the cube [0, 1]^3 split into n^3 cells of 6 tets each (Kuhn subdivision; consistent faces)."""
    x = np.linspace(0, 1, n + 1)
    V = np.stack(np.meshgrid(x, x, x, indexing="ij"), -1).reshape(-1, 3)

    def vid(i, j, k):
        return (i * (n + 1) + j) * (n + 1) + k

    T = []
    for i in range(n):
        for j in range(n):
            for k in range(n):
                c = [vid(i + a, j + b, k + d) for a in (0, 1) for b in (0, 1) for d in (0, 1)]
                # the six tets around the diagonal c[0] - c[7]
                for p in ([1, 3], [1, 5], [2, 3], [2, 6], [4, 5], [4, 6]):
                    T.append([c[0], c[p[0]], c[p[0] | p[1]], c[7]])
    T = np.array(T)
    # orient positively
    a, b, c, d = (V[T[:, i]] for i in range(4))
    neg = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    T[neg] = T[neg][:, [1, 0, 2, 3]]
    return V, T


def tet_boundary(T):
    """Boundary triangles of a tet mesh (faces used by one tet), outward for positively oriented tets."""
    Fc = np.vstack([T[:, [1, 2, 3]], T[:, [0, 3, 2]], T[:, [0, 1, 3]], T[:, [0, 2, 1]]])
    key = np.sort(Fc, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return Fc[cnt[inv.reshape(-1)] == 1]


def msh22_text(V, T, F, tet_data=True):
    """A Gmsh 2.2 ASCII file in the layout of libigl's readMSH test file: nodes, triangle elements (type 2) and
    tet elements (type 4), and an ``$ElementData`` scalar over the tets only."""
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", str(len(V))]
    out += [f"{i + 1} {float(x)!r} {float(y)!r} {float(z)!r}" for i, (x, y, z) in enumerate(V)]
    out += ["$EndNodes", "$Elements", str(len(F) + len(T))]
    e = 0
    for f in F:
        e += 1
        out.append(f"{e} 2 2 1 1 " + " ".join(str(v + 1) for v in f))
    for t in T:
        e += 1
        out.append(f"{e} 4 2 2 2 " + " ".join(str(v + 1) for v in t))
    out += ["$EndElements"]
    if tet_data:
        out += ["$ElementData", "1", '"conductivity"', "1", "0.0", "3", "0", "1", str(len(T))]
        out += [f"{len(F) + i + 1} {0.1 + i:g}" for i in range(len(T))]
        out += ["$EndElementData"]
    return "\n".join(out) + "\n"


def blob_mesh():
    """A closed, star-shaped, lumpy mesh of 1280 triangles (decimated-knight.obj's role: a closed mesh of ~1.5k
    faces whose box centre is inside)."""
    from gsdf.data import sphere_mesh

    V, F = sphere_mesh(3)
    V = V * (1 + 0.3 * np.sin(3 * V[:, [0]]) * np.sin(2 * V[:, [1]]) + 0.2 * np.cos(4 * V[:, [2]]))
    V[:, 2] *= 1.8
    return V, F


def hemisphere_mesh():
    """The upper half (z >= 0) of the 3-times subdivided icosphere: an open mesh of 624 triangles
    (hemisphere.obj's role)."""
    from gsdf.data import sphere_mesh

    V, F = sphere_mesh(3)
    F = F[V[F][:, :, 2].min(axis=1) >= -1e-12]
    used, F = np.unique(F, return_inverse=True)
    return V[used], F.reshape(-1, 3)


def airplane():
    """A closed fuselage (a capped octagonal tube along x) and a single-layer wing crossing it: the
    ShapeNet airplane's (mesh2sdf's plane.obj) mix of solid parts and double-sided sheets."""
    k = 8
    ang = np.arange(k) * 2 * np.pi / k
    xs = np.array([-1.0, 1.0])
    ring = np.column_stack([np.cos(ang), np.sin(ang)]) * 0.15
    V = [np.column_stack([np.full(k, x), ring]) for x in xs] + [np.array([[-1.0, 0, 0], [1.0, 0, 0]])]
    V = np.vstack(V)
    F = []
    for i in range(k):
        j = (i + 1) % k
        F += [[i, j, k + j], [i, k + j, k + i]]  # the side, outward
        F += [[2 * k, j, i], [2 * k + 1, k + i, k + j]]  # the caps
    F = np.array(F)
    wing = np.array([[-0.3, -1.2, 0], [0.3, -1.2, 0], [0.3, 1.2, 0], [-0.3, 1.2, 0]])
    W = np.array([[0, 1, 2], [0, 2, 3]]) + len(V)
    return np.vstack([V, wing]), np.vstack([F, W])
