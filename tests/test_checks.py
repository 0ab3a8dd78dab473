"""gsdf._checks: the one real-number check, switches, neighbour counts and input files (issue: bad values
accepted, leaked internal errors, FIFO / device / folder inputs)."""

import os

import numpy as np
import pytest

from gsdf._checks import _real, as_faces, as_occupancy, as_points, as_values, flag, neighbours, readable_file

INTERNALS = ("could not convert", "invalid literal", "ufunc", "check for nan", "inhomogeneous")


@pytest.mark.parametrize("bad, why", [
    (np.array([1 + 2j, 3]), "complex"),
    (np.array(["1", "2"]), "strings"),
    (np.array([True, False]), "booleans"),
    (np.array([1.0, object()], dtype=object), "Python objects"),
    ([[1.0, 2.0], [3.0]], "ragged"),
    ("1,2", "string"),
    (np.array([1.0, np.nan]), "NaN"),
    (np.array([1.0, np.inf]), "NaN or infinite"),
])
def test_as_values_refuses_what_is_not_real_numbers(bad, why):
    with pytest.raises(ValueError, match=why) as e:
        as_values(bad, "v")
    assert str(e.value).startswith("v:") and not any(s in str(e.value) for s in INTERNALS)


def test_as_values_shapes_lists_and_empty():
    assert as_values([1, 2, 3], "v", (3,)).dtype == np.float64
    assert as_values((1, 2), "v").tolist() == [1.0, 2.0]
    assert as_values(np.zeros((2, 3), np.float32), "v", (None, 3)).shape == (2, 3)
    with pytest.raises(ValueError, match=r"v: expected shape \(4,\), got \(3,\)"):
        as_values([1, 2, 3], "v", (4,))
    with pytest.raises(ValueError, match=r"expected shape \(3,\), got \(3, 1\)"):
        as_values(np.zeros((3, 1)), "v", (3,))  # a column is not one value per vertex
    with pytest.raises(ValueError, match="is empty"):
        as_values([], "v")
    assert as_values([], "v", allow_empty=True).shape == (0,)
    assert np.isnan(as_values([np.nan], "v", finite=False)[0])


@pytest.mark.parametrize("bad", [np.complex128(1 + 1j), 1j, True, np.bool_(False), "1", b"1", [1.0],
                                 np.array(["x"])[0], np.array(2j)])
def test_scalars_refuse_complex_bools_strings_and_lists(bad):
    with pytest.raises(ValueError, match="x: expected a real number"):
        _real(bad, "x")


def test_points_and_faces_refuse_strings_and_complex_in_gsdf_words():
    for bad in ([["a", "b", "c"]], np.ones((2, 3)) * 1j):
        with pytest.raises(ValueError, match="P: expected numeric coordinates") as e:
            as_points(bad, "P")
        assert not any(s in str(e.value) for s in INTERNALS)
    with pytest.raises(ValueError, match="F: expected an array of numbers, got a string"):
        as_faces("y", 3, "F")
    with pytest.raises(ValueError, match="F: expected integer indices, got complex"):
        as_faces(np.array([[0, 1, 2j]]), 3, "F")


def test_flag_takes_only_bools():
    assert flag(True, "t") is True and flag(np.bool_(False), "t") is False
    for bad in ("yes", "no", 0, 1, None, [1]):
        with pytest.raises(ValueError, match="t: expected True or False"):
            flag(bad, "t")


def test_neighbours_bounded_by_the_cloud():
    assert neighbours(10, 200, default=20) == 10
    assert neighbours(20, 5, default=20) == 20  # the default on a small cloud: the callers' documented clamp
    with pytest.raises(ValueError, match="k: 1000000000 neighbours asked for, but the cloud has 200 points"):
        neighbours(10 ** 9, 200, default=20)
    with pytest.raises(ValueError, match="k: 21 neighbours asked for, but the cloud has 5 points"):
        neighbours(21, 5, default=20)
    with pytest.raises(ValueError, match="k: expected an integer >= 1"):
        neighbours(0, 200)


