"""Structured FE meshes on grids, and grid -> meshio -> VTU -> grid transfers."""

import meshio
import numpy as np
import pytest
import skfem
from skfem.helpers import dot, grad

from fem_twin.io import from_meshio, grid_mesh, read_vtu, to_meshio, write_vtu
from fem_twin.io.mesh import write_pvd


def test_nodes_are_pixels_row_major():
    gm = grid_mesh((4, 6), (1e-6, 2e-6), origin=(-3e-6, 1e-6))
    x1 = -3e-6 + 1e-6 * np.arange(6)
    x2 = 1e-6 + 2e-6 * np.arange(4)
    X1, X2 = np.meshgrid(x1, x2)
    assert np.array_equal(gm.mesh.p[0], X1.ravel()) and np.array_equal(gm.mesh.p[1], X2.ravel())
    f = np.arange(24.0).reshape(4, 6)
    assert np.array_equal(gm.to_nodes(f), f.ravel())
    assert np.array_equal(gm.to_grid(gm.to_nodes(f)), f)


@pytest.mark.parametrize("kind,element", [("quad", skfem.ElementQuad1),
                                          ("tri", skfem.ElementTriP1)])
@pytest.mark.parametrize("periodic", [False, True])
def test_mesh_geometry_and_periodic_operator(kind, element, periodic):
    ny, nx, dx1, dx2 = 8, 10, 0.3, 0.2
    gm = grid_mesh((ny, nx), (dx1, dx2), periodic=periodic, kind=kind)
    basis = skfem.Basis(gm.mesh, element())
    mass = skfem.BilinearForm(lambda u, v, w: u * v).assemble(basis)
    lap = skfem.BilinearForm(lambda u, v, w: dot(grad(u), grad(v))).assemble(basis)
    area = (nx * dx1 * ny * dx2) if periodic else ((nx - 1) * dx1 * (ny - 1) * dx2)
    P = gm.periodic_map
    assert np.isclose((P.T @ mass @ P).sum(), area, rtol=1e-13)
    lap_p = (P.T @ lap @ P).toarray()
    assert np.allclose(lap_p, lap_p.T)
    eig = np.linalg.eigvalsh(lap_p)
    # one zero mode (constants), all others positive: a consistent Neumann/periodic operator
    assert abs(eig[0]) < 1e-12 and eig[1] > 1e-3
    if periodic:
        # u = cos(2 pi x1 / L1) is an eigenfunction of the periodic Laplacian; the FE
        # Rayleigh quotient approaches (2 pi / L1)^2 with O(h^2) error
        x1 = dx1 * np.arange(nx)
        u = np.tile(np.cos(2 * np.pi * x1 / (nx * dx1)), (ny, 1)).ravel()
        m_p = (P.T @ mass @ P).toarray()
        rq = u @ lap_p @ u / (u @ m_p @ u)
        assert abs(rq / (2 * np.pi / (nx * dx1)) ** 2 - 1) < 0.1


@pytest.mark.parametrize("kind", ["quad", "tri"])
@pytest.mark.parametrize("periodic", [False, True])
def test_grid_meshio_vtu_grid_round_trip_is_exact(tmp_path, kind, periodic):
    rng = np.random.default_rng(1)
    gm = grid_mesh((7, 9), (1.105e-7, 1.106e-7), origin=(-3.3e-7, 2.1e-7),
                   periodic=periodic, kind=kind)
    fields = {"gap": rng.random((7, 9)) * 1e-6, "flow": rng.random((7, 9, 2))}
    mesh = to_meshio(gm, fields)
    assert isinstance(mesh, meshio.Mesh) and len(mesh.points) == gm.mesh.nvertices
    gm1, back1 = from_meshio(mesh)
    write_vtu(tmp_path / "f.vtu", gm, fields)
    gm2, back2 = read_vtu(tmp_path / "f.vtu")
    for g, back in ((gm1, back1), (gm2, back2)):
        assert g.shape == gm.shape and g.spacing == gm.spacing and g.origin == gm.origin
        assert g.periodic == periodic
        for name, value in fields.items():
            assert np.array_equal(back[name], value)


def test_grid_inferred_from_foreign_meshio_in_any_order():
    gm = grid_mesh((5, 6), (1e-6, 1e-6), periodic=True)
    f = np.random.default_rng(2).random((5, 6))
    m = to_meshio(gm, {"h": f})
    perm = np.random.default_rng(3).permutation(len(m.points))
    foreign = meshio.Mesh(m.points[perm], [], point_data={"h": m.point_data["h"][perm]})
    g, back = from_meshio(foreign, periodic=True)
    assert g.shape == (5, 6) and np.array_equal(back["h"], f)
    foreign.point_data["h"] = np.random.default_rng(4).random(len(perm))
    with pytest.raises(ValueError, match="not periodic"):
        from_meshio(foreign, periodic=True)


def test_vtu_opens_in_vtk_like_paraview(tmp_path):
    vtk = pytest.importorskip("vtk")
    gm = grid_mesh((6, 8), (1e-6, 1e-6), periodic=True)
    f = np.random.default_rng(5).random((6, 8))
    write_vtu(tmp_path / "p.vtu", gm, {"gap": f}, elevation="gap")
    write_pvd(tmp_path / "series.pvd", [(0.0, tmp_path / "p.vtu")])
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(tmp_path / "p.vtu"))
    reader.Update()
    out = reader.GetOutput()
    assert out.GetNumberOfPoints() == 7 * 9 and out.GetNumberOfCells() == 6 * 8
    data = np.array([out.GetPointData().GetArray("gap").GetValue(i) for i in range(63)])
    assert np.array_equal(data, gm.to_nodes(f))
    text = (tmp_path / "series.pvd").read_text()
    assert 'file="p.vtu"' in text and 'type="Collection"' in text


def test_3d_views_render_in_a_child_process_or_say_why_not(tmp_path):
    """pyvista segfaults without an OpenGL backend: a failed render (here: a missing file in
    the child) costs a note, never the calling process."""
    from fem_twin.io.render import render_views
    made, note = render_views([(tmp_path / "missing.vtu", tmp_path / "x.png", "t")])
    assert made == [] and "no 3D view" in note and "libegl1" in note
