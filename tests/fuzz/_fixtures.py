"""Valid values by parameter *name* — the only hand-written table of the fuzz suite.

A public function whose parameters have conventional names (``V``, ``F``, ``Q``, ``P``, ``N``, ``path``, ``func``,
``curves`` ...) needs nothing here: its baseline call is searched among these candidates (the first combination the
function accepts), and every parameter is then attacked from that baseline. A parameter name with no entry makes its
target a *coverage gap*, printed by the runner: the fix is one line here (by name, reused by every function with a
parameter of that name), never a per-function case.

Values are built lazily: the runner's parent process only asks *whether* a name has candidates; the arrays and the
files are made in the forked case processes (the parent imports gsdf but never runs a kernel).
"""

from __future__ import annotations

import os
import re

import numpy as np

#: names of writer-like targets (``path`` is an output) and reader-like ones (``path`` is an input)
WRITER = re.compile(r"(^|\.)(write_|save|render_png)")
READER = re.compile(r"(^|\.)(read_|load)")

#: parameter names that hold a file or folder name
PATH_NAMES = {"path", "source", "inputs", "out", "screenshot"}


def _sphere(n: int = 120):
    i = np.arange(n) + 0.5
    ph, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    V = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    from scipy.spatial import ConvexHull

    F = ConvexHull(V).simplices.astype(np.int64)
    flip = np.einsum("ij,ij->i", np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), V[F[:, 0]]) < 0
    F[flip] = F[flip][:, ::-1]
    return V, F


