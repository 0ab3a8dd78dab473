"""The surface-winding-number authors' examples (nzfeng/SWN, the thesis ch. 6 demo), against gsdf.

Source: github.com/nzfeng/SWN @ 49451ae0 (MIT; LICENSE next to the assets). Vendored under data/swn/:
twirl.obj.gz + twirl.txt (every node a mesh vertex, 1456 separate one-edge segments), torus.obj.gz +
torus-phi.txt. The authors' published output for the torus (data/torus_w.obj: their program's winding number as
homogeneous texture coordinates on their cut mesh) is reduced by ../record_refs.py to one value per output face
at its centroid (data/refs/swn.npz).

The SWN repository has no test suite; these are issue 32's checks on its data: curve insertion keeps a closed
manifold mesh manifold, one reader reads the demo's curve files, and gsdf's labels agree with the authors' output
up to the global constant.
"""

from __future__ import annotations

import numpy as np
import pytest

import gsdf
from tests.conformance.helpers import ref

P = "swn"


def parse_swn_curves(path):
    """The demo's curve file: '#offset k', 'v i' nodes (mesh vertices), 'l j k ...' segments between nodes
    (commented-out '#l' segments and the 'n' line skipped); every node here is a vertex. Returns vertex pairs."""
    nodes, lines, off = [], [], 1
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == "#offset":
            off = int(t[1])
        elif t[0].startswith("#") or t[0] == "n":
            continue
        elif t[0] == "v":
            nodes.append(int(t[1]) - off)
        elif t[0] == "l":
            lines.append([int(x) - off for x in t[1:]])
        else:
            raise ValueError(f"unexpected directive {t[0]!r}")
    return [[nodes[a], nodes[b]] for idx in lines for a, b in zip(idx[:-1], idx[1:])]


@pytest.fixture(scope="module")
def twirl(unpacked):
    return unpacked(P, "twirl.obj"), unpacked(P, "twirl.txt")


def test_twirl_cli_insertion_keeps_manifold(twirl, tmp_path):
    """gsdf swn twirl.obj twirl.txt: the closed manifold torus with its curve file is accepted. Regression: curve
    insertion cut a thin face far from the origin into a zero-area triangle ('F: non-manifold mesh: edge (6082,
    6084) has 4 faces'): its degeneracy test compared round-off of absolute coordinates with 1e-12 of the face's
    area (tests/swn/test_insert.py)."""
    mesh, curves = twirl
    from click.testing import CliRunner

    from gsdf.cli.swn import swn

    out = tmp_path / "twirl_w.ply"
    r = CliRunner().invoke(swn, [mesh, curves, "-o", str(out), "--quiet"])
    assert r.exit_code == 0, r.output[-500:]
    assert out.exists()


def test_twirl_segments_direct(twirl):
    """The same 1456 segments passed as vertex pairs (no insertion): surface_winding_number runs on the closed
    genus-1 mesh and labels every face."""
    mesh, curves = twirl
    V, F = gsdf.read_mesh(mesh)
    assert gsdf.mesh_topology(V, F)["closed"]
    res = gsdf.surface_winding_number(V, F, parse_swn_curves(curves))
    assert res.face_labels.shape == (len(F),)
    assert len(np.unique(res.face_labels)) >= 2


@pytest.mark.parametrize("name,nseg", [("twirl.txt", 1456), ("torus-phi.txt", 88)])
def test_read_curves_reads_swn_files(unpacked, name, nseg):
    """gsdf.read_curves on the SWN demo's curve files gives their segments. Regression: read_curves knew only
    the signed heat demo's format ('l 0 1' read as 1-based OBJ indices)."""
    mesh = unpacked(P, "twirl.obj" if name == "twirl.txt" else "torus.obj")
    V, F = gsdf.read_mesh(mesh)
    src = gsdf.read_curves(unpacked(P, name), F)
    assert sum(len(c) - 1 for c in src.curves) == nseg


@pytest.fixture(scope="module")
def torus_labels(unpacked):
    V, F = gsdf.read_mesh(unpacked(P, "torus.obj"))
    res = gsdf.surface_winding_number(V, F, parse_swn_curves(unpacked(P, "torus-phi.txt")))
    r = ref("swn")
    d, face, _ = gsdf.unsigned_distance(V, F, r["torus_w_centroids"], return_closest=True)
    assert d.max() < 1e-12           # the authors' faces subdivide the input's faces
    return res, face, r["torus_w_face_value"]


@pytest.mark.xfail(reason="documented difference (docs/formats.md, conventions): 3 of 7798 faces differ, each within "
                          "one edge length of an endpoint of the broken curve, where the authors' w is 0.66 / 0.59 "
                          "(after the constant) and gsdf's 0.41 / 0.46: both within 0.1 of the rounding level 1/2, "
                          "where the two solvers' w (which differ by 0.17 in the median face) round either way",
                   strict=True)
def test_torus_labels_match_authors_output(torus_labels):
    """torus.obj + torus-phi.txt: gsdf's face labels equal round(the authors' winding number) plus one global
    constant on every face of the authors' output (located by centroid)."""
    res, face, w_auth = torus_labels
    diff = res.face_labels[face] - np.round(w_auth).astype(int)
    assert len(np.unique(diff)) == 1


def test_torus_labels_match_authors_output_off_threshold(torus_labels):
    """The same comparison on the faces where neither answer is within 0.1 of a rounding threshold (the global
    constant taken from the majority)."""
    res, face, w_auth = torus_labels
    w_g = res.corner_values[face].mean(axis=1)
    diff = res.face_labels[face] - np.round(w_auth).astype(int)
    const = np.bincount(diff - diff.min()).argmax() + diff.min()
    near = (np.abs(w_auth - np.floor(w_auth) - 0.5) < 0.1) | (np.abs(w_g - np.floor(w_g) - 0.5) < 0.1)
    assert (diff[~near] == const).all()
