"""Error and time against the user-facing parameters (the tables of docs/guide/parameters.md).

One shape, four conditions of it: CGAL's elephant.off (closed, genus 3) as the truth, and as inputs

* clean — elephant.off itself;
* holey — elephant-with-holes.off (the same elephant with ~20 % of the faces cut out);
* noisy — elephant.off with Gaussian vertex noise, σ = 0.5 % of the bounding-box diagonal;
* flipped — elephant.off with 30 % of its faces reversed (badly oriented).

Reference: the exact signed distance to the clean elephant (closest triangle, sign of the exact winding number).
Swept, one parameter at a time, the others at their defaults:

* ``signed_heat_volume``: ``t_coef`` × ``t_scale`` at resolution 32, and ``resolution`` (mean |φ − φ_ref| over
  the grid nodes within 10 % of the diagonal of the surface, where the field is used);
* ``fast_winding_number``: ``beta`` (RMS against the exact winding number of the same input, and the fraction of
  queries classified like the truth, w ≥ 1/2);
* ``point_areas`` / ``fast_winding_number_points``: ``k`` on the vertices with area-weighted normals (noisy and
  flipped conditions perturb positions / normals);
* ``signed_distance_grid``: ``resolution`` (time, and error on the nodes — it is exact up to the sign).

Run: ``PYTHONPATH=src python3 bench/bench_parameters.py`` (~5-10 min on 2 loaded cores); writes the "parameters"
section of bench/RESULTS.md and docs/_generated/parameters.md (included by docs/guide/parameters.md).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import command, data_dir, heading, table, write_section
from load import uptime  # noqa: E402  # noqa: E402

import gsdf  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DOCS_OUT = os.path.join(HERE, "..", "docs", "_generated", "parameters.md")


def load_inputs():
    root = os.path.join(data_dir(), "meshes")
    V, F = gsdf.read_mesh(os.path.join(root, "elephant.off"))
    Vh, Fh = gsdf.read_mesh(os.path.join(root, "elephant-with-holes.off"))
    rng = np.random.default_rng(0)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    Vn = V + rng.normal(scale=0.005 * diag, size=V.shape)
    Ff = F.copy()
    flip = rng.random(len(F)) < 0.3
    Ff[flip] = Ff[flip][:, ::-1]
    return (V, F), {"clean": (V, F), "holey": (Vh, Fh), "noisy": (Vn, F), "flipped": (V, Ff)}, diag


def vertex_normals(V, F):
    """Area-weighted vertex normals (the oriented cloud a scanner would give for this mesh)."""
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N = np.zeros_like(V)
    for j in range(3):
        np.add.at(N, F[:, j], n)
    return N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def main():
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    truth, inputs, diag = load_inputs()
    Vt, Ft = truth
    exact_truth = gsdf.ExactWindingNumber(Vt, Ft)
    dist_truth = gsdf.TriangleDistance(Vt, Ft)

    def ref_sdf(Q):
        return np.sign(0.5 - exact_truth(Q)) * dist_truth.query(Q)[0]

    lines = [
        heading("Parameters: error and time against the user-facing parameters",
                command("bench_parameters.py", [])).rstrip(), "",
        "Times are indicative on a shared machine: compare within a table.", "",
        "Shape: CGAL elephant.off (5,558 faces, closed, genus 3, bbox diagonal "
        f"{diag:.3f}); inputs: clean, holey = elephant-with-holes.off, noisy = vertex noise σ = 0.5 % of the "
        "diagonal, flipped = 30 % of the faces reversed. Reference: exact signed distance to the clean elephant.", "",
    ]
    # warm the JIT so the first row is not a compile time
    gsdf.signed_heat_volume(mesh=truth, resolution=12)
    gsdf.fast_winding_number(Vt, Ft, Vt[:10])

    # --- signed heat method in a volume: t_coef x t_scale
    lines += ["### signed_heat_volume: t_coef × t_scale (grid, resolution 32)", "",
              "Mean |φ − φ_ref| over the grid nodes within 10 % of the diagonal of the surface (in units of the "
              "diagonal, ×10⁻³), seconds in brackets.", ""]
    rows = []
    best = {}
    for name, (V, F) in inputs.items():
        row = [name]
        for t_scale in ("grid", "input"):
            for t_coef in (0.25, 1.0, 4.0):
                sec, field = timed(lambda: gsdf.signed_heat_volume(
                    mesh=(V, F), resolution=32, t_coef=t_coef, options=gsdf.VolumeHeatOptions(t_scale=t_scale)))
                X = grid_nodes(field)
                ref = ref_sdf(X)
                near = np.abs(ref) < 0.1 * diag
                err = float(np.mean(np.abs(field(X[near]) - ref[near]))) / diag
                row.append(f"{err * 1e3:.2f} ({sec:.1f})")
                best.setdefault(name, []).append((err, t_scale, t_coef))
        rows.append(row)
        print(row, flush=True)
    lines += [table(["input"] + [f"{s} t_coef={c}" for s in ("grid", "input") for c in (0.25, 1.0, 4.0)], rows), ""]
    lines += ["Best per input: " + "; ".join(
        f"{n}: t_scale={min(v)[1]}, t_coef={min(v)[2]}" for n, v in best.items()) + ".", ""]

    # --- resolution
    lines += ["### signed_heat_volume: resolution (defaults otherwise)", "",
              "Same error measure (×10⁻³ of the diagonal), seconds in brackets; resolution 32 is the "
              "t_scale=grid, t_coef=1 column above.", ""]
    rows = []
    for name, (V, F) in inputs.items():
        row = [name]
        for res in (16, 24, 40):
            sec, field = timed(lambda: gsdf.signed_heat_volume(mesh=(V, F), resolution=res))
            X = grid_nodes(field)
            ref = ref_sdf(X)
            near = np.abs(ref) < 0.1 * diag
            err = float(np.mean(np.abs(field(X[near]) - ref[near]))) / diag
            row.append(f"{err * 1e3:.2f} ({sec:.1f})")
        rows.append(row)
        print(row, flush=True)
    lines += [table(["input", "16", "24", "40"], rows), ""]

    # --- signed_distance_grid (exact distance, winding-number sign)
    lines += ["### signed_distance_grid: resolution (exact distance, sign from the fast winding number)", "",
              "Mean |φ − φ_ref| over the same near-surface nodes (×10⁻³ of the diagonal) — only the sign can be "
              "wrong — and the fraction of nodes whose sign differs from the truth; seconds in brackets.", ""]
    rows = []
    for name, (V, F) in inputs.items():
        row = [name]
        for res in (32, 48):
            sec, field = timed(lambda: gsdf.signed_distance_grid(V, F, resolution=res))
            X = grid_nodes(field)
            ref = ref_sdf(X)
            near = np.abs(ref) < 0.1 * diag
            v = field(X[near])
            err = float(np.mean(np.abs(v - ref[near]))) / diag
            wrong = float(np.mean(np.sign(v) != np.sign(ref[near])))
            row.append(f"{err * 1e3:.2f}, {100 * wrong:.1f} % ({sec:.1f})")
        rows.append(row)
        print(row, flush=True)
    lines += [table(["input", "32", "48"], rows), ""]

    # --- fast winding number beta
    rng = np.random.default_rng(1)
    lo, hi = Vt.min(0) - 0.05 * diag, Vt.max(0) + 0.05 * diag
    Q = lo + (hi - lo) * rng.random((20000, 3))
    inside_truth = exact_truth(Q) >= 0.5
    lines += ["### fast_winding_number: beta (20,000 random queries in the padded box)", "",
              "RMS against the exact winding number of the same input; % of queries classified (w ≥ 1/2) like "
              "the clean truth; seconds for build + query in brackets (exact: the ExactWindingNumber tree).", ""]
    rows = []
    for name, (V, F) in inputs.items():
        w_exact = gsdf.ExactWindingNumber(V, F)(Q)
        row = [name, f"{100 * np.mean((w_exact >= 0.5) == inside_truth):.2f} %"]
        for beta in (1.0, 2.0, 3.0):
            sec, w = timed(lambda: gsdf.fast_winding_number(V, F, Q, beta=beta))
            rms = float(np.sqrt(np.mean((w - w_exact) ** 2)))
            row.append(f"{rms:.1e}, {100 * np.mean((w >= 0.5) == inside_truth):.2f} % ({sec:.2f})")
        rows.append(row)
        print(row, flush=True)
    lines += [table(["input", "exact: agree", "beta=1", "beta=2", "beta=3"], rows), ""]

    # --- point clouds: k of point_areas
    lines += ["### Point clouds: k of point_areas (fast_winding_number_points, beta 2.3)", "",
              "The mesh's vertices with area-weighted normals as the oriented cloud (noisy: noisy positions; "
              "flipped: 30 % of the normals reversed; holey: the holey mesh's vertices). % of the 20,000 queries "
              "classified like the truth; seconds for areas + query in brackets.", ""]
    rows = []
    for name, (V, F) in inputs.items():
        N = vertex_normals(V, F) if name != "flipped" else vertex_normals(Vt, Ft)
        if name == "flipped":
            N = N * np.where(np.random.default_rng(2).random(len(N)) < 0.3, -1.0, 1.0)[:, None]
        row = [name]
        for k in (10, 20, 40):
            sec, w = timed(lambda: gsdf.fast_winding_number_points(V, N, Q, areas=gsdf.point_areas(V, N, k=k)))
            row.append(f"{100 * np.mean((w >= 0.5) == inside_truth):.2f} % ({sec:.2f})")
        rows.append(row)
        print(row, flush=True)
    lines += [table(["input", "k=10", "k=20", "k=40"], rows), ""]

    lines += [f"At the end: {uptime()}."]
    text = "\n".join(lines)
    write_section("parameters", text)
    if os.environ.get("GSDF_BENCH_RESULTS"):  # a trial run: leave the docs page alone
        print(text)
        return
    os.makedirs(os.path.dirname(DOCS_OUT), exist_ok=True)
    with open(DOCS_OUT, "w") as f:
        f.write(text.replace("## Parameters: error and time against the user-facing parameters", "## Measured", 1) + "\n")
    print(text)


def grid_nodes(field):
    """The grid nodes of a GridField, (n, 3)."""
    vals = np.asarray(field.values)
    axes = [np.linspace(field.bbox_min[i], field.bbox_max[i], vals.shape[i]) for i in range(3)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


if __name__ == "__main__":
    main()
