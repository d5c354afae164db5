"""Scale-out: a small Stribeck sweep on a Dask LocalCluster equals the serial one."""

import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from fem_twin import Topography
from fem_twin.io.files import read_topography
from fem_twin.macro import Lubricant
from fem_twin.micro import homogenise
from fem_twin.stages.sweeps import run_sweeps
from fem_twin.stribeck import SweepRequest
from fem_twin.topography import resample_cell
from fem_twin.topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin

sys.path.insert(0, str(Path(__file__).parent))
from sample_cases import macro_case, smooth_factors  # noqa: E402

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "sample"


@dataclass(frozen=True, eq=False)
class Scheduled:
    """What the scheduler reads of a SweepRequest: its grid, speeds and outputs."""

    gap: np.ndarray
    speeds: np.ndarray
    fields: str | None = None
    factors_key: str | None = None
    checkpoint: str | None = None
    guide: str | None = None


def small_sweep():
    opts = MacroOptions(resolution=(32, 32))
    pin = prepare_pin(read_topography(SAMPLE / "pin_2.npz"), opts)
    disk = prepare_disk(read_topography(SAMPLE / "disk_2.npz"), opts)
    low = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_2_pin.npz")), (16, 16))
    up = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_2_disk.npz"), upper=True),
                  (16, 16))
    ff = homogenise(low, up, np.geomspace(2e-8, 1e-6, 8), steps=4)
    return dict(gap=disk.heights - pin.heights, spacing=pin.spacing, factors=ff,
                speeds=np.geomspace(1.0, 0.02, 4), load=150.0,
                face=pin.heights > -0.5e-3)


@pytest.mark.integration
def test_dask_local_cluster_gives_the_serial_numbers(tmp_path):
    distributed = pytest.importorskip("distributed")
    common = small_sweep()
    lubricants = [Lubricant(0.066), Lubricant(0.024)]
    tasks = [SweepRequest(**common, lubricant=lub) for lub in lubricants]
    serial = run_sweeps(tasks, None, progress=False).curves
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = run_sweeps(tasks, client.get_executor(), progress=False).curves
    for a, b in zip(serial, remote):
        assert a.viscosity == b.viscosity
        assert np.array_equal(a.friction_coefficient, b.friction_coefficient)
        assert np.array_equal(a.h_d, b.h_d)


def test_a_local_cluster_computes_without_the_dask_profiler():
    """[run] scheduler = "local" serves tasks from a LocalCluster of
    [run] workers processes whose Dask settings keep background work out of the tasks'
    way (threads.DASK_CONFIG: a default worker's profiler and ticks made a task's wall time
    7-10 % longer than its CPU time on 2 cores)."""
    pytest.importorskip("distributed")
    from fem_twin.numerics.threads import DASK_CONFIG, DASK_ENVIRONMENT, executor_for

    def settings():
        import os

        import dask
        return {k: dask.config.get(k) for k in DASK_CONFIG}, os.getpid()

    with executor_for(2, "local") as executor:
        assert executor.n_workers == 2
        seen = [executor.submit(settings).result() for _ in range(4)]
    for config, pid in seen:
        assert config == DASK_CONFIG and pid != __import__("os").getpid()
    assert DASK_ENVIRONMENT["DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED"] == "False"


