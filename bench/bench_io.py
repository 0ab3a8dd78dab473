"""Mesh readers: gsdf.read_mesh against trimesh (process=False) and meshio on a broken soup, speed and fidelity.

Why gsdf keeps its own OBJ/OFF/PLY/STL parsers while the other formats go through trimesh / meshio: on a soup with
polygons, duplicated and degenerate faces and unreferenced vertices, "exact" means the vertices and the fan-
triangulated faces come back identical to what was written (order included).

Run: ``PYTHONPATH=src python3 bench/bench_io.py [n_lat]`` (default 400 -> ~0.32 M triangles); writes the
"io-readers" section of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import tempfile
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from common import command, heading, median_time, table, write_section  # noqa: E402

import gsdf  # noqa: E402


def soup(n_lat: int):
    """A UV sphere (quads as polygons) + duplicated and degenerate triangles + unreferenced vertices."""
    n_lon = 2 * n_lat
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")
    V = np.column_stack([np.sin(T).ravel() * np.cos(P).ravel(), np.sin(T).ravel() * np.sin(P).ravel(),
                         np.cos(T).ravel()])
    idx = np.arange(len(V)).reshape(n_lat - 1, n_lon)
    a, b = idx[:-1], np.roll(idx[:-1], -1, axis=1)
    c, d = idx[1:], np.roll(idx[1:], -1, axis=1)
    quads = np.stack([a, c, d, b], axis=-1).reshape(-1, 4)
    rng = np.random.default_rng(0)
    tris = quads[rng.integers(0, len(quads), len(quads) // 20)][:, :3]
    dup = np.vstack([tris, tris])  # duplicated
    degenerate = np.column_stack([tris[:, 0], tris[:, 0], tris[:, 1]])
    V = np.vstack([V, rng.normal(size=(100, 3)) * 5])  # unreferenced vertices
    polys = list(quads) + list(dup) + list(degenerate)
    fan = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]).reshape(2, -1, 3).transpose(1, 0, 2).reshape(-1, 3)
    F = np.vstack([fan, dup, degenerate])
    return V, polys, F


def exact(V, F, V0, F0) -> str:
    if V.shape == V0.shape and np.array_equal(V, V0) and F.shape == F0.shape and np.array_equal(F, F0):
        return "exact"
    return f"differs ({len(V)}/{len(V0)} vertices, {len(F)}/{len(F0)} triangles)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n_lat", nargs="?", type=int, default=400, help="latitude rings of the soup (400: ~0.32 M triangles)")
    n_lat = ap.parse_args().n_lat
    import meshio
    import trimesh

    V0, polys, F0 = soup(n_lat)
    d = tempfile.mkdtemp()
    rows = []
    for ext in (".obj", ".off", ".ply"):
        p = os.path.join(d, "soup" + ext)
        tw, _ = median_time(lambda: gsdf.write_mesh(p, V0, polys), 1)
        t0, (V, F) = median_time(lambda: gsdf.read_mesh(p), 3)
        rows.append([ext, "gsdf.read_mesh", f"{t0:.2f}", exact(V, F, V0, F0), f"write {tw:.2f} s"])
        try:
            t1, m = median_time(lambda: trimesh.load(p, process=False, force="mesh"), 3)
            rows.append([ext, "trimesh.load(process=False)", f"{t1:.2f}",
                         exact(np.asarray(m.vertices), np.asarray(m.faces), V0, F0), ""])
        except Exception as exc:  # noqa: BLE001 - report what the library does
            rows.append([ext, "trimesh.load(process=False)", "-", f"fails: {type(exc).__name__}", ""])
        try:
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()), \
                    warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t2, mm = median_time(lambda: meshio.read(p), 3)
            cells = [c for c in mm.cells if c.type in ("triangle", "quad")]
            rows.append([ext, "meshio.read", f"{t2:.2f}", f"{len(mm.points)}/{len(V0)} vertices, blocks "
                         f"{[c.type for c in mm.cells][:4]} (face order by type)", ""])
            del cells
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - meshio calls sys.exit on failures
            rows.append([ext, "meshio.read", "-", f"fails: {type(exc).__name__}", ""])
    text = (heading("Mesh readers against trimesh and meshio", command("bench_io.py", [str(n_lat)]))
            + "Times are indicative on a shared machine: compare within a row group.\n\n"
            f"Soup: {len(V0)} vertices (100 unreferenced), {len(polys)} polygons (quads, duplicated and degenerate "
            f"triangles) -> {len(F0)} triangles after fan triangulation. 'exact' = vertices and triangles identical "
            "to what was written, in order.\n\n"
            + table(["format", "reader", "median s", "result", "note"], rows))
    print(text)
    write_section("io-readers", text)


if __name__ == "__main__":
    main()
