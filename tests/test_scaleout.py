"""Scale-out: a small Stribeck sweep on a Dask LocalCluster equals the serial one."""

from pathlib import Path

import numpy as np
import pytest

from fem_twin import Topography
from fem_twin.io.files import read_topography
from fem_twin.macro import Lubricant
from fem_twin.micro import homogenise
from fem_twin.stages.curves import run_sweeps
from fem_twin.topography import resample_cell
from fem_twin.topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "sample"


def small_sweep():
    opts = MacroOptions(resolution=(32, 32))
    pin = prepare_pin(read_topography(SAMPLE / "pin_2.npz"), opts)
    disk = prepare_disk(read_topography(SAMPLE / "disk_2.npz"), opts)
    low = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_2_pin.npz")), (16, 16))
    up = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_2_disk.npz"), upper=True),
                  (16, 16))
    ff = homogenise(low, up, np.geomspace(2e-8, 1e-6, 8), n_steps=4)
    return dict(gap=disk.heights - pin.heights, spacing=pin.spacing, factors=ff,
                speeds=np.geomspace(1.0, 0.02, 4), load=150.0,
                face=pin.heights > -0.5e-3)


def test_dask_local_cluster_gives_the_serial_numbers(tmp_path):
    distributed = pytest.importorskip("distributed")
    common = small_sweep()
    lubricants = [Lubricant(0.066), Lubricant(0.024)]
    tasks = [(common, lub) for lub in lubricants]
    serial = run_sweeps(tasks, None, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = run_sweeps(tasks, client.get_executor(), progress=False)
    for a, b in zip(serial, remote):
        assert a.viscosity == b.viscosity
        assert np.array_equal(a.friction_coefficient, b.friction_coefficient)
        assert np.array_equal(a.h_d, b.h_d)


def test_micro_tasks_follow_the_cluster_size():
    """Issue 17 item 5: with an executor served by W processes the h0 values go out as 4 W
    tasks (at most one per h0), so a large Dask cluster is not left idle."""
    from concurrent.futures import Executor, Future

    class Recorder(Executor):                 # runs each task here, remembers its size
        sizes = []

        def submit(self, fn, job, key=None):     # Dask's submit owns the keyword 'key'
            self.sizes.append(len(job[0]))
            f = Future()
            f.set_result(fn(job))
            return f

    rng = np.random.default_rng(3)
    low = Topography(rng.normal(0, 1e-7, (8, 8)), (1e-6, 1e-6))
    up = Topography(rng.normal(0, 1e-7, (8, 8)), (1e-6, 1e-6))
    h0 = np.geomspace(2e-7, 1e-6, 40)
    for workers, tasks in ((2, 8), (16, 40)):
        Recorder.sizes = []
        homogenise(low, up, h0, n_steps=2, executor=Recorder(), workers=workers,
                   error_estimate=False)
        assert len(Recorder.sizes) == tasks and sum(Recorder.sizes) == h0.size
