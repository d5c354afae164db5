"""A fitted twin's predictions: C_f at other speeds, temperatures or cases with the 95 %
band of the fitted parameters (:func:`predict`), and the fit's figure (:func:`plot_fit`)."""

from __future__ import annotations

import numpy as np

from .fit import FitModel, boundary_values


def predict(model: FitModel, result: dict, speeds, temperature: float | None,
            nominal=None, *, curve: int | None = None) -> dict:
    """C_f at ``speeds`` [m/s] for the oil at ``temperature`` [C] with the fitted parameters
    of ``result`` (:func:`fit_curves`), and its 95 % band from their covariance.

    With fitted temperatures and the ``nominal`` oil temperatures of the measured curves
    [C], the contact runs at ``temperature`` plus their mean offset (fitted minus nominal,
    e.g. frictional heating), whose uncertainty joins the band; without, at
    ``temperature`` (None: at the viscosity of the simulated ``curve``).  The simulated
    curve of the nearest viscosity, or ``curve``, is rescaled (Hersey); without ``curve``
    the band adds the spread of all the simulated curves so rescaled (the Hersey collapse's
    own error, when there are two or more); it adds their C_f error estimates and
    sensitivity to the boundary film (``cf_err``, ``cf_film``; NaN without the first).
    The band is clipped to C_f in [0, 1] (``band_clipped`` marks where: the linearised
    band is wider than C_f).  A fitted load share and thermal resistance move C_f along
    ``model.share_curves`` and ``model.resistance_curves``."""
    names = result["fit"]["parameters"]
    x = np.array([result[n]["value"] for n in names])
    cov = np.asarray(result["fit"]["covariance"])
    temps = [i for i, n in enumerate(names) if n.startswith("temperature_")]

    def cf(x, k=curve):
        v = dict(zip(names, x))
        offset = (np.mean([x[i] - t for i, t in zip(temps, nominal)])
                  if temps and nominal is not None else 0.0)
        mu = (model.curves[k].viscosity if temperature is None
              else float(model.law.viscosity(temperature + offset)))
        if k is None:
            k = int(np.argmin([abs(np.log(c.viscosity / mu)) for c in model.curves]))
        return model.friction(k, speeds, mu, boundary_values(v), v.get("load_share"),
                              v.get("bulk_resistance"))

    value, inside = cf(x)
    twin = _error_at(model, speeds) + (_collapse_error(model, cf, x)
                                       if curve is None else 0.0)
    grad = np.stack([(cf(x + step)[0] - value) / step[i]
                     for i, step in enumerate(np.diag(np.maximum(1e-6 * np.abs(x), 1e-6)))],
                    axis=1)
    half = result["fit"]["t_factor"] * np.sqrt(np.einsum("ij,jk,ik->i", grad, cov, grad))
    half = half + np.nan_to_num(twin)        # the twin's own error (cf_err, cf_film), if known
    return {"speed_m_s": np.asarray(speeds, float), "cf": value,
            "cf_low": np.maximum(value - half, 0.0), "cf_high": np.minimum(value + half, 1.0),
            "cf_err": twin, "inside_simulated_range": inside,
            "band_clipped": (value - half < 0) | (value + half > 1)}


def _collapse_error(model: FitModel, cf, x) -> np.ndarray:
    """Largest spread of the simulated curves rescaled to the same viscosity (eq 46)."""
    if len(model.curves) < 2:
        return 0.0
    values = np.array([cf(x, k)[0] for k in range(len(model.curves))])
    return values.max(axis=0) - values.min(axis=0)


def _error_at(model: FitModel, speeds) -> np.ndarray:
    """The simulated curves' C_f error estimate at ``speeds``, with their sensitivity to the
    boundary film where they carry it (the largest over the curves; NaN without estimates:
    missing, not zero)."""
    curves = [c for c in model.curves if c.friction_error is not None]
    if not curves:
        return np.full(np.shape(speeds), np.nan)
    out = []
    for c in curves:
        order = np.argsort(c.speed)
        error = c.friction_error + (0.0 if c.film_sensitivity is None
                                    else np.nan_to_num(c.film_sensitivity))
        out.append(np.interp(np.log(speeds), np.log(c.speed[order]), error[order]))
    return np.max(out, axis=0)


def plot_fit(result: dict, path, labels=None):
    """Measured and fitted C_f against speed, one colour per curve."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for i, row in enumerate(result["residuals"]):
        label = labels[i] if labels else f"curve {row['curve']}"
        (line,) = ax.loglog(row["speed_m_s"], row["fitted_cf"], "-", label=f"fitted, {label}")
        ax.loglog(row["speed_m_s"], row["measured_cf"], "s", color=line.get_color(), ms=4,
                  label=f"measured, {label}")
    fitted = ", ".join(f"{k} = {v['value']:.4g} [{v['low']:.4g}, {v['high']:.4g}]"
                       for k, v in result.items() if k in result["fit"]["parameters"])
    return finish_fit_figure(fig, ax, path, fitted)


def finish_fit_figure(fig, ax, path, title: str):
    """A fit's C_f-against-speed figure with its ``title``, labels, grid and legend,
    saved to ``path``."""
    from ..io.figure import save_figure
    ax.set_title(title, fontsize="small")
    ax.set_xlabel("sliding speed $U$ [m/s]")
    ax.set_ylabel("$C_f$ [-]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="x-small")
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
