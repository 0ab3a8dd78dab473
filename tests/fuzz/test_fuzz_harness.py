"""The fuzz suite's own machinery (no gsdf kernel runs here): generation covers the whole public surface, the
knowledge read from docstrings is right, the classification rules hold, the sample is stable."""

from __future__ import annotations

import collections

import numpy as np
import pytest

from tests.fuzz import _cases, _execute, _knowledge, _mutations


@pytest.fixture(scope="module")
def api_cases():
    return _cases.all_cases({"api"})


@pytest.fixture(scope="module")
def cli_cases():
    return _cases.all_cases({"cli"})


def test_every_public_name_is_attacked(api_cases):
    import gsdf

    targets = {c["target"] for c in api_cases}
    for name in gsdf.__all__:
        assert name in targets, f"gsdf.{name} has no generated case"
    per = collections.Counter(c["target"] for c in api_cases)
    sigs = _cases.target_map()
    gap_targets = {t for t, _, why in _cases.coverage_gaps() if why.startswith("required")}
    options = _knowledge.option_classes(gsdf)
    for t, (sig, _) in sigs.items():
        if t not in gap_targets and t not in options and \
                any(p.kind != p.VAR_KEYWORD for p in sig.parameters.values()):
            assert per[t] > 1, f"{t}: only a baseline"
    # every field of every options dataclass is attacked through a function that takes it
    fields = {c["param"].split(".", 1)[1] for c in api_cases if c["area"] == "api:options" and "." in c["param"]}
    for cls, fs in options.items():
        for f in fs:
            assert f in fields, f"{cls}.{f}: attacked through no function"


def test_every_cli_option_is_attacked(cli_cases):
    group = _cases.cli_group()
    attacked = {(c["command"], c.get("param")) for c in cli_cases}
    for name, cmd in group.commands.items():
        assert (name, None) in attacked, f"gsdf {name}: no baseline case"
        for p in cmd.params:
            if getattr(p, "hidden", False):
                continue
            assert (name, p.name) in attacked, f"gsdf {name} {p.opts}: no case"


def test_case_ids_are_unique_and_stable(api_cases, cli_cases):
    ids = [c["id"] for c in api_cases + cli_cases]
    assert len(ids) == len(set(ids))
    again = [c["id"] for c in _cases.all_cases({"api", "cli"})]
    assert sorted(again) == sorted(ids)


def test_gaps_are_reported_not_skipped():
    gaps = _cases.coverage_gaps()
    sigs = _cases.target_map()
    for target, param, why in gaps:
        assert target in sigs and why
    # a required parameter without a fixture is a gap of its target
    assert all("no fixture" in w or "generic" in w for _, _, w in gaps)


def test_doc_knowledge():
    s = _knowledge.Spec("x", "float")
    _knowledge.parse_type_line("float in (0, 1]", s)
    assert (s.lo, s.lo_open, s.hi, s.hi_open) == (0.0, True, 1.0, False)
    s = _knowledge.Spec("x", "int")
    _knowledge.parse_type_line("int >= 2 or gsdf.Grid, default 256", s)
    assert (s.lo, s.lo_open) == (2.0, False) and not s.optional
    s = _knowledge.Spec("x", "str")
    _knowledge.parse_type_line('{"none", "sphere", "cube"}', s)
    assert s.choices == ("none", "sphere", "cube") and not s.optional
    s = _knowledge.Spec("x", "int")
    _knowledge.parse_type_line("int in 3..64", s)
    assert (s.lo, s.hi) == (3.0, 64.0)
    m = _knowledge.scalar_mutations(s)
    assert m["zero"] == "refuse" and m["below_range"] == "refuse" and m["above_range"] == "refuse"


def test_name_knowledge():
    import inspect

    def f(k: int = 20, level: float = 0.0, t: float = 1.0, seed: int = 0, resolution=64):
        """Doc.

        Parameters
        ----------
        k : int
            Neighbours.
        """

    sp = _knowledge.specs("f", inspect.signature(f), f)
    mk = _knowledge.scalar_mutations(sp["k"])
    assert mk["zero"] == "refuse" and mk["negative"] == "refuse" and mk["huge"] == "refuse"
    ml = _knowledge.scalar_mutations(sp["level"])
    assert ml["negative"] == "either" and ml["nan"] == "refuse" and ml["complex"] == "refuse"
    mt = _knowledge.scalar_mutations(sp["t"])
    assert mt["zero"] == "refuse" and mt["negative"] == "refuse" and mt["huge"] == "either"
    ms = _knowledge.scalar_mutations(sp["seed"])
    assert ms["zero"] == "either" and ms["negative"] == "refuse"
    assert sp["resolution"].kind == "int" and sp["resolution"].size


