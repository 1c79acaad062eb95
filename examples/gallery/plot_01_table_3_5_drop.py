"""
The Table 3.5 drop: depth against time
======================================

The thesis's steel rod (L = 0.190 m, d_c = 0.0127 m, 0.184 kg) dropped tip first into
play sand at three angles, each at the fastest speed of its Table 3.5 group, with the
Table 3.4 coefficients of its angle and the force applied at the tip, as in the thesis's
CAD runs. The dots are the thesis's own simulated stop (Table 3.5).
"""

import matplotlib.pyplot as plt

import granrs

table = granrs.data.load("table_3_5")

# %%
# Run one scene per angle, recording the state and the forces (``depth`` is a force-record
# series: the tip's depth below the surface at each step).

fig, ax = plt.subplots(figsize=(6.4, 4.0))
for q_deg, colour in [(0.0, "C0"), (45.0, "C1"), (75.0, "C2")]:
    row = table[table["q_deg"] == q_deg].iloc[0]
    scene = granrs.cases.free_link(q_deg=q_deg, v0=row["v0"], record=("state", "forces"))
    result = granrs.simulate(scene)
    s = result.series
    ax.plot(s["t"] * 1e3, s["depth"] * 1e3, color=colour, label=f"q = {q_deg:g} deg")
    ax.plot(row["t_s"] * 1e3, row["depth"] * 1e3, "o", color=colour, mfc="none")
    print(
        f"q = {q_deg:4.1f} deg, v0 = {row['v0']:.3f} m/s: granrs stops at "
        f"{result.t_s * 1e3:5.1f} ms, {result.depth * 1e3:5.1f} mm deep; "
        f"Table 3.5: {row['t_s'] * 1e3:4.0f} ms, {row['depth'] * 1e3:5.1f} mm "
        f"({scene.coefficients_source})"
    )

ax.invert_yaxis()
ax.set_xlabel("time since the tip met the sand [ms]")
ax.set_ylabel("depth of the tip [mm]")
ax.set_title("Free link, Table 3.4 coefficients (dots: thesis Table 3.5)")
ax.legend()
fig.tight_layout()
plt.show()

# %%
# The depth comes to rest where the static vertical term, which grows as
# :math:`d^\lambda`, balances the weight; the stop is the moment the tip's vertical
# velocity reaches zero, located inside the step (see :doc:`/events`).
