"""Every `gsdf` subcommand on bad inputs and bad outputs: a non-zero exit, one error line, no traceback, inputs
untouched.

The table COMMANDS holds one valid invocation per subcommand (checked to succeed, so the failing cases fail for
the reason they test); a new subcommand must get a row (test_every_subcommand_has_a_row).
"""

import hashlib
import os

import numpy as np
import pytest
from click.testing import CliRunner

import gsdf
from gsdf.cli.main import main

from tests.shapes import cube, fibonacci_sphere, uv_sphere

# name -> (arguments with {placeholders} for the input files, the -o output name)
COMMANDS = {
    "winding": (["{mesh}", "{queries}", "--exact"], "w.npy"),
    "sdf": (["{mesh}", "--resolution", "6", "-q"], "s.npz"),
    "voxelize": (["{mesh}", "--resolution", "4", "-q"], "v.npz"),
    "surface": (["{mesh}", "--resolution", "6", "--bisection", "0", "-q"], "s.ply"),
    "boolean": (["{mesh}", "{mesh2}", "--op", "union", "--exact"], "b.ply"),
    "slice": (["{mesh}", "--layers", "1", "--resolution", "8", "-q"], "s.svg"),
    "heat": (["{mesh}", "--resolution", "6", "-q"], "h.npz"),
    "heat-surface": (["{sphere}", "--curves", "{curves}", "-q"], "h.ply"),
    "tori": (["{cloud}", "-k", "8"], "t.npz"),
    "render": (["{cloud}", "--size", "8"], "r.png"),
    "swn": (["{sphere}", "{swn_curves}", "-q"], "w.ply"),
    "reconstruct": (["{cloud}", "--method", "winding", "--resolution", "8", "-q"], "r.ply"),
}
# subcommands with their own safety tests here or elsewhere
EXEMPT = {"demo": "test_demo_output_folder_that_is_a_file", "warmup": "reads and writes no user files",
          "batch": "writes a folder of items; tests/batch/test_batch.py",
          "view": "renders with polyscope where EGL works; tests/cli/test_view.py"}
COMMANDS = {k: v for k, v in COMMANDS.items() if k in main.commands}  # rows for subcommands of other branches
INPUT_KEYS = ("mesh", "mesh2", "queries", "sphere", "curves", "swn_curves", "cloud")


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    V, F = cube()
    paths = {k: str(d / n) for k, n in (("mesh", "cube.ply"), ("mesh2", "cube2.ply"), ("queries", "q.npy"),
                                         ("sphere", "sphere.ply"), ("curves", "c.txt"), ("swn_curves", "swn.txt"),
                                         ("cloud", "cloud.xyz"))}
    gsdf.write_mesh(paths["mesh"], V, F)
    gsdf.write_mesh(paths["mesh2"], V + 0.3, F)
    np.save(paths["queries"], np.array([[0.0, 0, 0], [2, 0, 0]]))
    Vs, Fs = uv_sphere(6, 12)
    gsdf.write_mesh(paths["sphere"], Vs, Fs)
    ring = 1 + 4 * 12 // 2 + np.arange(12)  # vertices of the middle latitude ring
    with open(paths["curves"], "w") as fh:
        fh.write("signed_curve\n" + "".join(f"v {i}\n" for i in np.append(ring, ring[0])))
    with open(paths["swn_curves"], "w") as fh:  # the SWN demo format: nodes 'v i', segments 'l a b' between nodes
        fh.write("".join(f"v {i}\n" for i in ring) + "".join(f"l {k} {(k + 1) % 12}\n" for k in range(12)))
    P = fibonacci_sphere(120)
    gsdf.write_points(paths["cloud"], P, P)
    paths["dir"] = str(d)
    return paths


def digest(paths):
    return {p: hashlib.sha256(open(p, "rb").read()).hexdigest() for p in paths if os.path.isfile(p)}


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])  # catch_exceptions=True: leaks show in r.exception


def args_for(name, files, output):
    argv, _ = COMMANDS[name]
    return [name] + [a.format(**files) for a in argv] + ["-o", output]


