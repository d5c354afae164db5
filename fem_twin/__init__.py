"""fem_twin: finite-element digital twin of a pin-on-disk tribometer in mixed lubrication.

Pipeline: ``topography -> contact -> micro (homogenisation) -> macro (reynolds) ->
stribeck``, with ``fvm`` as the reference twin of the FE solvers and ``io`` for files,
meshes and VTK.  All quantities are SI (m, Pa, Pa s, m/s).
"""

from .io.files import read_topography, write_topography
from .topography import Topography

try:
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as _version
    __version__ = _version("fem-twin")                  # one source: pyproject.toml
except PackageNotFoundError:                            # a source tree never installed
    __version__ = "0.0.0+unknown"
__all__ = ["Topography", "read_topography", "write_topography", "__version__"]
