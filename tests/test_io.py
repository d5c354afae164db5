"""Topography files: native round trips, instrument readers, and clear errors."""

import numpy as np
import pytest

import fem_twin
from fem_twin import Topography, read_topography, write_topography
from fem_twin.io import TopographyFileError

# file, (ny, nx), size (x1, x2) [m], Sq [m] -- from the shared README, units checked in the
# files themselves.  sur-2.sur stores heights in mm: its Sq is 17.5 nm (the README's
# "17.5 um" is a unit slip).
INSTRUMENT_FILES = [
    ("frt-1.frt", (500, 500), (12e-3, 12e-3), 4.9e-6),
    ("frt-2.frt", (300, 150), (30e-3, 60e-3), 8.8e-6),
    ("plu-1.plu", (576, 768), (1.27e-3, 0.96e-3), 2.8e-6),
    ("x3p-2.x3p", (650, 650), (0.083e-3, 0.204e-3), 77e-9),
    ("mnt-2.mnt", (960, 1280), (95.8e-6, 71.9e-6), 0.72e-6),
    ("sur-2.sur", (484, 563), (1.96e-3, 1.69e-3), 17.5e-9),
    ("al3d-1.al3d", (296, 200), (0.0876e-3, 0.1297e-3), 7.7e-6),
    ("opd-1.opd", (480, 640), (0.126e-3, 0.094e-3), 8.4e-9),
    ("metropro-1.dat", (480, 640), (0.70e-3, 0.53e-3), 75e-9),
]


@pytest.fixture
def topo():
    rng = np.random.default_rng(0)
    z = rng.normal(size=(12, 17)) * 1e-7
    z[3, 4] = np.nan
    return Topography(z, (1.1e-7, 1.3e-7), origin=(-2e-6, 5e-7), meta={"sample": "t"})


def test_npz_round_trip_is_exact(tmp_path, topo):
    write_topography(tmp_path / "a.npz", topo)
    back = fem_twin.read_topography(tmp_path / "a.npz")
    assert np.array_equal(back.heights, topo.heights, equal_nan=True)
    assert np.array_equal(back.valid, topo.valid)
    assert back.spacing == topo.spacing and back.origin == topo.origin
    assert back.meta == topo.meta


def test_quantised_npz_within_half_quantum(tmp_path, topo):
    write_topography(tmp_path / "q.npz", topo, height_scale=1e-10)
    back = read_topography(tmp_path / "q.npz")
    v = topo.valid
    assert np.max(np.abs(back.heights[v] - topo.heights[v])) <= 0.5e-10 * (1 + 1e-9)
    assert np.array_equal(back.valid, v)


@pytest.mark.parametrize("suffix", [".txt", ".csv", ".xyz"])
def test_ascii_round_trips_are_exact(tmp_path, topo, suffix):
    write_topography(tmp_path / f"a{suffix}", topo)
    back = read_topography(tmp_path / f"a{suffix}")
    assert np.array_equal(back.heights, topo.heights, equal_nan=True)
    assert np.allclose(back.spacing, topo.spacing, rtol=1e-12)
    assert np.allclose(back.origin, topo.origin, rtol=1e-12)


def test_every_written_format_reads_back(tmp_path, topo):
    """fem_twin.io.files.WRITERS: each suffix written has its reader in READERS."""
    from fem_twin.io.files import READERS, WRITERS
    assert set(WRITERS) <= set(READERS)
    for suffix in WRITERS:
        back = read_topography(write_topography(tmp_path / f"a{suffix}", topo),
                               spacing=topo.spacing)
        assert np.array_equal(back.heights, topo.heights, equal_nan=True), suffix


