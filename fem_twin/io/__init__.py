"""Files, meshes and VTK: topography readers/writers, grid <-> mesh transfers, VTU/PVD."""

from .atomic import atomic_path
from .files import TopographyFileError, read_topography, write_topography
from .mesh import GridMesh, from_meshio, grid_mesh, read_vtu, to_meshio, write_pvd, write_vtu

__all__ = ["atomic_path", "TopographyFileError", "read_topography", "write_topography",
           "GridMesh", "grid_mesh", "to_meshio", "from_meshio", "write_vtu", "read_vtu",
           "write_pvd"]
