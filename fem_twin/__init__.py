"""fem_twin: finite-element digital twin of a pin-on-disk tribometer in mixed lubrication.

Pipeline: ``topography -> contact -> micro (homogenisation) -> macro (reynolds) ->
stribeck``, with ``fvm`` as the reference twin of the FE solvers and ``io`` for files,
meshes and VTK.  All quantities are SI (m, Pa, Pa s, m/s).

The layers, in the pipeline's order: a module imports only from its own layer or an
earlier one (``tests/test_architecture.py`` reads this table).  Shared plumbing (errors,
checks, tables, numerics ...) is layer 0; ``io.files`` reads and writes the Topography
value, so ``io`` sits with the topography stage; ``fvm`` gathers the FV siblings of micro
and macro.  The workflow (6.x): the case, the run's data files, the stages on a case and
the task graph, the pipeline that orders them, the studies that run it, and the report
of a finished run::

    1    topography, io
    2    contact
    3    micro
    4    macro, fvm
    5    stribeck
    6.0  case
    6.1  results
    6.2  stages, taskgraph
    6.3  pipeline
    6.4  compare, calibration, verification, fitting
    6.5  report, samples
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
