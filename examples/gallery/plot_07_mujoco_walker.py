"""
Sand under a MuJoCo walker
==========================

MuJoCo has no granular ground. :class:`granrs.mujoco.Sand` gives the named rod geoms of a
planar MuJoCo model granrs's force terms, evaluated by the same Rust code as
:func:`granrs.simulate` (each geom is the free link's rod), in one call per step for all
geoms.

A passive two-legged walker (:func:`granrs.mujoco.walker_mjcf`, printed below: a torso on
slide x, slide z and hinge y; two legs of thigh and shank with stiff, damped hips and knees;
no controller) is dropped at 2 m/s onto sand under ``rft`` (resistive force theory), then
under the thesis's law, and onto MuJoCo's rigid ground. The two shanks are the sand geoms
and meet the sand tip first, as the thesis's rod does. The plot shows how deep the feet go
and the ground's vertical reaction; the strip below draws the three landings from the
recorded poses (matplotlib: no offscreen rendering needed).
``pip install 'granrs[mujoco]'``.
"""

import matplotlib.pyplot as plt
import mujoco
import numpy as np

from granrs import forces
from granrs.mujoco import WALKER_SAND_GEOMS, Sand, walker_mjcf

print(walker_mjcf(floor=True))
T_END = 0.25  # short, so that the docs build (and CI) runs it in seconds
GEOMS = list(WALKER_SAND_GEOMS)

LAWS = {
    # Resistive force theory (Li, Zhang & Goldman 2013) with the generic coefficients and
    # zeta = 1e6 N/m^3, on 16 elements per plate of each shank's outline.
    "sand, rft": [forces.term("rft", zeta=1e6, elements=16)],
    # The thesis's law with its Table 3.4 defaults (the free link's steel rod in play sand).
    "sand, thesis's law": [forces.drag(), forces.static_h(), forces.static_v()],
    "rigid ground": None,
}


def land(terms):
    """Drop the hopper; record the foot's depth, the vertical ground force and the poses."""
    rigid = terms is None
    model = mujoco.MjModel.from_xml_string(walker_mjcf(floor=rigid))
    data = mujoco.MjData(model)
    data.qvel[1] = -2.0
    sand = None if rigid else Sand(model, GEOMS, terms)
    shanks = [model.geom(name).id for name in GEOMS]
    t, depth, force, poses = [], [], [], []
    wrench = np.zeros(6)
    for k in range(round(T_END / model.opt.timestep)):
        if sand is not None:
            sand.step(data)
        mujoco.mj_step(model, data)
        t.append(data.time)
        # The deeper shank's lowest point below the surface (z = 0).
        low = min(
            data.geom_xpos[g, 2]
            - abs(data.geom_xmat[g, 8]) * model.geom_size[g, 1]
            - model.geom_size[g, 0]
            for g in shanks
        )
        depth.append(max(0.0, -low))
        if rigid:
            fz = 0.0
            for i in range(data.ncon):
                mujoco.mj_contactForce(model, data, i, wrench)
                fz += wrench[0] * data.contact[i].frame[2]
            force.append(fz)
        else:
            force.append(sand.applied[:, 1].sum())
        if k % 250 == 0:
            poses.append((data.time, data.geom_xpos.copy(), data.geom_xmat.copy()))
    if sand is not None:
        print(f"largest timestep x drag rate: {sand.max_h_lambda:.3f}")
    return model, np.array(t), np.array(depth), np.array(force), poses


runs = {label: land(terms) for label, terms in LAWS.items()}

fig, (ax_d, ax_f) = plt.subplots(2, 1, figsize=(8.0, 6.0), sharex=True)
for label, (_, t, depth, force, _) in runs.items():
    ax_d.plot(t * 1e3, depth * 1e3, label=label)
    ax_f.plot(t * 1e3, force, label=label)
    print(
        f"{label:20s}: deepest {depth.max() * 1e3:6.1f} mm, largest vertical ground force "
        f"{force.max():7.1f} N"
    )
ax_d.set_ylabel("deepest foot below the surface [mm]")
ax_d.invert_yaxis()
ax_d.legend()
ax_f.set_ylabel("vertical ground force [N]")
ax_f.set_xlabel("time [ms]")
ax_f.set_yscale("symlog", linthresh=10.0)
ax_f.set_ylim(bottom=0.0)
fig.suptitle("A passive walker dropped at 2 m/s")
fig.tight_layout()

# %%
# The landings frame by frame, drawn from the recorded poses (capsules as thick lines).

fig, axes = plt.subplots(len(runs), 1, figsize=(9.0, 8.0), sharex=True)
for ax, (label, (model, _, _, _, poses)) in zip(axes, runs.items(), strict=True):
    for n, (time, xpos, xmat) in enumerate(poses):
        shift = 0.8 * n
        for g in range(model.ngeom):
            if model.geom_type[g] != mujoco.mjtGeom.mjGEOM_CAPSULE:
                continue
            axis = xmat[g].reshape(3, 3)[:, 2] * model.geom_size[g, 1]
            a, b = xpos[g] - axis, xpos[g] + axis
            color = "C3" if model.geom(g).name in GEOMS else "C0"
            ax.plot([a[0] + shift, b[0] + shift], [a[2], b[2]], color=color, lw=4, alpha=0.8)
        ax.text(shift, 1.25, f"{time * 1e3:.0f} ms", ha="center", fontsize=8)
    ax.axhspan(-0.3, 0.0, color="tan" if "sand" in label else "0.6", alpha=0.5)
    ax.set_ylim(-0.3, 1.35)
    ax.set_aspect("equal")
    ax.set_title(label, fontsize=9)
    ax.set_yticks([])
axes[-1].set_xlabel("x [m] (frames shifted by 0.8 m)")
fig.tight_layout()
plt.show()
