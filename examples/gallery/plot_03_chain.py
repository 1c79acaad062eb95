"""
The two-link chain
==================

Two rods pinned at their top ends by a frictionless joint (thesis chapter 4) fall onto
the sand, case 1 of Table 4.1: each link at its measured angle, both at the mean of the
two measured speeds, each with its own Table 4.4 coefficients. The tips may meet the sand
at different times, and each stops on its own (``end="all_stops"``).
"""

import matplotlib.pyplot as plt
import numpy as np

import granrs

scene = granrs.cases.chain(case=1, end="all_stops", record=("state", "forces"))
result = granrs.simulate(scene)
s = result.series
print(f"q1 = {scene.q_deg:g} deg, q2 = {scene.q2_deg:g} deg, v0 = {scene.v0:.3f} m/s")
for i, c in enumerate(result.contacts, 1):
    print(f"link {i}: stopped after {c.t_s * 1e3:.1f} ms at {c.depth * 1e3:.1f} mm depth")
print(f"largest force at the pin: {result.joints['pin']['F_max']:.2f} N")

# %%
# Depth of each tip, and the chain drawn at eight moments from touchdown to the last stop
# (each link from the pin to its tip, in the plane; darker is later).

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9.0, 3.8))
for i in (0, 1):
    ax1.plot(s["t"] * 1e3, s[f"c{i}.depth"] * 1e3, label=f"link {i + 1}")
ax1.invert_yaxis()
ax1.set_xlabel("time [ms]")
ax1.set_ylabel("depth of the tip [mm]")
ax1.legend()

n = len(s["t"])
for k in np.linspace(0, n - 1, 8).astype(int):
    shade = 0.25 + 0.75 * k / (n - 1)
    for i in (0, 1):
        ax2.plot(
            [s["x_pin"][k], s[f"c{i}.tip_x"][k]],
            [s["y_pin"][k], s[f"c{i}.tip_y"][k]],
            color=(0.1, 0.2 + 0.5 * i, 0.6, shade),
            lw=2,
            label=f"link {i + 1}" if k == n - 1 else None,
        )
ax2.axhline(0.0, color="0.4", lw=1)
ax2.fill_between([-0.1, 0.1], -0.06, 0.0, color="tan", alpha=0.4)
ax2.legend(loc="upper right")
ax2.set_aspect("equal")
ax2.set_xlabel("x [m]")
ax2.set_ylabel("y [m]")
ax2.set_title("the chain from touchdown to the last stop")
fig.tight_layout()
plt.show()