def assert_clean_failure(r, *, contains=None):
    """Non-zero exit through click (no leaked exception), exactly one error line, no traceback."""
    assert r.exit_code != 0, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), f"leaked {r.exception!r}\n{r.output}"
    assert "Traceback" not in r.output, r.output
    errors = [line for line in r.output.splitlines() if line.startswith("Error")]
    assert len(errors) == 1, r.output
    if contains is not None:
        assert contains in errors[0].lower(), errors[0]
    return errors[0]


def test_every_subcommand_has_a_row():
    listed = set(main.commands) - set(EXEMPT)
    missing = listed - set(COMMANDS)
    assert not missing, f"add a row to COMMANDS in {__file__} for: {sorted(missing)}"


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_valid_invocation_succeeds_and_never_touches_inputs(name, inputs, tmp_path):
    before = digest([inputs[k] for k in INPUT_KEYS])
    out = tmp_path / "sub" / COMMANDS[name][1]  # a missing parent folder is created
    r = invoke(args_for(name, inputs, out))
    assert r.exit_code == 0, r.output
    assert out.exists() and not [p for p in os.listdir(out.parent) if p.endswith(".tmp" + out.suffix)]
    # the default replaces an existing output; --no-clobber refuses it and leaves it alone
    stamp = out.read_bytes()
    r = invoke(args_for(name, inputs, out) + ["--no-clobber"])
    assert_clean_failure(r, contains="exists")
    assert out.read_bytes() == stamp
    assert digest([inputs[k] for k in INPUT_KEYS]) == before


def _slots(name):
    argv, _ = COMMANDS[name]
    return [k for k in INPUT_KEYS if any("{" + k + "}" in a for a in argv)]


CASES = [(n, k) for n in sorted(COMMANDS) for k in _slots(n)]