def test_micro_tasks_follow_the_cluster_size():
    """With an executor served by W processes the h0 values go out as 4 W
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
        homogenise(low, up, h0, steps=2, executor=Recorder(), workers=workers,
                   error_estimate=False)
        assert len(Recorder.sizes) == tasks and sum(Recorder.sizes) == h0.size


def test_the_schedule_of_a_task_graph():
    """fem_twin.runtime.taskgraph.makespan: one worker runs the sum of the tasks, unlimited workers
    the critical path; a diamond a -> (b, c) -> d of 1, 2, 3 and 1 s takes 7 s on one
    worker, 5 s on two (b and c side by side) and on more."""
    from fem_twin.runtime.taskgraph import Task, critical_path, makespan
    tasks = [Task("a", 1.0), Task("b", 2.0, ("a",)), Task("c", 3.0, ("a",)),
             Task("d", 1.0, ("b", "c"))]
    assert makespan(tasks, 1) == 7.0 and makespan(tasks, 2) == 5.0
    assert makespan(tasks, 8) == critical_path(tasks) == 5.0
    rng = np.random.default_rng(0)
    many = [Task(f"t{i}", float(s)) for i, s in enumerate(rng.uniform(1, 2, 40))]
    total = sum(t.seconds for t in many)
    assert makespan(many, 1) == pytest.approx(total)
    for w in (2, 4, 8):                           # greedy: within one task of the ideal
        assert total / w <= makespan(many, w) <= total / w + 2.0
    with pytest.raises(ValueError, match="cycle"):          # an InputError
        makespan([Task("x", 1.0, ("y",)), Task("y", 1.0, ("x",))], 2)


@pytest.mark.integration
def test_the_task_graph_of_a_finished_run(tmp_path):
    """The graph read back from a run's checkpoints holds every h0 the
    micro stage solved (round by round, the rounds replayed from the checkpoints; each h0
    its even and odd instants, issue 62), the coarse cells of the grid estimate, each
    sweep's guide and points, and the band's sweeps; on one worker it takes the
    CPU time the run measured for them, on the run's own 2 workers no longer than the
    run's wall time."""
    import json

    from sample_cases import small_case

    from fem_twin.case import load_case
    from fem_twin.cli import main
    from fem_twin.micro.sampling import START
    from fem_twin.runtime.taskgraph import critical_path, makespan, run_task_graph
    path = small_case(tmp_path, workers=2, band=True)
    path.write_text(path.read_text().replace("h0_count = 6", "h0_count = 24").replace(
        "steps = 4", "steps = 8"))                                # 2+ rounds of the sampler
    out = tmp_path / "out"
    assert main(["run", str(path), "-o", str(out), "--no-progress"]) == 0
    tasks = run_task_graph(load_case(path), out)
    summary = json.loads((out / "summary.json").read_text())
    solved = summary["stages"]["micro"]["h0_solved"]
    for k, n in enumerate(solved, start=1):             # each h0 its even and odd instants
        rounds = [t.name for t in tasks if t.name.startswith(f"patch {k} round")]
        assert len(rounds) == 2 * n and sum(r.endswith(" even instants") for r in rounds) == n
        assert sum(t.name.startswith(f"patch {k} coarse") for t in tasks) == n
        first = 2 * START - 1                      # the start, bisected once
        assert sum(t.name.startswith(f"patch {k} round 1 ") for t in tasks) == 2 * first < 2 * n
    sweeps = [t for t in tasks if "sweep" in t.name]
    assert len(sweeps) == 2 + 3 * 2               # average, two patches and the coarse average
    assert all(t.seconds > 0 for t in tasks if not t.name.startswith("refinement"))
    cpu = sum(t.seconds for t in tasks)
    assert makespan(tasks, 1) == pytest.approx(cpu)
    assert critical_path(tasks) <= makespan(tasks, 2) <= summary["wall_time_s"]
    graph = summary["task_graph"]                 # the run's summary holds the same numbers
    assert graph["tasks"] == len(tasks) and graph["cpu_s"] == pytest.approx(cpu, abs=0.1)
    assert graph["wall_s"]["2"] == pytest.approx(makespan(tasks, 2), abs=0.1)
    # checkpoints of an earlier fem_twin, without the confined films' moments: read as they
    # are, not set aside as damaged (an upgraded run's graph moved every one to .corrupt)
    for cp in out.glob("micro/*/checkpoints/**/*_h0_*.json"):
        data = json.loads(cp.read_text())
        data["moments"] = {k: v for k, v in data["moments"].items() if "thin" not in k}
        cp.write_text(json.dumps(data))
    assert len(run_task_graph(load_case(path), out)) == len(tasks)
    assert not list(out.rglob("*.corrupt"))


