"""
A sweep: depth over angle and speed
===================================

:func:`granrs.sweep` runs the Cartesian product of scene fields in the Rust core, on every
core, and returns one row per run. Here 9 angles times 6 speeds of the free link (54
impacts, each with the Table 3.4 coefficients of its angle) become a heat map of the
final depth.
"""

import matplotlib.pyplot as plt
import numpy as np

import granrs

# %%
# Coefficients depend on the angle (Table 3.4's nearest row), so the base scene takes
# them per run: sweep over a list of scenes built by :func:`granrs.cases.free_link`.

angles = np.linspace(0.0, 80.0, 9)
speeds = np.array([0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
scenes = [granrs.cases.free_link(q_deg=q, v0=v) for q in angles for v in speeds]
df = granrs.sweep(scenes)
print(df[["status", "t_s", "depth", "steps"]].describe().loc[["count", "mean", "min", "max"]])

# %%
# One row per run, in input order: reshape the depth into the (angle, speed) grid.

depth_mm = df["depth"].to_numpy().reshape(len(angles), len(speeds)) * 1e3
fig, ax = plt.subplots(figsize=(6.4, 4.2))
mesh = ax.pcolormesh(speeds, angles, depth_mm, shading="nearest", cmap="viridis")
for i, q in enumerate(angles):
    for j, v in enumerate(speeds):
        ax.text(v, q, f"{depth_mm[i, j]:.0f}", ha="center", va="center", color="w", fontsize=8)
fig.colorbar(mesh, ax=ax, label="final depth of the tip [mm]")
ax.set_xlabel("impact speed v0 [m/s]")
ax.set_ylabel("angle from the vertical q [deg]")
ax.set_title("Free link: final depth (Table 3.4 coefficients)")
fig.tight_layout()
plt.show()

# %%
# With a single base scene, the axes are keyword arguments and the DataFrame carries them
# as its first columns, e.g. ``granrs.sweep(base, q_deg=angles, v0=speeds)``; then every
# run keeps the base scene's coefficients. See :doc:`/sweeps` for Dask.
