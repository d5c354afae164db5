"""The numerical kernels the scales share: sparse solvers and their orderings
(:mod:`~fem_twin.numerics.linalg`, :mod:`~fem_twin.numerics.ordering`), fixed-pattern FE
assembly on structured grids (:mod:`~fem_twin.numerics.assembly`), Anderson acceleration
(:mod:`~fem_twin.numerics.anderson`) and one BLAS/FFT thread per process
(:mod:`~fem_twin.numerics.threads`)."""