@pytest.mark.integration
def test_the_band_runs_beside_the_main_points(tmp_path):
    """On a grid with a coarser level (96^2: guides at 48^2) the band's
    grid is the guides', so its sweeps start after the guides' first passes, beside the
    main points, and each refined speed after the band's first pass and the guides' point
    there; the band then leaves the critical path (the same checkpoints scheduled with the
    band after the main points give a longer one), and a rerun of the finished run finds
    every band point checkpointed."""
    from sample_cases import small_case

    from fem_twin.case import load_case
    from fem_twin.cli import main
    from fem_twin.runtime.taskgraph import critical_path, run_task_graph, sweep_tasks
    from fem_twin.stribeck.sweep import point_files
    path = small_case(tmp_path, workers=2, band=True)
    path.write_text(path.read_text().replace("resolution = [48, 48] #", "resolution = [96, 96] #")
                    .replace("refine = 0 ", "refine = 1 "))
    case, out = load_case(path), tmp_path / "out"
    assert case.band_after_guides(case.macro_shape)
    assert main(["run", str(path), "-o", str(out), "--no-progress"]) == 0
    tasks = run_task_graph(case, out)
    chains = {}                                               # the guides' points
    for t in tasks:
        if t.name.startswith("sweep "):
            chains.setdefault(t.name.split()[1], []).append(t)
    band = [t for t in tasks if t.name.startswith("band sweep")]
    assert len(chains) == 2 and len(band) == 4                # 2 viscosities x 2 patches
    assert all(set(t.after) == {c[-1].name for c in chains.values()} for t in band)
    later = [t for t in tasks if t.name.startswith("band refinement")]
    assert later and all(t.after[0].startswith("band sweep") and len(t.after) > 1 and all(
        d.startswith("refinement") for d in t.after[1:]) for t in later)
    beside, after = (sweep_tasks(out / "stribeck" / "checkpoints", case.sweep.speeds, (),
                                 band_beside=b) for b in (True, False))
    assert critical_path(beside) < critical_path(after)
    first = len(list(point_files(out / "stribeck" / "checkpoints")))
    assert main(["run", str(path), "-o", str(out), "--no-progress"]) == 0
    assert len(list(point_files(out / "stribeck" / "checkpoints"))) == first


def test_the_largest_sweeps_are_submitted_first(monkeypatch):
    """stages.sweeps.run_sweeps submits the sweeps by nodes times speeds, largest first (the
    resolution study's 1997^2 sweep must not start last on a busy pool), and returns the
    curves in the order of its tasks."""
    from concurrent.futures import Future

    import fem_twin.stages.sweeps as curves
    monkeypatch.setattr(curves, "_sweep_task", lambda args: args[0].gap.shape[0])

    class Recording:
        order = []

        def submit(self, fn, args):
            self.order.append(args[0].gap.shape[0])
            done = Future()
            done.set_result(fn(args))
            return done

    pool = Recording()
    tasks = [Scheduled(np.zeros((n, n)), np.ones(k))
             for n, k in ((128, 17), (999, 5), (1997, 5), (256, 17))]
    assert curves.run_sweeps(tasks, pool, progress=False).curves == [128, 999, 1997, 256]
    assert pool.order == [1997, 999, 256, 128]


