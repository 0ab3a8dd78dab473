"""Inputs and frozen outputs of the old-vs-new operator tests (tests/mesh/test_operators.py).

The triangle and tet operators used to be written twice — ``TriangleDEC`` (gsdf.dec._triangle) next to
``TriangleMeshOperators`` (gsdf.heat.triangle._operators), ``TetComplex`` (gsdf.dec._tet) next to the P1 functions
of gsdf.heat.tet._mesh — and now come from gsdf.mesh._triangle_ops and gsdf.mesh._tet_ops.
tests/data/mesh_operators_reference.npz holds what the two old implementations computed on the meshes of
:func:`triangle_meshes` / :func:`tet_mesh` (and the surface winding numbers of :func:`swn_cases` downstream). It was
written by ``PYTHONPATH=<checkout of 994c990>/src python3 tests/mesh/operator_reference.py`` (the layout commit
before the operators were merged); the script only runs against that code.
"""

import os
import sys

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))  # run as a script

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "mesh_operators_reference.npz")


def triangle_meshes():
    """name -> (V, F): a jittered grid (open), an icosphere (closed), the grid with one face flipped."""
    from gsdf.data._shapes import grid_mesh, sphere_mesh

    V, F = grid_mesh(6, jitter=0.2, seed=1)
    Ff = F.copy()
    Ff[7] = Ff[7, ::-1]
    return {"grid": (V, F), "sphere": sphere_mesh(1), "flipped": (V, Ff)}


def tet_mesh():
    """V (40, 3), T: Delaunay tets of random points in the unit cube."""
    from scipy.spatial import Delaunay

    P = np.random.default_rng(0).uniform(0, 1, (40, 3))
    return P, Delaunay(P).simplices.astype(np.int64)


def fields(nv, nf, ne, seed=0):
    """Random test fields: per face vectors (nf, 3), per edge complex values (ne,), per vertex values (nv,)."""
    rng = np.random.default_rng(seed)
    return rng.normal(size=(nf, 3)), rng.normal(size=ne) + 1j * rng.normal(size=ne), rng.normal(size=nv)


def dec_chain(dec):
    """A jump chain on a triangle mesh: the oriented boundary of the faces with centroid x > 0, cut short (open)."""
    c = dec.V[dec.F].mean(axis=1)
    g = np.rint(dec.d1.T @ (c[:, 0] > 0).astype(float))
    g[np.flatnonzero(g)[:2]] = 0.0
    return g


def tet_chain(K):
    """A face chain on the tet mesh: the boundary of the tets with centroid x > 0.5."""
    c = K.V[K.T].mean(axis=1)
    return K.d2.T @ (c[:, 0] > 0.5).astype(float)


def swn_cases():
    """(name, V, F, curves): a broken equator on a UV sphere (interior endpoints), a torus meridian (nonbounding)."""
    from tests.shapes import torus, uv_sphere

    V, F = uv_sphere(12, 24)
    ring = 1 + 5 * 24 + np.arange(24)
    broken = [ring[0:6].tolist(), ring[8:15].tolist(), ring[17:22].tolist()]
    Vt, Ft, idx = torus(24, 12)
    return [("sphere_broken", V, F, broken), ("torus_meridian", Vt, Ft, [np.r_[idx[5], idx[5, 0]]])]


def put(out, key, A):
    """Store ``A`` under ``key``; sparse matrices as canonical COO triplets (duplicates summed, zeros dropped)."""
    if sp.issparse(A):
        C = sp.coo_matrix(A.tocsr())
        C.sum_duplicates()
        C.eliminate_zeros()
        out[key + "/row"], out[key + "/col"], out[key + "/val"] = C.row, C.col, C.data
        out[key + "/shape"] = np.array(C.shape)
    else:
        out[key] = np.asarray(A)


def load(key):
    """The frozen array or sparse matrix (COO) stored under ``key``."""
    ref = _reference()
    if key + "/row" in ref.files:
        return sp.coo_matrix((ref[key + "/val"], (ref[key + "/row"], ref[key + "/col"])),
                             shape=tuple(ref[key + "/shape"]))
    return ref[key]


def canonical(A):
    """``A`` as :func:`put` stores it (sparse: canonical COO, duplicates summed, zeros dropped)."""
    if sp.issparse(A):
        C = sp.coo_matrix(A.tocsr())
        C.sum_duplicates()
        C.eliminate_zeros()
        return C
    return np.asarray(A)


def identical(key, A) -> bool:
    """Is ``A`` bit-identical (values, dtype, sparsity pattern) to the frozen ``key``?"""
    ref, new = load(key), canonical(A)
    if sp.issparse(ref):
        return (sp.issparse(new) and ref.shape == new.shape and ref.dtype == new.dtype
                and all(np.array_equal(a, b) for a, b in ((ref.row, new.row), (ref.col, new.col),
                                                         (ref.data, new.data))))
    return ref.shape == new.shape and ref.dtype == new.dtype and np.array_equal(ref, new)


def relative_difference(key, A) -> float:
    """max |A − frozen| / max |frozen|."""
    ref, new = load(key), canonical(A)
    if sp.issparse(ref):
        return float(abs(ref.tocsr() - new.tocsr()).max() / abs(ref).max())
    return float(np.abs(new - ref).max() / np.abs(ref).max())


