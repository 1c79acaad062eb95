"""
The leg: locked and sprung joints
=================================

One leg of the thesis's average subject (75.35 kg, 1.78 m) landing flat on fine sand at
3.28 m/s (thesis chapter 5): foot, shank, thigh and half of head-arms-trunk, segment data
from Dempster as tabulated by Winter. With its ankle, knee and hip locked the leg is one
rigid body; with rotational spring-dampers (k = 300 N m/rad, c = 5 N m s/rad) the joints
give and the foot is loaded differently.
"""

import matplotlib.pyplot as plt

import granrs

runs = {
    "joints locked": granrs.cases.leg(v0=3.28, record=("state", "forces")),
    "spring-dampers": granrs.cases.leg(
        v0=3.28, joints={"k": 300.0, "c": 5.0}, record=("state", "forces")
    ),
}

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9.0, 3.8))
for label, scene in runs.items():
    result = granrs.simulate(scene)
    s = result.series
    print(
        f"{label:15s}: the foot stopped after {result.t_s * 1e3:5.1f} ms at "
        f"{result.depth * 1e3:5.1f} mm; largest knee torque "
        f"{result.joints['knee']['torque_max']:6.1f} N m"
    )
    ax1.plot(s["t"] * 1e3, s["depth"] * 1e3, label=label)
    ax2.plot(s["t"] * 1e3, s["F_sv"] + s["F_dy"], label=label)

ax1.invert_yaxis()
ax1.set_xlabel("time [ms]")
ax1.set_ylabel("depth of the sole [mm]")
ax1.legend()
ax2.set_xlabel("time [ms]")
ax2.set_ylabel("upward sand force on the foot [N]")
fig.tight_layout()
plt.show()

# %%
# The segments, scaled to the subject's mass and height:

for seg in runs["joints locked"].leg_segments():
    print(
        f"{seg['name']:10s} {seg['mass']:6.2f} kg, {seg['length']:.3f} m, "
        f"inertia {seg['inertia']:.4f} kg m^2"
    )
