"""The fits behind the values a shipped medium card says were "fitted here".

The ``thesis_sand`` card of :mod:`granrs.media` has three laws fitted to the thesis's
Table 3.1 (the free link's measured depth and stopping time, 12 drops):

- ``rft.zeta``: ``granrs.calibrate`` under gravity and ``rft``;
- ``poncelet.c`` and ``poncelet.k``: ``granrs.calibrate`` under gravity and ``poncelet``;
- ``rft3d.zeta``: a capsule standing in for the rod (radius d_c / 2, the rod's length
  overall, its mass: thesis sec. 3.2.1, a steel rod with round ends) dropped in
  ``granrs.space`` under gravity and ``rft3d``, tilted by each row's q about y and falling
  straight down at its v0; zeta fitted in log space by least squares on depth and stopping
  time, each over its measured sd with the printed rounding in quadrature (as
  ``granrs.calibrate`` weighs them), its standard error from the Jacobian widened by
  sqrt(chi2 / dof) when above 1, the interval +-1.96 standard errors in log space.

This script makes the fits again and prints each value next to the card's (the card keeps
them rounded to the figures the standard error supports)::

    python benches/media_fits.py
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

import granrs
from granrs import forces as f
from granrs import space

#: The printed resolution of Table 3.1's depth [m] and stopping time [s].
RESOLUTION = 0.001


def rft3d_fit() -> tuple[float, float, tuple[float, float], float, int]:
    """``rft3d.zeta`` fitted to Table 3.1 with a capsule for the rod: value, standard
    error, ~95 % interval, chi2 and degrees of freedom."""
    table = granrs.data.load("table_3_1", as_="numpy")
    length, diameter, mass = 0.190, 0.0127, 0.184
    body = space.Body(space.Capsule(radius=diameter / 2, length=length - diameter), mass=mass)

    def sd(column: str) -> np.ndarray:
        return np.sqrt(np.asarray(table[column], dtype=float) ** 2 + RESOLUTION**2 / 12)

    def residuals(x: np.ndarray) -> np.ndarray:
        depth, t_s = [], []
        for q, v0 in zip(table["q_deg"], table["v0_mean"], strict=True):
            half = math.radians(float(q)) / 2
            scene = space.Scene(
                body=body,
                forces=[f.gravity(), f.rft3d(zeta=math.exp(float(x[0])))],
                orientation=(math.cos(half), 0.0, math.sin(half), 0.0),
                velocity=(0.0, 0.0, -float(v0)),
                t_end=0.5,
            )
            r = granrs.simulate(scene)
            depth.append(r.depth)
            t_s.append(r.t_s)
        return np.concatenate(
            [
                (np.array(depth) - table["depth_mean"]) / sd("depth_sd"),
                (np.array(t_s) - table["t_s_mean"]) / sd("t_s_sd"),
            ]
        )

    fit = least_squares(residuals, [math.log(1e6)], x_scale="jac", diff_step=1e-3)
    chi2 = float(fit.fun @ fit.fun)
    dof = len(fit.fun) - 1
    scale = math.sqrt(chi2 / dof) if chi2 > dof else 1.0
    se_x = math.sqrt(float(np.linalg.inv(fit.jac.T @ fit.jac)[0, 0])) * scale
    x = float(fit.x[0])
    interval = (math.exp(x - 1.96 * se_x), math.exp(x + 1.96 * se_x))
    return math.exp(x), math.exp(x) * se_x, interval, chi2, dof


def main() -> None:
    card = granrs.media.load("thesis_sand")
    fits = {
        ("rft.zeta",): granrs.calibrate(
            "free_link",
            "table_3_1",
            ["rft.zeta"],
            forces=[f.gravity(), f.rft(zeta=1e6)],
            bounds={"rft.zeta": (1e5, 1e8)},
        ),
        ("poncelet.c", "poncelet.k"): granrs.calibrate(
            "free_link",
            "table_3_1",
            ["poncelet.c", "poncelet.k"],
            forces=[f.gravity(), f.poncelet(c=0.8, k=150.0)],
            bounds={"poncelet.c": (1e-3, 1e3), "poncelet.k": (1e-1, 1e5)},
        ),
    }
    rows = []
    for names, fit in fits.items():
        for name in names:
            rows.append(
                (name, fit.values[name], fit.std_errors[name], fit.intervals[name], fit.chi2)
            )
    value, se, interval, chi2, _ = rft3d_fit()
    rows.append(("rft3d.zeta", value, se, interval, chi2))
    for name, value, se, (low, high), chi2 in rows:
        kept = card.value(name)
        print(
            f"{name:12s} fitted {value:11.5g} se {se:9.3g} 95% [{low:.4g}, {high:.4g}] "
            f"chi2 {chi2:6.1f} | card {kept.value:.5g} sd {kept.sd:.3g}"
        )


if __name__ == "__main__":
    main()