_REF = []


def _reference():
    if not _REF:
        _REF.append(np.load(OUT))
    return _REF[0]


def main():                                                        # pragma: no cover - runs on the old code
    from gsdf.dec._tet import TetComplex
    from gsdf.dec._triangle import TriangleDEC
    from gsdf.heat.intrinsic._kernels import intrinsic_delaunay, layout
    from gsdf.heat.tet._mesh import p1_laplacian, tet_geometry, weak_divergence
    from gsdf.heat.triangle._operators import TriangleMeshOperators
    from gsdf.heat.triangle._sharpen import gradient_operator
    from gsdf.swn._solver import surface_winding_number

    out = {}
    meshes = triangle_meshes()
    V, F = meshes["grid"]
    Fi, L, _ = intrinsic_delaunay(V, F)
    heat = {k: TriangleMeshOperators(V_, F_) for k, (V_, F_) in meshes.items()}
    heat["intrinsic"] = TriangleMeshOperators(V, Fi, P=layout(L))
    for name, ops in heat.items():
        Y, X, _ = fields(ops.n_vertices, ops.n_faces, ops.n_edges)
        k = f"heat/{name}/"
        for a in ("areas", "normals", "cot", "angles", "slot_len", "edges", "face_edges", "slot_sign", "edge_len",
                  "h", "slot_u", "slot_w", "slot_rho", "slot_sigma", "edge_ref_slot"):
            put(out, k + a, getattr(ops, a))
        put(out, k + "cotan_laplacian", ops.cotan_laplacian())
        put(out, k + "vertex_mass", ops.vertex_mass())
        put(out, k + "cr_mass", ops.cr_mass())
        put(out, k + "cr_connection_laplacian", ops.cr_connection_laplacian())
        put(out, k + "cr_connection_laplacian_real", ops.cr_connection_laplacian_real())
        put(out, k + "cr_vector_heat_matrix", ops.cr_vector_heat_matrix(0.05))
        put(out, k + "divergence", ops.divergence(Y))
        put(out, k + "edge_to_face_vectors", ops.edge_to_face_vectors(X))
        put(out, k + "gradient", gradient_operator(ops))
        put(out, k + "vertex_faces", ops.vertex_faces())
    for name in ("grid", "sphere"):
        dec = TriangleDEC(*meshes[name])
        k = f"dec/{name}/"
        for a in ("d0", "d1", "star0", "star1", "star2", "cot", "halfedge_weight", "edge_length", "face_area",
                  "corner_angles"):
            put(out, k + a, getattr(dec, a))
        put(out, k + "laplacian", dec.laplacian())
        ex = np.zeros(dec.n_vertices, bool)
        ex[[3, 10]] = True
        put(out, k + "laplacian_exclude", dec.laplacian(ex))
        g = dec_chain(dec)
        put(out, k + "chain_endpoints", dec.chain_endpoints(g))
        jc = dec.jump_coordinates(g)
        u0, u = dec.solve_jump(jc)
        put(out, k + "jump_c", jc.c)
        put(out, k + "jump_u0", u0)
        put(out, k + "jump_u", u)
        put(out, k + "darboux", dec.darboux(u, jc.endpoints))
        put(out, k + "corner_jumps", dec.corner_jumps(u))
        bc = dec.branch_coordinates(g)
        put(out, k + "branch_c", bc.c)
        put(out, k + "branch_u", dec.solve_jump(bc)[1])
    P, T = tet_mesh()
    K = TetComplex(P, T)
    for a in ("T", "volumes", "edges", "faces", "tet_edges", "tet_faces", "tet_face_sign", "face_tets", "d0", "d1",
              "d2", "star0", "star1", "star2"):
        put(out, "tet/" + a, getattr(K, a))
    put(out, "tet/fem_tet_weights", K.fem_tet_weights())
    put(out, "tet/laplacian", K.laplacian())
    put(out, "tet/face_areas", K.face_areas())
    u, info = K.jump_laplace(tet_chain(K))
    put(out, "tet/jump_u", u)
    put(out, "tet/jump_omega", info["omega"])
    vol, G, q = tet_geometry(P, T)
    Y = np.random.default_rng(1).normal(size=(len(T), 3))
    put(out, "heat_tet/vol", vol)
    put(out, "heat_tet/quality", q)
    put(out, "heat_tet/p1_laplacian", p1_laplacian(T, vol, G, len(P)))
    put(out, "heat_tet/weak_divergence", weak_divergence(T, vol, G, Y, len(P)))
    for name, V_, F_, curves in swn_cases():
        r = surface_winding_number(V_, F_, curves)
        put(out, f"swn/{name}/corner_values", r.corner_values)
        put(out, f"swn/{name}/face_labels", r.face_labels)
        put(out, f"swn/{name}/u", r.u)
        put(out, f"swn/{name}/residual", r.residual)
    np.savez_compressed(OUT, **out)
    print(f"wrote {OUT}: {len(out)} arrays, {os.path.getsize(OUT) / 1e3:.0f} kB")


if __name__ == "__main__":
    main()
