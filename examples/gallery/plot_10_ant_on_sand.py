"""
Gymnasium's Ant on sand
=======================

:class:`granrs.mujoco.Sand` puts granular ground under named geoms of any MuJoCo model in
three dimensions. Here it is gymnasium's own Ant (its ``ant.xml``, as shipped: RK4 at
0.01 s, 0.91 kg, eight hinge motors of gear 150 with commands in [-1, 1]). Its four feet,
the ankle capsules, are the sand geoms, under 3D resistive force theory
(:func:`granrs.forces.rft3d`, Agarwal, Goldman & Kamrin 2023) with the material scale
``zeta = xi_n(1520 kg/m^3, 0.4)`` = 4.6e5 N/m^3 (:func:`granrs.space.xi_n`: a dry sand of
bulk density 1520 kg/m^3 and internal friction 0.4, from the paper's fit). The feet no
longer collide with MuJoCo's floor (their ``contype`` and ``conaffinity`` set to 0); the
rest of the robot keeps its contacts. The same robot also runs on MuJoCo's rigid floor,
its feet with their default contacts.

Each run: 2 s with the motors off (zero action), then 4 s of a fixed open-loop gait. The
plots show how deep each foot is (the depth of its lowest point below the surface z = 0:
on sand ``sand.output[:, 0]``, on the rigid floor the penetration of MuJoCo's soft
contact), each foot's vertical ground reaction (on sand ``sand.applied[:, 2]``, on the
floor the contact forces on the foot from ``mujoco.mj_contactForce``) against the
robot's weight, and how far the torso goes. ``pip install 'granrs[mujoco]' gymnasium``.
"""

import math
import os
import warnings

import gymnasium
import matplotlib.pyplot as plt
import mujoco
import numpy as np
from matplotlib.patches import Circle, Polygon

import granrs
from granrs import forces, space
from granrs.mujoco import Sand

ANT_XML = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/ant.xml")
FEET = ["left_ankle_geom", "right_ankle_geom", "third_ankle_geom", "fourth_ankle_geom"]
ZETA = space.xi_n(1520.0, 0.4)  # [N/m^3]
T_STAND = 2.0  # [s] zero action
T_WALK = 4.0  # [s] the gait, after standing
SNAPSHOTS = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)  # [s] the strip of poses

# %%
# The gait
# --------
#
# Each leg has a hip (about the vertical) and an ankle (lifting the foot). Every command is
# a sinusoid at 1.5 Hz, open loop (a function of time only): each hip's of amplitude 0.2
# (30 N m at gear 150) swinging its foot back and forth, each ankle's of amplitude 0.01
# (1.5 N m) pressing the foot down while the hip's torque swings it back. The diagonal
# pairs (the feet at (+x, +y) and (-x, -y); at (-x, +y) and (+x, -y)) move together, half
# a period apart; the amplitudes ramp up over the first 0.5 s. The ankles' amplitude is
# small because the motors are strong for the Ant's weight (8.9 N): larger commands throw
# it about. The signs below turn each hip's torque into "foot backwards" (-x) and each
# ankle's into "foot down", from the joints' axes in ``ant.xml``.

FREQ, HIP, ANKLE, RAMP = 1.5, 0.2, 0.01, 0.5
# joint suffix: (hip sign for foot backwards, ankle sign for foot down, phase [rad])
LEGS = {"1": (1.0, 1.0, 0.0), "2": (1.0, -1.0, math.pi), "3": (-1.0, -1.0, 0.0)}
LEGS["4"] = (-1.0, 1.0, math.pi)


def gait(model):
    """The open-loop command as a function of time: zero while standing, then the gait."""
    amp, phase = np.zeros(model.nu), np.zeros(model.nu)
    for a in range(model.nu):
        joint = model.joint(model.actuator_trnid[a, 0]).name  # "hip_1", "ankle_3", ...
        kind, leg = joint.split("_")
        back, down, phase[a] = LEGS[leg]
        amp[a] = HIP * back if kind == "hip" else ANKLE * down

    def command(t):
        s = t - T_STAND
        if s < 0.0:
            return np.zeros(model.nu)
        return min(1.0, s / RAMP) * amp * np.sin(2.0 * math.pi * FREQ * s + phase)

    return command


# %%
# The runs
# --------
#
# One run per ground: zero action for 2 s, then the gait for 4 s, both at the Ant's own
# 0.01 s step; on sand ``sand.step(data)`` before each ``mujoco.mj_step``. The sand is taken
# implicitly: each step solves, by Newton's method, for the feet's motion at the step's end
# under the sand's force at that motion. A step where Newton's method does not converge
# sticks or slides instead: the feet are brought to rest, a foot that would need more than
# the sand's resistance held at it and the others solved again. ``sand.fallbacks`` counts
# those steps, and the first one warns (:class:`granrs.StepSizeWarning`). The runs catch
# that warning and print the count and the times of those steps instead.