class Fixtures:
    """Small valid inputs; files under ``root/fixtures`` (written once by :meth:`prepare`, then only read)."""

    def __init__(self, root: str = ""):
        self.root = root
        self.fdir = os.path.join(root, "fixtures")
        V, F = _sphere()
        self.V, self.F = V, F
        self.Q = np.array([[0.1, 0.2, 0.1], [1.5, 0.0, 0.0], [0.0, -0.3, 0.2], [0.0, 0.0, 2.0]])
        self.V2 = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]) - 0.5
        self.E2 = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
        self.Q2 = np.array([[0.1, 0.0], [2.0, 0.0]])
        self.Xt = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
        self.Tt = np.array([[0, 1, 2, 3]])
        g = np.linspace(-1.5, 1.5, 10)
        G = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1)
        self.grid_vals = np.linalg.norm(G, axis=-1) - 1.0
        self.occ = self.grid_vals < 0
        self.loop = np.array([F[0, 0], F[0, 1], F[0, 2], F[0, 0]])
        self.Ain = np.zeros((3, 3))
        self.Bout = np.full((3, 3), 1.4)
        self.face_mask = np.arange(len(F)) < len(F) // 2
        self.square = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
        self.areas = np.full(len(V), 4 * np.pi / len(V))

    # ------------------------------------------------------------------ files (gsdf's own writers, in a child)
    def prepare(self):
        import gsdf

        os.makedirs(self.fdir, exist_ok=True)
        p = self.path
        gsdf.write_mesh(p("mesh.off"), self.V, self.F)
        gsdf.write_mesh(p("mesh2.off"), self.V + 0.3, self.F)
        gsdf.write_mesh(p("mesh.obj"), self.V, self.F)
        gsdf.write_mesh(p("mesh.ply"), self.V, self.F, vertex_data={"d": self.V[:, 2]})
        gsdf.write_points(p("cloud.xyz"), self.V, self.V)
        np.save(p("queries.npy"), self.Q)
        gsdf.write_curves(p("curves.txt"), [self.loop])
        with open(p("curves.obj"), "w") as fh:
            fh.write("l " + " ".join(str(int(v) + 1) for v in self.loop) + "\n")
        with open(p("curves_swn.txt"), "w") as fh:        # the surface-winding-number demo's node format
            fh.write("".join(f"v {int(v)}\n" for v in self.loop[:-1]) + "l 0 1 2 0\n")
        gsdf.GridField(self.grid_vals, [-1.5] * 3, [1.5] * 3).save(p("field.npz"))
        # the saved state of every class with a load(): each loader gets a file of its own kind
        gsdf.SurfaceField(self.V, self.F, self.V[:, 2].copy()).save(p("surface_field.npz"))
        gsdf.TetField(self.Xt, self.Tt, self.Xt[:, 0].copy()).save(p("tet_field.npz"))
        gsdf.PointsAsTori(self.V, self.V, k=16).save(p("pat.npz"))
        os.makedirs(p("in_dir"), exist_ok=True)
        gsdf.write_mesh(p("in_dir/m.off"), self.V, self.F)

    def path(self, name: str) -> str:
        return os.path.join(self.fdir, name)

    # ------------------------------------------------------------------ callables
    @staticmethod
    def sdf(q):
        return np.linalg.norm(np.asarray(q, float), axis=1) - 1.0

    # ------------------------------------------------------------------ the table
    def table(self, target: str) -> dict:
        """name -> list of zero-argument builders of valid values (a few candidates, tried in order)."""
        s, p = self, self.path

        def grid_field():
            import gsdf

            return gsdf.GridField(s.grid_vals, [-1.5] * 3, [1.5] * 3)

        t = {
            "V": [lambda: s.V, lambda: s.V2, lambda: s.Xt], "VA": [lambda: s.V], "VB": [lambda: s.V + 0.3],
            "vertices": [lambda: s.V, lambda: s.Xt], "X": [lambda: s.Xt, lambda: s.V, lambda: s.V[s.F].mean(axis=1)],
            "F": [lambda: s.F], "FA": [lambda: s.F], "FB": [lambda: s.F], "faces": [lambda: s.F],
            "E": [lambda: s.E2], "T": [lambda: s.Tt], "tets": [lambda: s.Tt],
            "Q": [lambda: s.Q, lambda: s.Q2], "P": [lambda: s.V], "N": [lambda: s.V], "W": [lambda: s.V],
            "A": [lambda: s.Ain], "B": [lambda: s.V, lambda: s.Bout],
            "values": [lambda: s.V[:, 2].copy(), lambda: s.grid_vals, lambda: np.array([-1.0, 1, 1, 1])],
            "f": [lambda: s.V[:, 2].copy()], "phi0": [lambda: s.V[:, 2].copy()],
            "fa": [lambda: np.full(3, -1.0)], "fb": [lambda: np.full(3, 1.0)],
            "areas": [lambda: s.areas], "orient_towards": [lambda: np.zeros(3)],
            "t": [lambda: 0.01], "n": [lambda: 1], "s": [lambda: 1.0], "op": [lambda: "union"],
            "task": [lambda: "occupancy"],
            "bbox_min": [lambda: np.full(3, -1.5)], "bbox_max": [lambda: np.full(3, 1.5)],
            "box": [lambda: (np.full(3, -1.5), np.full(3, 1.5))], "shape": [lambda: (6, 6, 6)],
            "resolution": [lambda: 8],
            "func": [lambda: s.sdf], "sdf": [lambda: s.sdf], "field": [grid_field],
            "radius": [lambda: 0.2], "distance": [lambda: 0.2], "level": [lambda: 0.0],
            "levels": [lambda: [0.0, 0.1]],
            "z_values": [lambda: [0.0]], "contours_per_slice": [lambda: [[s.square]]],
            "occ": [lambda: s.occ], "occupancy": [lambda: s.occ], "face_mask": [lambda: s.face_mask],
            "polygons": [lambda: [f for f in s.F]],
            "curves": [lambda: [s.loop], lambda: [np.array([0, 1, 2, 3, 0])]], "curve": [lambda: s.loop], "nodes": [lambda: s.loop],
            "curve_signs": [lambda: [True]],
            "face": [lambda: np.array([0, 1])], "bary": [lambda: np.full((2, 3), 1 / 3)],
            "mesh": [lambda: (s.V, s.F)], "points": [lambda: (s.V, s.V)], "items": [lambda: (s.V, s.F)],
            "source": [lambda: p("mesh.off")], "inputs": [lambda: p("in_dir")], "out": [lambda: "out_dir"],
            "screenshot": [lambda: "shot.png"],
            "progress": [lambda: (lambda *a, **k: None)], "vertex_data": [lambda: {"d": s.V[:, 2].copy()}],
            "bbox": [lambda: ((-1.0, -1.0), (2.0, 2.0))], "style": [lambda: {}], "options": [lambda: {}],
            "executor": [lambda: "local"], "flat_index": [lambda: np.array([0, 5])],
            "dref": [lambda: np.full(len(s.Q), 0.5)], "curve_normals": [lambda: [np.array([0.0, 0.0, 1.0])]],
        }
        if target.split(".")[-1] == "compute_distance":   # surface points for solvers: vertex sources only
            t["points"] = [lambda: ()]
        if "path" not in t:
            if READER.search(target):
                t["path"] = [lambda f=f: p(f) for f in ("mesh.off", "cloud.xyz", "curves.txt", "field.npz",
                                                          "mesh.ply", "mesh.obj", "surface_field.npz",
                                                          "tet_field.npz", "pat.npz")]
            elif WRITER.search(target):
                t["path"] = [lambda e=e: f"out{e}" for e in (".ply", ".off", ".xyz", ".txt", ".npz", ".svg",
                                                               ".png", ".npy")]
        return t

    def candidates(self, name: str, target: str):
        """Built valid candidates for a parameter (``None``: no fixture for that name)."""
        c = self.table(target).get(name)
        return None if c is None else [b() for b in c]

    def has(self, name: str, target: str) -> bool:
        return name in self.table(target)

    def count(self, name: str, target: str) -> int:
        return len(self.table(target).get(name, ()))

    def get(self, name: str, target: str, i: int):
        return self.table(target)[name][i]()
