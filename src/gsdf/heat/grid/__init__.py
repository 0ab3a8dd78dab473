"""The signed heat method on regular grids (Feng & Crane 2024, §8.2): the domain (``_domain``), the screened grid
solve of step I (``_screened``) and the Poisson solves of step III (``_poisson``: DCT, penalty CG, augmented Lagrangian)."""
