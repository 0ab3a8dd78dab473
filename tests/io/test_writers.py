"""Library writers (not only the CLI) keep the requested name, refuse extensions they cannot honour, and write
atomically."""

import numpy as np
import pytest


def test_library_writers_refuse_wrong_extensions_and_keep_names(tmp_path):
    """save_voxels, PointsAsTori.save, write_svg and render_png: the named file or a ValueError, never a
    silently renamed file (numpy appends .npz) and never a half-written one."""
    import gsdf
    from gsdf.contour import write_svg
    from gsdf.ops import load_voxels, save_voxels
    from gsdf import render_png

    occ = np.ones((2, 2, 2), bool)
    with pytest.raises(ValueError, match=r"\.npz"):
        save_voxels(tmp_path / "v.dat", occ, [0, 0, 0], [1, 1, 1])
    assert not (tmp_path / "v.dat.npz").exists() and not (tmp_path / "v.dat").exists()
    save_voxels(tmp_path / "v.npz", occ, [0, 0, 0], [1, 1, 1])
    assert int(load_voxels(tmp_path / "v.npz")[0].sum()) == 8
    sq = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    with pytest.raises(ValueError, match=r"\.svg"):
        write_svg(tmp_path / "s.txt", [[sq]])
    assert write_svg(tmp_path / "s.svg", [[sq]]) == str(tmp_path / "s.svg")
    ball = lambda Q: np.linalg.norm(Q, axis=1) - 0.5  # noqa: E731
    with pytest.raises(ValueError, match=r"\.png"):
        render_png(ball, tmp_path / "b.jpg", 8, 8, bbox_min=[-1] * 3, bbox_max=[1] * 3)
    render_png(ball, tmp_path / "b.png", 8, 8, bbox_min=[-1] * 3, bbox_max=[1] * 3)
    assert (tmp_path / "b.png").stat().st_size > 0
    rng = np.random.default_rng(0)
    P = rng.normal(size=(300, 3))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    pat = gsdf.PointsAsTori(P, P)
    with pytest.raises(ValueError, match=r"\.npz"):
        pat.save(tmp_path / "t")
    assert not (tmp_path / "t.npz").exists()
    pat.save(tmp_path / "t.npz")
    back = gsdf.PointsAsTori.load(tmp_path / "t.npz")
    np.testing.assert_array_equal(back.signed_distance(P[:5]), pat.signed_distance(P[:5]))


def test_vertex_data_with_several_components(tmp_path):
    """An (n, 3) per-vertex array (point-cloud-utils' custom attributes, gpytoolbox's N=): PLY stores its columns
    as name_0, name_1, name_2; VTK/VTU as one 3-component array."""
    from gsdf.io import read_vertex_data, write_mesh

    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    vec = np.random.default_rng(0).random((4, 3))
    for binary in (True, False):
        p = tmp_path / f"v{binary}.ply"
        write_mesh(p, V, F, vertex_data={"vector": vec, "d": V[:, 0]}, binary=binary)
        got = read_vertex_data(p)
        assert list(got) == ["vector_0", "vector_1", "vector_2", "d"]
        np.testing.assert_array_equal(np.column_stack([got[f"vector_{j}"] for j in range(3)]), vec)
    p = tmp_path / "v.vtu"
    write_mesh(p, V, F, vertex_data={"vector": vec})
    np.testing.assert_array_equal(read_vertex_data(p)["vector"], vec)
    with pytest.raises(ValueError, match="given twice"):
        write_mesh(tmp_path / "x.ply", V, F, vertex_data={"n": vec, "n_0": V[:, 0]})
    with pytest.raises(ValueError, match=r"shape \(4,\) or \(4, k\)"):
        write_mesh(tmp_path / "x.ply", V, F, vertex_data={"n": vec[:3]})


def test_binary_is_a_switch(tmp_path):
    """'no' is truthy: a string for binary is refused, not taken as True (and nothing is written)."""
    import os

    import gsdf

    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match="binary: expected True or False"):
        gsdf.write_mesh(tmp_path / "m.ply", V, [[0, 1, 2]], binary="no")
    with pytest.raises(ValueError, match="binary: expected True or False"):
        gsdf.write_points(tmp_path / "p.ply", V, binary="no")
    assert not os.listdir(tmp_path)


@pytest.mark.parametrize("bad", ["x", [1.0, 2.0], 3])
def test_vertex_data_must_be_a_dict(tmp_path, bad):
    """A string leaked AttributeError: 'str' object has no attribute 'items'."""
    from gsdf.io import write_mesh

    p = tmp_path / "m.ply"
    with pytest.raises(ValueError, match="vertex_data: expected a dict"):
        write_mesh(p, np.eye(3), [[0, 1, 2]], vertex_data=bad)
    assert not p.exists()