def test_a_sweep_longer_than_a_workers_share_runs_as_chains(monkeypatch):
    """stages.sweeps.run_sweeps cuts a sweep that costs more than an even share of a pool's
    workers into chains of consecutive speeds (the resolution study's 1997^2 sweep: four
    chains on two workers, started before the 500^2 sweep; the other grids whole), submits
    them largest first and joins each sweep's chains back into one curve in speed order; a
    sweep that writes fields stays whole."""
    from concurrent.futures import Future

    import fem_twin.stages.sweeps as curves
    from fem_twin.stribeck import StribeckCurve

    def sweep(args):
        speeds = args[0].speeds
        one = np.full(speeds.size, args[0].gap.shape[0], float)
        return StribeckCurve(speeds, speeds, speeds / 10, 0.066, one, one, one, one, one,
                             friction_error=speeds / 100,
                             friction_error_parts={"macro": speeds / 100},
                             coarse_friction_coefficient=np.vstack([speeds] * 2))
    monkeypatch.setattr(curves, "_sweep_task", sweep)

    class Pool:
        n_workers, order = 2, []

        def submit(self, fn, args):
            self.order.append((args[0].gap.shape[0], args[0].speeds.size))
            done = Future()
            done.set_result(fn(args))
            return done

    speeds = {128: 17, 256: 17, 500: 17, 999: 5, 1997: 5}
    tasks = [Scheduled(np.zeros((n, n)), np.geomspace(2, 0.005, k)) for n, k in speeds.items()]
    pool = Pool()
    out = curves.run_sweeps(tasks, pool, progress=False).curves
    assert pool.order == [(1997, 2), (1997, 1), (1997, 1), (1997, 1), (999, 5), (500, 17),
                          (256, 17), (128, 17)]
    for task, c in zip(tasks, out):
        assert np.array_equal(c.speed, task.speeds)
        assert np.array_equal(c.friction_coefficient, task.speeds / 10)
        assert np.array_equal(c.friction_error_parts["macro"], task.speeds / 100)
        assert c.coarse_friction_coefficient.shape == (2, task.speeds.size)
    fields = [replace(task, fields="somewhere") for task in tasks]
    assert len(curves.chains(fields, 2)) == len(tasks)
    assert len(curves.chains(tasks, 1)) == len(tasks)
    assert len(curves.chains(tasks, 2, whole=True)) == len(tasks)      # a refinement's last


