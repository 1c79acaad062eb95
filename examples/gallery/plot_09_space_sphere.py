"""
Bodies in space: spheres dropped into sand, and a sphere dragged under it
=========================================================================

:mod:`granrs.space` runs a free rigid body in three dimensions under 3D resistive force
theory (:func:`granrs.forces.rft3d`, Agarwal, Goldman & Kamrin 2023). Left: a steel ball
(radius 20 mm) dropped straight down at four speeds; its depth against time, the stop
located inside the step. A speed-independent law stops each where the energy it brought
equals the work of the sand's force, so the faster drops go deeper but not in proportion.

Right: the same ball dragged sideways at a fixed depth (:func:`granrs.space.load`, the load
at one pose and motion): the sand pushes back (drag) and up (lift), as granular media do
on a sphere moving horizontally; both grow with depth. ``zeta`` here is an example value
of the order of the media of the RFT literature, not a calibrated sand.
"""

import matplotlib.pyplot as plt
import numpy as np

import granrs
from granrs import forces, space

zeta = 5e5  # [N/m^3], an example medium
ball = space.Body(space.Sphere(radius=0.02), density=7800.0)
law = [forces.rft3d(zeta=zeta), forces.gravity()]

fig, (left, right) = plt.subplots(1, 2, figsize=(9.5, 3.8))
for v0 in (0.5, 1.0, 2.0, 4.0):
    scene = space.Scene(body=ball, velocity=(0.0, 0.0, -v0), forces=law, record=True)
    r = granrs.simulate(scene)
    left.plot(r.series["t"] * 1e3, r.series["depth"] * 1e3, label=f"v0 = {v0:g} m/s")
    print(
        f"v0 = {v0:3.1f} m/s: stopped at t_s = {r.t_s * 1e3:6.2f} ms, depth = "
        f"{r.depth * 1e3:6.2f} mm, the sand took {r.dE:.4f} J ({r.summary['steps']:.0f} steps)"
    )
left.set_xlabel("time [ms]")
left.set_ylabel("depth of the lowest point [mm]")
left.invert_yaxis()
left.set_title("steel ball, 20 mm, dropped")
left.legend()

probe = space.Scene(body=ball, forces=[forces.rft3d(zeta=zeta)])
depths = np.linspace(0.02, 0.12, 11)  # of the centre [m]
drag, lift = [], []
for d in depths:
    load = space.load(probe, position=(0.0, 0.0, -d), velocity=(0.1, 0.0, 0.0))
    drag.append(-load.force[0])
    lift.append(load.force[2])
right.plot(depths * 1e3, drag, "o-", label="drag (against the motion)")
right.plot(depths * 1e3, lift, "s-", label="lift (up)")
right.set_xlabel("depth of the centre [mm]")
right.set_ylabel("force [N]")
right.set_title("the same ball dragged sideways")
right.legend()
fig.tight_layout()
plt.show()