def test_classification():
    c = _execute.classify_exception
    assert c(ValueError("V: contains NaN"), "nan_entry", "refuse")[0] == "pass"
    assert c(ValueError("could not convert string to float: 'x'"), "str", "refuse")[0] == "leak"
    assert c(MemoryError("Unable to allocate 22 GiB"), "huge_rows", "refuse")[0] == "leak"
    assert c(TypeError("unsupported"), "str", "refuse")[0] == "leak"
    assert c(FileNotFoundError(2, "No such file", "x.off"), "missing", "refuse")[0] == "pass"
    assert c(FileNotFoundError(2, "No such file", "x.off"), "directory", "refuse")[0] == "leak"
    assert c(IsADirectoryError(21, "Is a directory"), "directory", "refuse")[0] == "leak"
    assert c(UnicodeDecodeError("utf-8", b"\xff", 0, 1, "bad"), "garbage", "refuse")[0] == "leak"
    assert c(np.linalg.LinAlgError("Singular matrix"), "zero", "either")[0] == "leak"
    assert c(ValueError("k: must be at most 119"), "int32", "accept")[0] == "refused valid"
    assert _execute.finite({"a": np.array([1.0, np.nan])}) is False
    assert _execute.finite((np.zeros(3), None)) is True


def test_mutations_are_deterministic():
    data = b"OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n"
    for m in _mutations.FILE_MUTATIONS:
        try:
            a = _mutations.malform(data, m, "x.off")
        except KeyError:
            continue
        assert a == _mutations.malform(data, m, "x.off")
    assert b"999999999999" in _mutations.malform(data, "huge_count", "x.off")
    assert b"nan" in _mutations.malform(data, "nan_token", "x.off")


def test_sample_is_stable_under_additions(api_cases):
    s1 = _cases.sample(api_cases, 100, 1)
    extra = [dict(area="api:new", target="new", mutation=f"m{i}", expect="refuse", id=f"api:new|new|m{i}")
             for i in range(30)]
    s2 = _cases.sample(api_cases + extra, 100, 1)
    keep = {c["id"] for c in s1}
    other = {c["id"] for c in s2 if c["area"] != "api:new"}
    assert len(keep ^ other) <= 2 * len({c["area"] for c in api_cases})
    assert [c["id"] for c in _cases.sample(api_cases, 100, 1)] == [c["id"] for c in s1]


def test_hypothesis_draws_are_deterministic():
    from tests.fuzz import strategies

    a = strategies.draw(strategies.soups(), 5)
    b = strategies.draw(strategies.soups(), 5)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    V, F = a
    assert np.isfinite(V).all() and F.min() >= 0 and F.max() < len(V)


def test_a_changed_value_counts_only_when_the_reader_reads_it():
    P = np.arange(6.0).reshape(2, 3)
    read = {"same": lambda p: (P.copy(), None), "changed": lambda p: (P + 1, None), "nothing": lambda p: None}
    u = _execute._unread_change
    assert u("inf_token", (P, None), read["same"], "x.ply")            # e.g. inf in an extra PLY property
    assert u("npz_ravel", (P, None), read["same"], "pat.npz")           # a tampered array the reader ignores
    assert not u("inf_token", (P, None), read["changed"], "x.ply")      # the reader read it: accepted bad
    assert not u("inf_token", None, read["nothing"], "x.ply")           # no arrays to compare: no excuse
    assert not u("garbage", (P, None), read["same"], "x.ply")           # only value mutations qualify


def test_a_documented_bound_beats_the_name():
    """``normal_radius`` is a positive quantity by name, but the voxel solver documents 0 (trivial normals)."""
    import inspect

    import gsdf

    cls = gsdf.VoxelSurfaceSignedHeatSolver
    sp = _knowledge.specs("VoxelSurfaceSignedHeatSolver", inspect.signature(cls), cls)["normal_radius"]
    m = _knowledge.scalar_mutations(sp)
    assert m["zero"] == "either" and m["negative"] == "refuse"


def test_round_trip_meshes_compare_faces_in_any_order_but_keep_orientation():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    t = _execute._triangles
    same = t(V[F[::-1][:, [1, 2, 0]]], True)                      # faces reordered and rotated
    assert np.array_equal(same, t(V[F], True))
    flipped = t(V[F[:, ::-1]], True)
    assert not np.array_equal(flipped, t(V[F], True)) and np.array_equal(t(V[F[:, ::-1]], False), t(V[F], False))
    assert _execute._roundtrip((V, F[::-1]), {"V": V, "F": F}) is None
    assert _execute._roundtrip((V, F[:, ::-1]), {"V": V, "F": F}) == "mesh read back differs"