def run(on_sand):
    """Stand, then walk; record the feet, the torso and the poses at the snapshots."""
    model = mujoco.MjModel.from_xml_path(ANT_XML)
    feet = [model.geom(name).id for name in FEET]
    if on_sand:
        for g in feet:  # the feet no longer meet the floor: the sand carries them
            model.geom_contype[g] = model.geom_conaffinity[g] = 0
    data = mujoco.MjData(model)
    sand = Sand(model, FEET, [forces.rft3d(zeta=ZETA)], quadrature=3) if on_sand else None
    command = gait(model)
    rec = {"t": [], "x": [], "y": [], "z": [], "low": [], "depth": [], "fz": [], "poses": []}
    wrench = np.zeros(6)
    fallbacks = []  # the times of the sand's steps that stuck or slid
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", granrs.StepSizeWarning)  # counted: sand.fallbacks
        for _ in range(round((T_STAND + T_WALK) / model.opt.timestep)):
            data.ctrl[:] = command(data.time)
            if sand is not None:
                count = sand.fallbacks
                sand.step(data)
                if sand.fallbacks > count:
                    fallbacks.append(data.time)
            mujoco.mj_step(model, data)
            # The height of each foot's lowest point (the capsule's lower cap).
            low = np.array(
                [
                    data.geom_xpos[g, 2]
                    - abs(data.geom_xmat[g, 8]) * model.geom_size[g, 1]
                    - model.geom_size[g, 0]
                    for g in feet
                ]
            )
            if sand is not None:
                depth = sand.output[:, 0].copy()
                fz = sand.applied[:, 2].copy()
            else:
                depth = np.maximum(0.0, -low)
                fz = np.zeros(len(feet))
                for i in range(data.ncon):  # the floor's contact forces on each foot
                    con = data.contact[i]
                    mujoco.mj_contactForce(model, data, i, wrench)
                    f_world = con.frame.reshape(3, 3).T @ wrench[:3]  # on geom2, from geom1
                    for k, g in enumerate(feet):
                        fz[k] += f_world[2] * ((con.geom2 == g) - (con.geom1 == g))
            for key, value in zip(
                ("t", "x", "y", "z", "low", "depth", "fz"),
                (data.time, data.qpos[0], data.qpos[1], data.qpos[2], low, depth, fz),
                strict=True,
            ):
                rec[key].append(value)
            if any(abs(data.time - s) < 1e-9 for s in SNAPSHOTS):
                pose = (data.time, data.qpos.copy(), data.geom_xpos.copy(), data.geom_xmat.copy())
                rec["poses"].append(pose)
    out = {k: np.array(v) for k, v in rec.items() if k != "poses"}
    out["poses"], out["model"] = rec["poses"], model
    out["fallbacks"] = np.array(fallbacks)
    return out


runs = {"sand": run(True), "rigid floor": run(False)}
model = runs["sand"]["model"]
weight = model.body_subtreemass[1] * np.linalg.norm(model.opt.gravity)
stand = runs["sand"]["t"] <= T_STAND + 1e-9  # the same instants on both
walk = runs["sand"]["t"] >= T_STAND - 1e-9
print(f"zeta = xi_n(1520 kg/m^3, 0.4) = {ZETA:.4g} N/m^3; the Ant's weight {weight:.2f} N")
fallbacks = runs["sand"]["fallbacks"]
when = ", ".join(f"{t:.2f}" for t in fallbacks) or "none"
print(
    f"sand steps that stuck or slid (sand.fallbacks): {len(fallbacks)} of "
    f"{len(runs['sand']['t'])}, {(fallbacks < T_STAND).sum()} of them standing; "
    f"they start at t = {when} s"
)


