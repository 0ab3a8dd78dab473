"""Speed-path pieces of the grid signed heat method (issue 17): the numba triangular sweeps of the Step III
preconditioner against SciPy, and BLAS limited to one thread for the whole run (and restored after)."""

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve_triangular


def test_triangular_solve_matches_scipy():
    from gsdf.heat.grid._poisson import _triangular_solve, neumann_laplacian

    L = neumann_laplacian((9, 7, 6), np.array([0.1, 0.2, 0.15]))
    rng = np.random.default_rng(3)
    A = (L + sp.diags(rng.uniform(1, 50, L.shape[0]))).tocsr()
    band = np.sort(rng.choice(L.shape[0], 150, replace=False))
    Ab = A[band][:, band]
    b = rng.normal(size=len(band))
    for lower in (True, False):
        T = sp.tril(Ab, format="csr") if lower else sp.triu(Ab, format="csr")
        T.sort_indices()
        x = _triangular_solve(T.indptr, T.indices, T.data, b, lower)
        ref = spsolve_triangular(T, b, lower=lower)
        assert np.abs(x - ref).max() <= 1e-12 * np.abs(ref).max()
        assert np.abs(T @ x - b).max() <= 1e-10 * np.abs(b).max()


def test_blas_is_one_thread_during_the_run_and_restored_after():
    from threadpoolctl import threadpool_info

    from gsdf.heat.volume import VolumeHeatOptions, signed_heat_volume

    def blas():
        return [d["num_threads"] for d in threadpool_info() if d.get("user_api") == "blas"]

    before = blas()
    seen = []
    i = np.arange(300) + 0.5
    ph, th = np.arccos(1 - 2 * i / 300), np.pi * (1 + 5 ** 0.5) * i
    P = np.column_stack([np.cos(th) * np.sin(ph), np.sin(th) * np.sin(ph), np.cos(ph)])
    f = signed_heat_volume(points=(P, P), resolution=12,
                           options=VolumeHeatOptions(progress=lambda stage, frac: seen.extend(blas())))
    assert seen and all(n == 1 for n in seen)
    assert blas() == before
    # and the field is still a signed distance of the unit sphere
    d = f([[0.0, 0, 0], [1.3, 0, 0]])
    assert d[0] < -0.7 and abs(d[1] - 0.3) < 0.1


def test_direct_laplacian_equals_the_kronecker_assembly():
    from gsdf.heat.grid._poisson import _neumann_laplacian_kron, neumann_laplacian

    for shape, h in (((7, 5, 6), (0.1, 0.37, 1.3)), ((2, 2, 2), (1e-3, 7.0, 0.3)), ((3, 9, 2), (0.5, 0.5, 0.5))):
        A, B = neumann_laplacian(shape, np.array(h)), _neumann_laplacian_kron(shape, np.array(h))
        B.sort_indices()
        assert np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices)
        assert np.array_equal(A.data, B.data)  # bit for bit
        assert np.abs(A @ np.ones(A.shape[0])).max() <= 1e-9 * np.abs(A.data).max()  # constants in the kernel