@pytest.mark.parametrize("name,slot", CASES)
@pytest.mark.parametrize("kind", ["garbage", "truncated", "empty", "missing", "directory"])
def test_bad_input(name, slot, kind, inputs, tmp_path):
    files = dict(inputs)
    ext = os.path.splitext(inputs[slot])[1]
    bad = tmp_path / f"bad{ext}"
    if kind == "garbage":
        bad.write_bytes(bytes(range(256)) * 7 + b"\xff\xfe\x00garbage")
    elif kind == "truncated":
        data = open(inputs[slot], "rb").read()
        bad.write_bytes(data[: max(1, len(data) // 3)])
    elif kind == "empty":
        bad.write_bytes(b"")
    elif kind == "directory":
        bad.mkdir()
    files[slot] = str(bad)
    before = digest([files[k] for k in INPUT_KEYS])
    out = tmp_path / COMMANDS[name][1]
    r = invoke(args_for(name, files, out))
    if kind == "truncated" and r.exit_code == 0:
        pytest.skip("this truncation still leaves a valid file")  # e.g. a text cloud cut at a line end
    assert_clean_failure(r)
    assert not out.exists()
    assert digest([files[k] for k in INPUT_KEYS]) == before


@pytest.mark.parametrize("name", sorted(COMMANDS))
@pytest.mark.parametrize("kind", ["parent_is_file", "directory", "bad_extension", "readonly_folder"])
def test_bad_output(name, kind, inputs, tmp_path):
    ext = os.path.splitext(COMMANDS[name][1])[1]
    if kind == "parent_is_file":
        (tmp_path / "afile").write_text("x")
        out, needle = tmp_path / "afile" / f"o{ext}", "not a folder"
    elif kind == "directory":
        out, needle = tmp_path, "directory"
    elif kind == "bad_extension":
        out, needle = tmp_path / "o.vdb", "supported extensions"
    elif os.geteuid() != 0:
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        out, needle = ro / f"o{ext}", "not writable"
    else:  # root writes into read-only folders; sysfs refuses new files even to root
        if not _sysfs_refuses_files():
            pytest.skip("no folder refuses root here")
        out, needle = f"/sys/gsdf-safety-test{ext}", "cannot write"
    before = digest([inputs[k] for k in INPUT_KEYS])
    line = assert_clean_failure(invoke(args_for(name, inputs, out)), contains=needle)
    assert str(out) in line or "folder" in line
    assert not os.path.exists(str(out) + ".npz")  # never a silently different name
    assert digest([inputs[k] for k in INPUT_KEYS]) == before


def _sysfs_refuses_files() -> bool:
    import tempfile

    try:
        fd, p = tempfile.mkstemp(dir="/sys")
    except OSError:
        return os.path.isdir("/sys")
    os.close(fd)
    os.remove(p)
    return False


@pytest.mark.parametrize("name,slot", CASES)
def test_input_as_output_is_refused(name, slot, inputs, tmp_path):
    before = digest([inputs[k] for k in INPUT_KEYS])
    r = invoke(args_for(name, inputs, inputs[slot]))
    out_ext = os.path.splitext(COMMANDS[name][1])[1]
    same_kind = os.path.splitext(inputs[slot])[1] == out_ext
    assert_clean_failure(r, contains="input" if same_kind else None)
    # through a symlink too: the real paths are compared
    link = tmp_path / f"link{os.path.splitext(inputs[slot])[1]}"
    link.symlink_to(inputs[slot])
    assert_clean_failure(invoke(args_for(name, inputs, link)), contains="input" if same_kind else None)
    assert digest([inputs[k] for k in INPUT_KEYS]) == before


@pytest.mark.parametrize("option", ["--png", "--mesh-output"])
def test_secondary_outputs_are_checked_too(option, inputs, tmp_path):
    before = digest([inputs[k] for k in INPUT_KEYS])
    r = invoke(args_for("sdf", inputs, tmp_path / "s.npz") + [option, inputs["mesh"]])
    assert_clean_failure(r)
    assert not (tmp_path / "s.npz").exists()  # refused before any work
    r = invoke(args_for("voxelize", inputs, tmp_path / "v.npz") + ["--mesh-output", inputs["mesh"]])
    assert_clean_failure(r, contains="input")
    assert digest([inputs[k] for k in INPUT_KEYS]) == before


def test_heat_offsets_never_overwrite_an_input(inputs, tmp_path):
    # `-o X.npz --offsets 0` writes X_offset_0.ply: refused when that name is the input
    src = tmp_path / "m_offset_0.ply"
    V, F = cube()
    gsdf.write_mesh(str(src), V, F)
    before = digest([str(src)])
    r = invoke(["heat", str(src), "--resolution", "6", "-q", "--offsets", "0", "-o", str(tmp_path / "m.npz")])
    assert_clean_failure(r, contains="input")
    assert digest([str(src)]) == before and not (tmp_path / "m.npz").exists()


def test_empty_query_files(inputs, tmp_path):
    q = tmp_path / "empty.npy"
    np.save(q, np.zeros((0, 3)))
    line = assert_clean_failure(invoke(["winding", inputs["mesh"], str(q), "-o", str(tmp_path / "w.npy")]))
    assert "no query points" in line
    q2 = tmp_path / "empty.xyz"
    q2.write_text("# nothing\n")
    assert_clean_failure(invoke(["winding", inputs["mesh"], str(q2), "-o", str(tmp_path / "w.npy")]))
    q3 = tmp_path / "obj.npy"
    np.save(q3, np.array(["a", "b"]))
    assert_clean_failure(invoke(["winding", inputs["mesh"], str(q3), "-o", str(tmp_path / "w.npy")]))


def test_demo_output_folder_that_is_a_file(tmp_path):
    f = tmp_path / "notadir"
    f.write_text("keep me")
    assert_clean_failure(invoke(["demo", "-o", str(f)]))
    assert f.read_text() == "keep me"


@pytest.mark.parametrize("ext", [".npz", ".npy", ".vtk", ".vti", ".vtu"])
def test_sdf_writes_every_field_format_under_the_name_given(ext, inputs, tmp_path):
    out = tmp_path / f"s{ext}"
    r = invoke(args_for("sdf", inputs, out))
    assert r.exit_code == 0, r.output
    assert os.listdir(tmp_path) == [out.name]


def test_heat_tet_reports_its_nodes_and_refuses_vti(inputs, tmp_path):
    r = invoke(["heat", inputs["mesh"], "--tet", "--resolution", "6", "-q", "-o", str(tmp_path / "t.vtu")])
    assert r.exit_code == 0, r.output
    assert "-node tet mesh" in r.output and "?" not in r.output
    line = assert_clean_failure(invoke(["heat", inputs["mesh"], "--tet", "-q", "-o", str(tmp_path / "t.vti")]))
    assert ".npz, .npy, .vtk, .vtu" in line


@pytest.mark.parametrize("name", ["heat-surface", "swn"])
@pytest.mark.parametrize("view", ["0,0,0", "1,2", "a,b,c", "nan,0,1"])
def test_bad_view_is_a_usage_error_before_any_work(name, view, inputs, tmp_path):
    if name not in COMMANDS:
        pytest.skip(f"{name} is not a subcommand here")
    out = tmp_path / COMMANDS[name][1]
    r = invoke(args_for(name, inputs, out) + ["--png", str(tmp_path / "p.png"), "--view", view])
    assert r.exit_code == 2 and "--view" in r.output and "Traceback" not in r.output
    assert not out.exists()


# ------------------------------------------------------------------------------------ outputs as one set


def test_two_outputs_with_one_name_refused_before_any_work(inputs, tmp_path):
    r = invoke(["sdf", inputs["mesh"], "--resolution", "6", "-q", "--mesh-output", tmp_path / "x.vtk",
                "-o", tmp_path / "x.vtk"])
    assert "named by both -o and --mesh-output" in assert_clean_failure(r)
    (tmp_path / "a.vtk").write_bytes(b"old")
    os.link(tmp_path / "a.vtk", tmp_path / "b.vtk")  # two names, one file
    r = invoke(["sdf", inputs["mesh"], "--resolution", "6", "-q", "--mesh-output", tmp_path / "a.vtk",
                "-o", tmp_path / "b.vtk"])
    assert "named by both -o and --mesh-output" in assert_clean_failure(r)
    assert sorted(os.listdir(tmp_path)) == ["a.vtk", "b.vtk"] and (tmp_path / "a.vtk").read_bytes() == b"old"
    r = invoke(["sdf", inputs["mesh"], "--resolution", "6", "-q", "--png", tmp_path / "p.png",
                "--mesh-output", tmp_path / "z.ply", "-o", tmp_path / "g.npz"])
    assert r.exit_code == 0, r.output
    assert sorted(os.listdir(tmp_path)) == ["a.vtk", "b.vtk", "g.npz", "p.png", "z.ply"]


def test_a_late_failure_leaves_no_output(inputs, tmp_path):
    """The grid and the picture are computed, then the surface fails (no zero level set in an open triangle):
    nothing appears, the folder made for the outputs is removed, an existing file keeps its content."""
    tri = tmp_path / "tri.off"
    tri.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    (tmp_path / "s.png").write_bytes(b"old picture")
    r = invoke(["sdf", tri, "--resolution", "8", "-q", "--mesh-output", tmp_path / "s.ply", "--png",
                tmp_path / "s.png", "-o", tmp_path / "new" / "g.npz"])
    err = assert_clean_failure(r, contains="outside the field's range")
    assert "->" not in r.output.replace(err, "")  # no '-> path' line claims a file that was not left
    assert sorted(os.listdir(tmp_path)) == ["s.png", "tri.off"]
    assert (tmp_path / "s.png").read_bytes() == b"old picture"


def test_heat_offset_outside_the_field_leaves_no_field(inputs, tmp_path):
    r = invoke(["heat", inputs["mesh"], "--resolution", "6", "-q", "--offsets", "5", "-o", tmp_path / "h.npz"])
    assert_clean_failure(r, contains="outside the field's range")
    assert os.listdir(tmp_path) == []
    for bad in ("nan", "inf", ",", "1e308x"):
        r = invoke(["heat", inputs["mesh"], "--resolution", "6", "-q", "--offsets", bad, "-o", tmp_path / "h.npz"])
        assert r.exit_code == 2 and os.listdir(tmp_path) == [], r.output  # a usage error before any work


def test_heat_t_coef_beyond_any_domain_refused(inputs, tmp_path):
    r = invoke(["heat", inputs["mesh"], "--resolution", "6", "-q", "--t-coef", "1e308", "-o", tmp_path / "h.npz"])
    assert_clean_failure(r, contains="t_coef: must be a finite positive number <= 1e+06")
    assert os.listdir(tmp_path) == []


def test_outputs_set_commits_all_or_restores(tmp_path, monkeypatch):
    """A rename failing half way through the commit puts the replaced file back and removes the new ones."""
    from gsdf.cli import _common

    (tmp_path / "b.txt").write_text("old b")
    real = os.replace
    calls = []

    def flaky(src, dst):
        calls.append(dst)
        if str(dst).endswith("c.txt"):
            raise OSError(28, "No space left on device")
        return real(src, dst)

    monkeypatch.setattr(_common.os, "replace", flaky)
    with pytest.raises(ValueError, match="cannot write the outputs .No space left on device.; nothing was written"):
        with _common.outputs():
            for name in ("a.txt", "b.txt", "c.txt"):
                with _common.output_file(tmp_path / name) as tmp:
                    open(tmp, "w").write("new " + name)
    assert sorted(os.listdir(tmp_path)) == ["b.txt"] and (tmp_path / "b.txt").read_text() == "old b"


def test_memory_error_is_one_line(inputs, tmp_path, monkeypatch):
    import gsdf.ops._distance_grid as dg

    def boom(*a, **k):
        raise MemoryError("Unable to allocate 5.00 GiB for an array")

    monkeypatch.setattr(dg, "signed_distance_grid", boom)
    r = invoke(["sdf", inputs["mesh"], "--resolution", "6", "-q", "-o", tmp_path / "g.npz"])
    assert "out of memory (Unable to allocate 5.00 GiB" in assert_clean_failure(r)
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("var, value", [("GSDF_MEMORY_LIMIT", "nan"), ("GSDF_MEMORY_LIMIT", "x"),
                                        ("GSDF_WORK_LIMIT", "soon")])
def test_limit_variables_checked_before_any_work(inputs, tmp_path, monkeypatch, var, value):
    monkeypatch.setenv(var, value)
    r = invoke(["sdf", inputs["mesh"], "--resolution", "6", "-q", "-o", tmp_path / "g.npz"])
    assert var in assert_clean_failure(r)
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("kind", ["fifo", "dir", "dev"])
def test_inputs_that_are_not_regular_files(inputs, tmp_path, kind):
    p = tmp_path / "in.off"
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "dir":
        p.mkdir()
    elif os.path.exists("/dev/zero"):
        p.symlink_to("/dev/zero")
    else:
        pytest.skip("no /dev/zero")
    r = invoke(["sdf", p, "--resolution", "6", "-q", "-o", tmp_path / "g.npz"])
    assert_clean_failure(r)
    assert not (tmp_path / "g.npz").exists()


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="mounting a small tmpfs needs root")
def test_disk_full_leaves_nothing(inputs, tmp_path):
    import subprocess

    full = tmp_path / "full"
    full.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16k", "tmpfs", str(full)]).returncode:
        pytest.skip("mount -t tmpfs refused (no CAP_SYS_ADMIN in this container)")
    try:
        r = invoke(["sdf", inputs["mesh"], "--resolution", "24", "-q", "--png", full / "p.png",
                    "-o", full / "sub" / "g.npz"])
        left = os.listdir(full)
    finally:
        subprocess.run(["umount", str(full)])
    assert_clean_failure(r, contains="no space left on device")
    assert left == []
