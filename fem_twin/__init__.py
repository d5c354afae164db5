"""fem_twin: finite-element digital twin of a pin-on-disk tribometer in mixed lubrication.

Pipeline: ``topography -> contact -> micro (homogenisation) -> macro (reynolds) ->
stribeck``, with ``fvm`` as the reference twin of the FE solvers and ``io`` for files,
meshes and VTK.  All quantities are SI (m, Pa, Pa s, m/s).
"""

import os as _os

# One BLAS/OpenMP thread by default: on a loaded 2-core machine more threads made pyamg,
# CG and FFTs 5-50x slower.  Parallel speed comes from processes over independent work.
# Effective only if fem_twin is imported before numpy; users may override the variables.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

from .topography import Topography  # noqa: E402
from .io.files import read_topography, write_topography  # noqa: E402

try:
    from importlib.metadata import PackageNotFoundError, version as _version
    __version__ = _version("fem-twin")                  # one source: pyproject.toml
except PackageNotFoundError:                            # a source tree never installed
    __version__ = "0.0.0+unknown"
__all__ = ["Topography", "read_topography", "write_topography", "__version__"]