@pytest.mark.integration
@pytest.mark.parametrize("scheduler", ["local", None])
def test_ctrl_c_during_the_cells_ends_at_once_in_one_line(tmp_path, scheduler):
    """Ctrl-C reaches the whole process group: a LocalCluster's workers died of it, printed
    their tracebacks and hung the cluster's close (the run lived on for minutes).  They
    now ignore it; the run stops, closes them and exits 130 with one line.  The signal is
    sent once the cells compute (the first h0 checkpoint), on the LocalCluster and on the
    process pool, with minutes of cell work still queued (64 px, 16 h0 x 16 steps): the
    patches' threads waited for all of it before the pool was closed (probe: 30 s and
    more after Ctrl-C at 20-35 s on the bundled case); now within 20 s."""
    import os
    import signal
    import subprocess
    import sys
    import time

    from sample_cases import small_case
    if scheduler:
        pytest.importorskip("distributed")
    case = small_case(tmp_path)
    text = case.read_text().replace("resolution = [16, 16] #", "resolution = [64, 64] #")
    text = text.replace("h0_count = 6", "h0_count = 16").replace("steps = 4", "steps = 16")
    case.write_text(text.replace("workers = 1", "workers = 2" + (
        f'\nscheduler = "{scheduler}"' if scheduler else "")))
    out = tmp_path / "out"
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", FEM_TWIN_SLOWDOWN="1")
    # Ctrl-C from a terminal starts at its default: a SIGINT the test process ignores (a
    # shell's background job) would be inherited, and the run would never see it
    proc = subprocess.Popen([sys.executable, "-m", "fem_twin.cli", "run", str(case), "-o",
                             str(out), "--no-progress"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 300
    while not list(out.glob("micro/*/checkpoints/*.json")) and proc.poll() is None:
        assert time.monotonic() < deadline, "the micro stage never started"
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("the run hung after Ctrl-C")
    lines = err.splitlines()           # the banner and the interrupted line, nothing else
    assert proc.returncode == 130 and "interrupted" in lines[-1], err
    assert "Traceback" not in err and len(lines) <= 2, err


def _running(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, exited but not reaped, does not)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_local_worker_exits_when_its_parent_is_killed():
    """Probe R.02: after kill -9 of a run, its idle pool workers lived on (two processes of
    122 and 139 MiB resident at a later check); quiet_worker's watch ends them within
    seconds."""
    import signal
    import subprocess
    import time
    code = ("import os, time\n"
            "from fem_twin.numerics.threads import process_pool\n"
            "pool = process_pool(1)\n"
            "print(pool.submit(os.getpid).result(), flush=True)\n"
            "time.sleep(60)\n")
    parent = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    worker = int(parent.stdout.readline())
    parent.send_signal(signal.SIGKILL)
    parent.wait()
    deadline = time.monotonic() + 20             # ORPHAN_POLL is 1 s: 20x, for a loaded CI
    while _running(worker) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not _running(worker)


CTRL_C_BESIDE = """
import importlib, sys, time
import numpy as np
import scipy.fft
from fem_twin.numerics.threads import side_threads
main = importlib.import_module("fem_twin.cli.main")

def run(args):
    x = np.random.default_rng(0).random(1 << 21)
    def spin():
        while True:
            scipy.fft.rfft(x)              # C++ (pybind11) code that releases the GIL
    with side_threads() as threads:
        threads.submit(spin)
        time.sleep(0.5)
        raise KeyboardInterrupt
main.runs.run = run
sys.exit(main.main(["run", "case.toml", "-o", sys.argv[1]]))
"""


def test_ctrl_c_while_a_side_thread_is_in_native_code_exits_130(tmp_path):
    """Probe S-CC-pool-20s: Ctrl-C while the levelling beside the cells ran in native code
    ended in SIGABRT ("terminate called without an active exception": the interpreter
    finalised around a thread inside pybind11 code; 2 of 5 tries, 4 of 4 with this
    stand-in, an FFT loop).  The command line leaves at once then, exit 130, one line."""
    import subprocess
    import sys
    done = subprocess.run([sys.executable, "-c", CTRL_C_BESIDE, str(tmp_path / "o")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 130, done.stderr
    assert done.stderr.strip().splitlines() == [
        "fem-twin run: interrupted; finished work is kept, run the same command again to "
        "resume"], done.stderr


def test_a_guided_sweeps_curve_is_read_from_the_index_not_the_checkpoints(tmp_path,
                                                                          monkeypatch):
    """stages.sweeps.run_sweeps on a pool reads a guided sweep's curve from its points'
    scalars and meta in the index (point_index), not from their checkpoints in full: over
    two passes, the second adding a midpoint as a refinement does, the main process loads
    no point whole, and the curve is the one stribeck_sweep reads from the checkpoints,
    bit for bit (sample pin 1 at 72^2, the smallest grid with a guide; smooth factors)."""
    import dataclasses
    import os

    from fem_twin.macro import MacroSettings, MixedResult
    from fem_twin.numerics.threads import executor_for
    from fem_twin.stages.sweeps import guide_of
    from fem_twin.stribeck import stribeck_sweep
    gap, dx, face = macro_case(72)
    request = SweepRequest(gap, dx, smooth_factors(), [1.0, 0.25], load=150.0,
                           lubricant=Lubricant(0.066), face=face,
                           settings=MacroSettings(tol=1e-6), checkpoint=tmp_path,
                           factors_key="smooth")
    assert guide_of(request) is not None
    main, loads, real = os.getpid(), [], MixedResult.load.__func__
    monkeypatch.setattr(MixedResult, "load", classmethod(
        lambda cls, path: (os.getpid() == main and loads.append(path), real(cls, path))[1]))
    refined = replace(request, speeds=[1.0, 0.5, 0.25])
    with executor_for(2) as pool:
        run_sweeps([request], pool, progress=False)
        (curve,), points = run_sweeps([refined], pool, progress=False, whole=True)
    assert loads == [] and [p.speed for p in points] == [1.0, 0.5, 0.25]
    read = stribeck_sweep(refined)
    assert len(loads) == 3                                   # stribeck_sweep reads them whole
    for field in dataclasses.fields(curve):
        mine, theirs = getattr(curve, field.name), getattr(read, field.name)
        assert (mine is None and theirs is None) or np.array_equal(
            mine, theirs, equal_nan=True), field.name
