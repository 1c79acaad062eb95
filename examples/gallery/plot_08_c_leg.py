"""
A C-shaped leg turned through sand: lift and thrust over a cycle
================================================================

A C-leg (a half circle of radius 3.5 cm, 1 cm wide) hangs from an axle 3 cm above the
sand and is turned about it at a constant angular speed, as in the C-leg experiments of Li,
Zhang & Goldman, *A terradynamics of legged locomotion on granular media*, Science 339
(2013) 1408. The leg is an :class:`~granrs.bodies.Contact` of shape ``"arc"`` (cut into
chords, each a thin plate for ``rft``); the axle is a pinned :class:`~granrs.bodies.Root`
whose ``rate`` drives the leg's angle, and the run reports the torque it takes. The
geometry is illustrative (the paper's legs were of this size; its exact dimensions are not
taken from it here), with the generic RFT coefficients and ``zeta = 1e6 N/m^3``.

Under pure ``rft`` the force law does not depend on the speed, so the lift (the sand's
vertical force on the leg) and the thrust (its horizontal force) over one turn are the same
function of the leg's angle at every speed: the three curves lie on one another
(``tests/test_arc.py`` holds them equal to round-off). Adding ``rft_inertial`` (the
momentum flux of dynamic RFT) makes the faster turns depart, by an amount that grows as the
square of the speed (tested too).
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import granrs
from granrs import forces
from granrs.bodies import Contact, Link, Linkage, Root

R = 0.035  # the C's radius [m]
AXLE = 0.03  # the axle's height above the sand [m]
STEPS = 1440  # steps per turn (the same leg angles at every speed)


def c_leg(omega: float, terms: list) -> granrs.Scene:
    """The C-leg turned at `omega` [rad/s] for one turn, from pointing straight up."""
    leg = Linkage(
        links=[Link("leg", mass=0.02, inertia=2e-5, length=2 * R, com=(R, -2 * R / math.pi))],
        contacts=[
            Contact.arc(
                "leg", radius=R, start_deg=180.0, end_deg=360.0, width=0.01, at=(R, 0.0), name="c"
            )
        ],
        root=Root("pinned", link="leg", position=(0.0, AXLE), rate=omega),
    )
    period = 2 * math.pi / omega
    return granrs.Scene(
        body=leg,
        forces=terms,
        end="time",
        t_end=period,
        dt=period / STEPS,
        record=("state", "forces"),
    )


speeds = (1.0, 5.0, 20.0)
fig, axes = plt.subplots(2, 2, figsize=(9.5, 6.0), sharex=True)
for row, (label, terms) in enumerate(
    [
        ("rft", [forces.gravity(), forces.rft(zeta=1e6)]),
        ("rft + rft_inertial", [forces.gravity(), forces.rft(zeta=1e6), forces.rft_inertial()]),
    ]
):
    for omega in speeds:
        r = granrs.simulate(c_leg(omega, terms))
        s = r.series
        angle = np.degrees(s["q_leg"])
        thrust = s["F_rft_x"] + s.get("F_ri_x", 0.0)
        lift = s["F_rft_y"] + s.get("F_ri_y", 0.0)
        axes[row, 0].plot(angle, lift, label=f"{omega:g} rad/s")
        axes[row, 1].plot(angle, thrust, label=f"{omega:g} rad/s")
        torque = np.abs(s["root.torque"]).max()
        print(
            f"{label:20s} omega = {omega:5.1f} rad/s: largest lift {lift.max():6.2f} N, "
            f"thrust {thrust.max():6.2f} N, axle torque {torque:.3f} N m"
        )
    axes[row, 0].set_ylabel(f"{label}\nlift [N]")
    axes[row, 1].set_ylabel("thrust [N]")
for ax in axes[1]:
    ax.set_xlabel("leg angle from the vertical [deg]")
axes[0, 0].legend(title="rotation speed")
fig.suptitle("C-leg through sand, one turn: rft alone is rate-independent")
fig.tight_layout()
plt.show()
