"""The signed heat method on intrinsic Delaunay triangulations (Feng & Crane 2024, §9.4): the domain (``_domain``)
and the flip, point-location and tracing kernels (``_kernels``)."""
