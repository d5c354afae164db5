"""fem_twin: finite-element digital twin of a pin-on-disk tribometer in mixed lubrication.

Pipeline ``topography -> contact -> micro -> macro -> stribeck`` (``fvm``: the FE solvers'
reference twin; ``io``: files, meshes, VTK), SI units throughout.  A module imports only
from its own layer or an earlier one (0: shared plumbing; tests/test_architecture.py
reads this table; docs: ARCHITECTURE.md).  The workflow's packages run in
that order: the case file, what a run costs, the results as data, the main job's stages
(``stages.pipeline``), the studies built on it::

    1    topography, io
    2    contact
    3    micro
    3.5  peers
    4    macro, fvm
    5    stribeck
    6.0  case
    6.1  runtime
    6.2  results
    6.3  stages
    6.4  studies
    7    cli
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