def test_a_new_format_is_one_writer_and_one_reader_line(tmp_path, topo, monkeypatch):
    """A toy format registered in WRITERS and READERS round-trips through
    write_topography and read_topography; an unregistered suffix is refused before any
    file is made, naming the suffixes that are written."""
    from fem_twin.errors import InputError
    from fem_twin.io import files

    def write_toy(path, t, height_scale=None):
        with open(path, "wb") as f:
            np.save(f, t.heights)

    def read_toy(path, spacing, scale):
        return Topography(np.load(path) * scale, spacing)

    monkeypatch.setitem(files.WRITERS, ".toy", write_toy)
    monkeypatch.setitem(files.READERS, ".toy", read_toy)
    back = read_topography(write_topography(tmp_path / "a.toy", topo), spacing=topo.spacing)
    assert np.array_equal(back.heights, topo.heights, equal_nan=True)
    with pytest.raises(InputError, match=r"cannot write '\.tiff'; use .*\.toy"):
        write_topography(tmp_path / "a.tiff", topo)
    assert not list(tmp_path.glob("*tiff*"))


def test_plain_matrix_and_npy_need_spacing_and_convert_units(tmp_path):
    z_um = np.arange(12.0).reshape(3, 4) * 0.1          # heights in um
    np.savetxt(tmp_path / "m.txt", z_um)
    np.save(tmp_path / "m.npy", z_um)
    for name in ("m.txt", "m.npy"):
        with pytest.raises(TopographyFileError, match="spacing"):
            read_topography(tmp_path / name)
        t = read_topography(tmp_path / name, spacing=2e-6, unit="um")
        assert np.allclose(t.heights, z_um * 1e-6) and t.spacing == (2e-6, 2e-6)
    with pytest.raises(ValueError, match="unknown unit"):
        read_topography(tmp_path / "m.txt", spacing=1e-6, unit="furlong")


def test_bad_files_raise_clear_errors(tmp_path):
    (tmp_path / "x.bin").write_bytes(b"\x00\x01garbage" * 50)
    (tmp_path / "nan.npy").write_bytes(b"")
    np.save(tmp_path / "nan.npy", np.full((4, 4), np.nan))
    np.save(tmp_path / "words.npy", np.array(["a", "b"]))
    (tmp_path / "short.npz").write_bytes(b"PK\x03\x04broken")
    (tmp_path / "ragged.xyz").write_text("0 0 1\n1 0 2\n0 1 3\n")
    for name, match in [("x.bin", "not a topography|SurfaceTopography|no usable length unit"),
                        ("nan.npy", "no valid pixel"), ("words.npy", "not numbers"),
                        ("short.npz", "cannot read"), ("ragged.xyz", "regular grid")]:
        with pytest.raises(TopographyFileError, match=match):
            read_topography(tmp_path / name, spacing=1e-6)
    with pytest.raises(FileNotFoundError):
        read_topography(tmp_path / "missing.npz")


@pytest.mark.parametrize("name", ["di_corrupted.di", "nonsense_txt_file.txt", "wrongnpyfile.npy"])
def test_shared_broken_files_raise(shared_topographies, name):
    with pytest.raises(TopographyFileError, match=name) as err:
        read_topography(shared_topographies / name, spacing=1e-6)
    # advice a tribologist can act on, not numpy's (issue 18 item 9)
    assert "allow_pickle" not in str(err.value)
    if name.endswith(".txt"):
        assert "not a table of heights" in str(err.value)


@pytest.mark.parametrize("name,shape,size,sq", INSTRUMENT_FILES)
def test_instrument_files_load_in_si_units(shared_topographies, name, shape, size, sq):
    pytest.importorskip("SurfaceTopography")
    t = read_topography(shared_topographies / name)
    assert t.shape == shape
    # sizes and Sq as printed (2-3 significant digits) in the shared README
    assert np.allclose(t.size, size, rtol=0.01)
    assert abs(t.rms_height() / sq - 1) < 0.02
    assert t.meta["reader"].endswith("Reader")


def test_files_are_written_on_worker_processes(tmp_path):
    """fem_twin.io.writers.Writers: a file writer (a figure) runs on the executor's processes (the
    arguments pickled, its interpolants left behind), the file is there after wait(), and
    a writer's error reaches the caller at wait()."""
    from concurrent.futures import ProcessPoolExecutor

    from fem_twin.io.writers import Writers
    from fem_twin.micro import FlowFactors
    from fem_twin.micro.output import plot_flow_factors
    factors = FlowFactors.smooth()
    factors.contact_pressure(np.array([1e-6]))               # a cache that does not pickle
    with ProcessPoolExecutor(1) as pool:
        writers = Writers(pool)
        writers.write(plot_flow_factors, [factors], tmp_path / "ff.png")
        writers.wait()
        assert (tmp_path / "ff.png").stat().st_size > 1000
        writers.write(plot_flow_factors, ["not factors"], tmp_path / "bad.png")
        with pytest.raises(AttributeError):
            writers.wait()
    assert not (tmp_path / "bad.png").exists() and writers.pending == []


