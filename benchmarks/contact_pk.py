"""Group ``contact-pk``: fem_twin.contact against the shared plain-numpy Polonsky-Keer
(``../shared/baselines/pk_numpy.py``, one thread) on the periodic rough surface of the
``contact`` group: load control (100 MPa), gap control (the separation of that state), gap +
hardness (a cap of 0.6 x the elastic peak, so points are plastic) and load + hardness, at
256^2 and 1024^2.  Both at tol 1e-8 (each its own criterion); accuracy: L2 of the pressure
against a tol 1e-12 reference (fem_twin), bar 1e-6.  FFT pairs per iteration counted in both
(fem_twin: double + single precision).  Tamaas's load-controlled PK beside them when it is
installed (``pip install tamaas``).  Each timing is the best of ``REPS`` runs (this
machine's noise is 10-30 %).  Baseline: one rfft2+irfft2 pair.  Checked: pk_numpy's and
fem_twin's pressures within the bar.  Skipped where ``pk_numpy.py`` is absent."""

from __future__ import annotations

import os
import sys

import numpy as np
from common import Check, best_of

DEFAULT = True
HERE = os.path.dirname(os.path.abspath(__file__))
REPS = 3
#: the L2 accuracy bar of every solver's pressure against the tol 1e-12 reference
BAR = 1e-6


def run(sizes=(256, 1024)):
    shared = os.path.join(HERE, "..", "..", "shared", "baselines")
    if not os.path.isfile(os.path.join(shared, "pk_numpy.py")):
        return 1.0, [("pk_numpy.py absent (../shared/baselines): nothing to compare", 0.0,
                      "")], Check(None, "pk_numpy.py absent: nothing compared")
    sys.path.insert(0, shared)
    import pk_numpy

    from fem_twin import contact
    from fem_twin.contact import elastic
    from fem_twin.topography.synthetic import self_affine
    try:
        import tamaas
        tamaas.initialize(1)
        tamaas.set_log_level(tamaas.LogLevel.error)
    except ImportError:
        tamaas = None

    calls = {"n": 0, "single": 0}
    plain, single = elastic.ElasticOperator.__call__, elastic.ElasticOperator.single

    def counted(self, p):
        calls["n"] += 1
        return plain(self, p)

    def counted_single(self, p):
        calls["single"] += 1
        return single(self, p)

    elastic.ElasticOperator.__call__ = counted
    elastic.ElasticOperator.single = counted_single
    e_red = contact.reduced_modulus(210e9, 0.3, 210e9, 0.3)
    rows, base, worst = [], None, 0.0
    try:
        for n in sizes:
            dx = 85e-6 / n
            shape = -self_affine((n, n), dx, 0.8, 150e-9, rng=1).heights
            z = np.random.default_rng(0).random((n, n))
            t_fft, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)
            base = base or t_fft
            load = 100e6 * 85e-6 ** 2
            el = contact.solve(shape, dx, e_red, load=load, periodic=True, tol=1e-12)
            cap = 0.6 * el.pressure.max()
            cases = {"load": dict(load=load), "gap": dict(separation=el.separation),
                     "gap + hardness": dict(separation=el.separation, hardness=cap),
                     "load + hardness": dict(load=load, hardness=cap)}
            K = pk_numpy.Periodic((n, n), (85e-6, 85e-6), e_red / 2, workers=1)
            for name, kw in cases.items():
                ref = contact.solve(shape, dx, e_red, periodic=True, tol=1e-12, **kw).pressure
                pk_kw = dict(hardness=kw.get("hardness", np.inf), tol=1e-8)
                if "load" in kw:
                    pk_kw["pmean"] = 100e6
                else:
                    pk_kw["offset"] = kw["separation"]
                K.nfft = 0
                t_pk, out = best_of(lambda: pk_numpy.solve(K, -shape, **pk_kw), REPS)
                calls["n"] = calls["single"] = 0
                t_ft, res = best_of(lambda: contact.solve(shape, dx, e_red, periodic=True,
                                                          tol=1e-8, **kw), REPS)
                l2 = lambda p: np.linalg.norm(p - ref) / np.linalg.norm(ref)  # noqa: E731
                worst = max(worst, l2(out["p"]), l2(res.pressure))
                rows += [(f"{n}^2 {name}: pk_numpy", t_pk, f"{out['it']} it, "
                          f"{K.nfft / REPS / 2 / out['it']:.2f} FFT pairs/it, "
                          f"L2 {l2(out['p']):.1e}"),
                         (f"{n}^2 {name}: fem_twin", t_ft, f"{res.iterations} it, "
                          f"{calls['n'] / REPS / res.iterations:.2f} + "
                          f"{calls['single'] / REPS / res.iterations:.2f} single FFT pairs/it, "
                          f"L2 {l2(res.pressure):.1e}; pk_numpy / fem_twin = {t_pk / t_ft:.2f}")]
                if name == "load" and tamaas is not None:
                    rows.append(_tamaas_row(tamaas, shape, dx, e_red, ref, t_ft, f"{n}^2 {name}"))
    finally:
        elastic.ElasticOperator.__call__ = plain
        elastic.ElasticOperator.single = single
    return base, rows, Check(worst < BAR, f"pk_numpy's and fem_twin's pressures within L2 "
                                          f"{BAR:g} of the tol 1e-12 reference (worst "
                                          f"{worst:.1e})")


def _tamaas_row(tamaas, shape, dx, e_red, ref, t_ft, label):
    """Tamaas's Polonsky-Keer (Rey's variant, one thread) under the same mean pressure
    (100 MPa) at tol 1e-8; its E* = E'/2 against a rigid surface of heights -shape."""
    n = shape.shape[0]
    model = tamaas.ModelFactory.createModel(tamaas.model_type.basic_2d, [n * dx] * 2, [n, n])
    model.E, model.nu = e_red / 2, 0.0
    solver = tamaas.PolonskyKeerRey(model, np.ascontiguousarray(-shape), 1e-8)
    t, _ = best_of(lambda: solver.solve(100e6), 1)
    p = np.array(model.traction).reshape(n, n)
    return (f"{label}: Tamaas", t, f"L2 {np.linalg.norm(p - ref) / np.linalg.norm(ref):.1e}; "
            f"Tamaas / fem_twin = {t / t_ft:.2f}")