def test_occupancy_checked_and_sized_before_any_pass():
    assert as_occupancy(np.array([[[0, 1]]]), "occ").dtype == bool
    with pytest.raises(ValueError, match=r"occ: expected a boolean array \(or 0/1 values\)"):
        as_occupancy(np.full((1, 1, 2), 2), "occ")
    with pytest.raises(ValueError, match="occ: expected a 3-D boolean array"):
        as_occupancy(np.ones((2, 2)), "occ")
    with pytest.raises(ValueError, match=r"occ: a 10000x10000x10000 voxel grid \(1,000,000,000,000 voxels\): needs"):
        as_occupancy(np.broadcast_to(np.array(True), (10000,) * 3), "occ")


def test_readable_file_regular_files_only(tmp_path):
    f = tmp_path / "a.off"
    f.write_text("OFF\n")
    assert readable_file(f) == str(f)
    with pytest.raises(FileNotFoundError):
        readable_file(tmp_path / "missing.off")
    (tmp_path / "d.off").mkdir()
    with pytest.raises(ValueError, match="d.off: is a directory, not a file"):
        readable_file(tmp_path / "d.off")
    with pytest.raises(ValueError, match="a parent of this path is a file"):
        readable_file(tmp_path / "a.off" / "b.off")
    fifo = tmp_path / "p.off"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="p.off: is a FIFO"):
        readable_file(fifo)  # would block forever in open()
    if os.path.exists("/dev/zero"):
        (tmp_path / "z.xyz").symlink_to("/dev/zero")
        with pytest.raises(ValueError, match="z.xyz: is a device"):
            readable_file(tmp_path / "z.xyz")  # would read until memory runs out
    for bad in (5, None, True, ""):
        with pytest.raises(ValueError, match="path: expected a file name"):
            readable_file(bad, "path")


def test_readable_file_size_guard(tmp_path, monkeypatch):
    f = tmp_path / "big.xyz"
    with open(f, "wb") as fh:
        fh.truncate(1 << 25)  # a 32 MB sparse file
    monkeypatch.setenv("GSDF_MEMORY_LIMIT", "64M")
    with pytest.raises(ValueError, match="big.xyz: reading a file of 32.0 MB: needs about 256.0 MB"):
        readable_file(f)


def test_options_dataclasses_refuse_bad_values_at_construction():
    """The fuzz found options objects that took anything until used (or never)."""
    import gsdf

    for cls, kw in ((gsdf.BooleanOptions, {"exact": "no"}), (gsdf.BooleanOptions, {"beta": "x"}),
                    (gsdf.PointsAsToriOptions, {"ridge": np.inf}), (gsdf.PointsAsToriOptions, {"k_fallback": np.nan}),
                    (gsdf.PointsAsToriOptions, {"curvature_cap": "x"}), (gsdf.VolumeHeatOptions, {"mesher": "bogus"}),
                    (gsdf.VolumeHeatOptions, {"soft_weight": b"x"}), (gsdf.BatchOptions, {"resume": 2}),
                    (gsdf.BatchOptions, {"scheduler_timeout": -np.inf}), (gsdf.BatchOptions, {"scheduler_timeout": 1j}),
                    (gsdf.SdfSamplesOptions, {"margin": -1}), (gsdf.SWNOptions, {"time_limit": 0})):
        with pytest.raises(ValueError, match=next(iter(kw))):
            cls(**kw)
    for cls in (gsdf.BooleanOptions, gsdf.PointsAsToriOptions, gsdf.VolumeHeatOptions, gsdf.BatchOptions,
                gsdf.SdfSamplesOptions, gsdf.SWNOptions):
        cls()  # the defaults are valid


def test_switches_and_callbacks_of_entry_points():
    import gsdf

    with pytest.raises(ValueError, match="report: expected True or False"):
        gsdf.voxels_to_mesh(np.ones((1, 1, 1), bool), [0] * 3, [1] * 3, report="yes")
    with pytest.raises(ValueError, match="progress: expected a callable"):
        gsdf.run_batch("nowhere", "occupancy", "out", progress=float("nan"))
    with pytest.raises(ValueError, match="sdf: did not return real numbers"):
        gsdf.render_png(lambda q: np.linalg.norm(q, axis=1) - 0.5 + 1j, "x.png", 8, 8, bbox_min=[-1] * 3,
                        bbox_max=[1] * 3)


def test_as_values_keeps_scalars_scalar():
    assert as_values(2, "s").shape == () and as_values(np.float32(2), "s").shape == ()
    assert as_values([[1, 2]], "s").flags.c_contiguous