def test_a_stribeck_csv_of_before_the_boundary_force_rename_reads(tmp_path):
    """``boundary_friction_N`` (the boundary part of F_T, named like the case file's C_f,b
    in earlier versions) reads as ``boundary_force``, the same numbers."""
    from fem_twin.stribeck.curve import StribeckCurve, read_stribeck_csv, write_stribeck_csv
    u = np.geomspace(1.0, 0.01, 4)
    curve = StribeckCurve(speed=u, hersey=u * 3.5e-6, friction_coefficient=0.01 / u ** 0.5,
                          viscosity=0.066, hydrodynamic_friction=u, boundary_force=1 - u,
                          contact_load_fraction=0 * u, h_d=1e-6 * u, iterations=1 + 0 * u)
    path = write_stribeck_csv(tmp_path / "stribeck.csv", [curve])
    path.write_text(path.read_text().replace("boundary_force_N", "boundary_friction_N"))
    old, = read_stribeck_csv(path)
    assert np.allclose(old.boundary_force, curve.boundary_force, rtol=1e-9, atol=0)


def test_debris_of_interrupted_atomic_writes_is_removed(tmp_path):
    """Kill -9 between atomic_path's temporary file and its rename leaves a hidden file
    (``.results.nc.k3j2h1g0.nc``) that no resume removed: ``remove_debris``, which the run
    calls once it holds its folder's lock, deletes every name atomic_path makes and
    nothing else."""
    from fem_twin.io.atomic import TEMPORARY, atomic_path, remove_debris
    names = []
    for target in (tmp_path / "results.nc", tmp_path / "fields" / "mu0.066_003.vtu",
                   tmp_path / "stribeck" / "checkpoints" / "point_ab12_1.000000000e+00.npz"):
        with atomic_path(target) as tmp:
            names.append(tmp.name)
            tmp.write_text("whole")
        (target.parent / tmp.name).write_text("half")    # what a killed writer leaves behind
    assert all(TEMPORARY.fullmatch(n) for n in names)
    keep = [tmp_path / ".lock", tmp_path / "run.log", tmp_path / ".hidden_notes"]
    for k in keep:
        k.write_text("x")
    assert remove_debris(tmp_path) == 3
    assert all(k.is_file() for k in keep) and not [p for p in tmp_path.rglob(".*")
                                                    if TEMPORARY.fullmatch(p.name)]
    assert (tmp_path / "results.nc").read_text() == "whole"


def test_a_netcdf_write_on_a_full_disk_is_one_oserror(tmp_path):
    """A NetCDF write that runs out of room (here a file-size limit, errno EFBIG) raises
    one OSError with its errno, which the CLI reports as exit 4, prints none of h5py's
    tracebacks, and leaves no temporary file."""
    import subprocess
    import sys
    script = tmp_path / "full.py"
    script.write_text(
        "import resource, signal, sys\n"
        "import numpy as np, xarray as xr\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (20000, 20000))\n"
        "from fem_twin.results import write_netcdf\n"
        "ds = xr.Dataset({'a': (('x',), np.random.default_rng(0).random(100000))})\n"
        "try:\n"
        "    write_netcdf(sys.argv[1], {None: ds})\n"
        "except OSError as err:\n"
        "    print('errno', err.errno)\n")
    out = tmp_path / "out"
    out.mkdir()
    proc = subprocess.run([sys.executable, str(script), str(out / "results.nc")],
                          capture_output=True, text=True, timeout=120)
    assert proc.stdout.strip() == "errno 27" and proc.stderr == ""
    assert list(out.iterdir()) == []
