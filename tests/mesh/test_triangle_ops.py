"""gsdf.mesh._triangle_ops.TriangleOperators: the one triangle operator set.

Old vs new: the signed heat method's operators (``TriangleMeshOperators``, now a subclass) are bit-identical to
the former standalone class; the DEC operators (``TriangleDEC``, formerly computing its own cotangents as
dot / |cross| and angles by atan2) now use the shared Eq. 5 cotangents and arccos angles, which moves them by a few
ulps; the surface winding numbers downstream are unchanged. Frozen outputs: tests/mesh/operator_reference.py.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from gsdf.dec._triangle import TriangleDEC
from gsdf.heat.intrinsic._kernels import intrinsic_delaunay, layout
from gsdf.heat.triangle._operators import TriangleMeshOperators
from gsdf.mesh._triangle_ops import PREV, TriangleOperators
from tests.mesh.operator_reference import (dec_chain, fields, identical, load, relative_difference, swn_cases,
                                           triangle_meshes)

MESHES = triangle_meshes()
HEAT_ARRAYS = ("areas", "normals", "cot", "angles", "slot_len", "edges", "face_edges", "slot_sign", "edge_len", "h",
               "slot_u", "slot_w", "slot_rho", "slot_sigma", "edge_ref_slot")


def heat_operators(name):
    if name == "intrinsic":
        V, F = MESHES["grid"]
        Fi, L, _ = intrinsic_delaunay(V, F)
        return TriangleMeshOperators(V, Fi, P=layout(L))
    return TriangleMeshOperators(*MESHES[name])


@pytest.mark.parametrize("name", ["grid", "sphere", "flipped", "intrinsic"])
def test_heat_operators_are_bit_identical_to_the_former_class(name):
    ops = heat_operators(name)
    Y, X, _ = fields(ops.n_vertices, ops.n_faces, ops.n_edges)
    k = f"heat/{name}/"
    got = {a: getattr(ops, a) for a in HEAT_ARRAYS}
    got.update(cotan_laplacian=ops.cotan_laplacian(), vertex_mass=ops.vertex_mass(), cr_mass=ops.cr_mass(),
               cr_connection_laplacian=ops.cr_connection_laplacian(),
               cr_connection_laplacian_real=ops.cr_connection_laplacian_real(),
               cr_vector_heat_matrix=ops.cr_vector_heat_matrix(0.05), divergence=ops.divergence(Y),
               edge_to_face_vectors=ops.edge_to_face_vectors(X), gradient=ops.gradient(),
               vertex_faces=ops.vertex_faces())
    for key, A in got.items():
        assert identical(k + key, A), key


@pytest.mark.parametrize("name", ["grid", "sphere"])
def test_dec_operators_agree_with_the_former_triangle_dec(name):
    dec = TriangleDEC(*MESHES[name])
    k = f"dec/{name}/"
    # no cotangent involved: bit-identical
    for key, A in (("d0", dec.d0), ("d1", dec.d1), ("star0", dec.star0), ("star2", dec.star2),
                   ("face_area", dec.areas)):
        assert identical(k + key, A), key
    # Eq. 5 cotangents instead of dot / |cross|, arccos angles instead of atan2, edge lengths from the face slots
    # (sqrt of a dot product instead of np.linalg.norm): a few ulps (measured ≤ 3.9e-16 relative)
    ex = np.zeros(dec.n_vertices, bool)
    ex[[3, 10]] = True
    for key, A in (("edge_length", dec.edge_len), ("cot", dec.cot_clamped[:, PREV]), ("halfedge_weight", dec.halfedge_weight),
                   ("star1", dec.star1), ("corner_angles", dec.angles), ("laplacian", dec.laplacian()),
                   ("laplacian_exclude", dec.laplacian(ex))):
        assert relative_difference(k + key, A) < 1e-14, key
    g = dec_chain(dec)
    assert identical(k + "chain_endpoints", dec.chain_endpoints(g))
    jc = dec.jump_coordinates(g)
    u0, u = dec.solve_jump(jc)
    bc = dec.branch_coordinates(g)
    ub = dec.solve_jump(bc)[1]
    for key, A in (("jump_c", jc.c), ("branch_c", bc.c), ("darboux", dec.darboux(u, jc.endpoints)),
                   ("corner_jumps", dec.corner_jumps(u))):
        assert relative_difference(k + key, A) < 1e-13, key
    # the jump solve (L + 1e-8 I) fixes the constant only to ~ulp / 1e-8: the solutions agree up to a constant
    # (measured: shifts ≤ 3.8e-9, ≤ 1.8e-15 after removing them)
    for key, A in (("jump_u", u), ("branch_u", ub)):
        d = A - load(k + key)
        assert np.abs(d).max() < 1e-7 and np.ptp(d) < 1e-13, key
    free = ~jc.endpoints
    assert np.ptp((u0 - load(k + "jump_u0"))[free]) < 1e-13


@pytest.mark.parametrize("case", swn_cases(), ids=[c[0] for c in swn_cases()])
def test_surface_winding_numbers_unchanged(case):
    from gsdf.swn._solver import surface_winding_number

    name, V, F, curves = case
    r = surface_winding_number(V, F, curves)
    k = f"swn/{name}/"
    assert identical(k + "face_labels", r.face_labels)
    assert np.abs(r.corner_values - load(k + "corner_values")).max() < 1e-12           # measured 1.1e-15
    assert np.abs(r.residual - load(k + "residual")).max() < 1e-12
    assert np.ptp(r.u - load(k + "u")) < 1e-12                                         # u: up to a constant


# ------------------------------------------------------------------------------------------ the operators
def test_coboundaries_laplacian_and_stars():
    V, F = MESHES["sphere"]
    ops = TriangleOperators(V, F)
    assert abs(ops.d1 @ ops.d0).max() == 0
    C = ops.cotan_laplacian()
    assert abs(C @ np.ones(len(V))).max() < 1e-12 and abs(C - C.T).max() == 0
    # C = d0ᵀ diag(w) d0 with the edge cotan weights w_e = ½ Σ cot of the opposite angles
    w = np.bincount(ops.face_edges.ravel(), 0.5 * ops.cot[:, PREV].ravel(), minlength=ops.n_edges)
    assert abs(C - ops.d0.T @ sp.diags(w) @ ops.d0).max() < 1e-12
    assert np.isclose(ops.vertex_mass().sum(), ops.areas.sum()) and np.isclose(ops.cr_mass_diagonal().sum(),
                                                                                ops.areas.sum())
    assert np.allclose(ops.angles.sum(axis=1), np.pi)


def test_cotangents_gradient_and_divergence_on_a_flat_patch():
    V, F = MESHES["grid"]
    ops = TriangleOperators(V, F)
    E = ops.P[:, [1, 2, 0]] - ops.P
    ang = np.arccos(np.einsum("fij,fij->fi", E, -E[:, PREV]) / (ops.slot_len * ops.slot_len[:, PREV]))
    assert np.allclose(ops.cot, 1 / np.tan(ang))
    phi = V @ [0.3, -1.2, 0.0]                                # linear: the gradient is exact on every face
    assert np.allclose((ops.gradient() @ phi).reshape(-1, 3), [0.3, -1.2, 0.0], atol=1e-12)
    # the divergence is minus the adjoint of the gradient in the area-weighted inner product
    Y = np.random.default_rng(0).normal(size=(len(F), 3))
    assert np.allclose(ops.divergence(Y), ops.gradient().T @ (ops.areas[:, None] * Y).ravel(), atol=1e-12)
    # edges=False: the vertex operators only
    lean = TriangleOperators(V, F, edges=False)
    assert not hasattr(lean, "edges") and abs(lean.cotan_laplacian() - ops.cotan_laplacian()).max() == 0