def feet_plots(ax_d, ax_f, r, span, title):
    """Each foot's depth and vertical reaction over a time span, the weight for reference."""
    keep = (r["t"] >= span[0] - 1e-9) & (r["t"] <= span[1] + 1e-9)
    t = r["t"][keep]
    for k, name in enumerate(FEET):
        ax_d.plot(t, r["depth"][keep, k] * 1e3, lw=1.0, label=name)
        ax_f.plot(t, r["fz"][keep, k], lw=1.0, label=name)
    total = r["fz"][keep].sum(axis=1)
    ax_f.plot(t, total, color="k", lw=0.6, label="all four")
    n = round(1.0 / (FREQ * model.opt.timestep))  # the steps of one gait period
    if len(t) > 4 * n:  # walking: the mean over a period
        mean = np.convolve(total, np.ones(n) / n, mode="valid")
        ax_f.plot(t[n // 2 : n // 2 + len(mean)], mean, color="k", lw=2.0, label="all four, mean")
    ax_f.axhline(weight, color="k", ls="--", lw=0.8, label=f"weight {weight:.2f} N")
    ax_f.axhline(weight / 4, color="0.4", ls=":", lw=0.8, label="weight / 4")
    ax_d.set_title(title, fontsize=10)
    ax_d.invert_yaxis()
    ax_f.set_xlabel("time [s]")


# %%
# Standing
# --------
#
# With the motors off, the Ant drops from its initial height (the torso at 0.75 m) onto its
# feet. On sand the feet go in, deepest just after the landing, and settle where the sand
# carries the weight, a quarter of it on each foot (the four curves lie on one another: the
# Ant is symmetric). On the floor the landing bounces before the feet settle; they rest
# about 20 mm above z = 0, MuJoCo's contact acting within the geoms' margins (0.01 m each
# in ``ant.xml``), so their depth stays zero. The landings' peaks are cut off by the force
# axis (printed below). Nothing holds the ankles but their damping and their limits (30 to
# 70 degrees): the legs splay slowly under the weight and the torso sinks, faster on sand,
# where the feet slide outwards more easily than on the floor.

fig, axes = plt.subplots(2, 2, figsize=(9.0, 6.0), sharex=True, sharey="row")
for col, (label, r) in enumerate(runs.items()):
    feet_plots(axes[0, col], axes[1, col], r, (0.0, T_STAND), label)
axes[0, 0].set_ylabel("foot's depth below z = 0 [mm]")
axes[1, 0].set_ylabel("vertical ground reaction [N]")
axes[1, 0].set_ylim(-0.5, 3.0 * weight)
axes[1, 1].legend(fontsize=7, loc="upper right")
fig.suptitle("The Ant standing, zero action")
fig.tight_layout()
for label, r in runs.items():
    print(
        f"{label:11s} standing: landing peak {r['fz'][stand].sum(axis=1).max():5.1f} N; at "
        f"{T_STAND:.0f} s the feet carry {r['fz'][stand][-1].sum():5.2f} N, their lowest "
        f"points at z = {r['low'][stand][-1].mean() * 1e3:+6.2f} mm, the torso at z = "
        f"{r['z'][stand][-1]:.3f} m"
    )

# %%
# Walking
# -------
#
# The same gait on both grounds, from where standing left the Ant. Top: the torso's x, the
# distance made good. On sand each foot sinks and rises as its hip swings it through the
# stride, and the four reactions share the weight between the two diagonal pairs; the
# spikes in the sand's reactions are the steps that stuck or slid (their times are printed
# above). On the floor the feet's contacts come and go from one 0.01 s step to the next, so
# each foot's reaction is a train of spikes (cut off by the axis). Over a gait period (the
# thick line) both grounds carry the weight. The Ant's own 0.01 s step holds it standing on
# the sand, but it does not resolve the stride: the same gait on sand walks about 1.2 m at a
# 1 ms step against 1.4 m at 0.01 s; take the distance on sand at 0.01 s as the coarse
# step's, not the sand's.

fig = plt.figure(figsize=(9.0, 8.5))
grid = fig.add_gridspec(3, 2)
ax_x = fig.add_subplot(grid[0, :])
for label, r in runs.items():
    ax_x.plot(r["t"][walk], r["x"][walk] - r["x"][walk][0], label=label)
ax_x.set_ylabel("torso's x from where it started [m]")
ax_x.set_xlabel("time [s]")
ax_x.legend()
ax_d0 = fig.add_subplot(grid[1, 0])
ax_f0 = fig.add_subplot(grid[2, 0], sharex=ax_d0)
axes = [(ax_d0, ax_f0)]
axes.append((fig.add_subplot(grid[1, 1], sharey=ax_d0), fig.add_subplot(grid[2, 1], sharey=ax_f0)))
for (ax_d, ax_f), (label, r) in zip(axes, runs.items(), strict=True):
    feet_plots(ax_d, ax_f, r, (T_STAND, T_STAND + T_WALK), label)
ax_d0.set_ylabel("foot's depth below z = 0 [mm]")
ax_f0.set_ylabel("vertical ground reaction [N]")
ax_f0.set_ylim(-2.0, 4.0 * weight)
axes[1][1].legend(fontsize=7, loc="upper right")
fig.suptitle(f"The Ant walking: {FREQ} Hz, hips {HIP}, ankles {ANKLE}")
fig.tight_layout()

for label, r in runs.items():
    x, y, depth, fz = r["x"][walk], r["y"][walk], r["depth"][walk], r["fz"][walk]
    print(
        f"{label:11s} walking {T_WALK:.0f} s: {x[-1] - x[0]:4.2f} m in x ({y[-1] - y[0]:+5.2f} m "
        f"in y); each foot loaded {(fz > 1e-3).mean() * 100:3.0f} % of the time; depth "
        f"{depth.mean() * 1e3:5.2f} mm on average, {depth.max() * 1e3:5.2f} mm at most"
    )

# %%
# A strip of poses
# ----------------
#
# MuJoCo's own images where it can render offscreen (this needs an OpenGL context: on a
# machine without a display, ``MUJOCO_GL=egl`` or ``osmesa`` in the environment), from the
# model's camera that follows the Ant from the side, the floor drawn as translucent sand in
# the sand runs. Elsewhere, the recorded poses drawn from the side (x-z: the torso a disc,
# each capsule its outline, the feet in red), centred on the torso, the ground shaded.


def render_strip():
    """MuJoCo's images of each recorded pose, or None where offscreen rendering fails."""
    images = {}
    for label, r in runs.items():
        m = r["model"]
        if label == "sand":  # the floor in the colour of sand, translucent
            m.geom_matid[0] = -1
            m.geom_rgba[0] = (0.82, 0.71, 0.55, 0.6)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # GLFW warns where there is no display
                renderer = mujoco.Renderer(m, 240, 320)
        except Exception as exc:  # no OpenGL context here
            print(f"offscreen rendering unavailable ({type(exc).__name__}): drawing the poses")
            return None
        d = mujoco.MjData(m)
        images[label] = []
        with renderer:
            for _, qpos, _, _ in r["poses"]:
                d.qpos[:] = qpos
                mujoco.mj_forward(m, d)
                renderer.update_scene(d, camera="track")
                images[label].append(renderer.render().copy())
    return images


def stadium(a, b, radius, n=12):
    """The outline of a capsule seen from the side: the segment a-b swept by a disc."""
    angle = math.atan2(b[1] - a[1], b[0] - a[0])
    half = np.linspace(-math.pi / 2, math.pi / 2, n)
    around_b = [b + radius * np.array([math.cos(angle + s), math.sin(angle + s)]) for s in half]
    around_a = [a - radius * np.array([math.cos(angle + s), math.sin(angle + s)]) for s in half]
    return np.array(around_b + around_a)


def draw_pose(ax, m, xpos, xmat, ground):
    """A pose in x-z from the geoms' positions and orientations."""
    feet = {m.geom(name).id for name in FEET}
    for g in range(m.ngeom):
        p = xpos[g][[0, 2]]
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
            ax.add_patch(Circle(p, m.geom_size[g, 0], color="C0", alpha=0.6, lw=0))
        elif m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE:
            axis = xmat[g].reshape(3, 3)[[0, 2], 2] * m.geom_size[g, 1]
            outline = stadium(p - axis, p + axis, m.geom_size[g, 0])
            ax.add_patch(Polygon(outline, color="C3" if g in feet else "C0", alpha=0.5, lw=0))
    ax.axhspan(-0.3, 0.0, color="tan" if ground == "sand" else "0.6", alpha=0.6, zorder=0)


# sphinx_gallery_thumbnail_number = 3
images = render_strip()
fig, axes = plt.subplots(2, len(SNAPSHOTS), figsize=(12.0, 4.6))
for row, (label, r) in zip(axes, runs.items(), strict=True):
    torso = r["model"].geom("torso_geom").id
    for i, (ax, (time, _, xpos, xmat)) in enumerate(zip(row, r["poses"], strict=True)):
        if images is not None:
            ax.imshow(images[label][i])
            ax.set_axis_off()
        else:
            draw_pose(ax, r["model"], xpos, xmat, label)
            ax.set_xlim(xpos[torso, 0] - 0.9, xpos[torso, 0] + 0.9)
            ax.set_ylim(-0.3, 1.0)
            ax.set_aspect("equal")
            ax.set_yticks([])
            ax.set_xticks([round(xpos[torso, 0], 2)])
            ax.tick_params(labelsize=7)
        ax.set_title(f"{label}, {time:.0f} s", fontsize=8)
title = "zero action to 2 s, then the gait"
fig.suptitle(title if images is not None else title + " (x ticks: the torso's x [m])")
fig.tight_layout()
plt.show()
