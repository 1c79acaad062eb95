"""The force terms a scene is made of (its *effects*), with their parameters and units.

A scene lists the effects it wants in :attr:`granrs.Scene.effects`; a term that is not
listed is neither evaluated nor stored (its parameters are then ignored). The default is
every effect. A vertical drop that lists only ``("gravity", "static_v")`` runs less code
than the full set: no drag, no horizontal term, no joint torques, and none of the sign
switches of the terms that are off are watched.

Each :class:`Effect` declares what it depends on (``velocity_dependent``: its magnitude
grows with speed; the static terms depend on the velocity only through a sign) and the
scene fields that parametrize it, with units and sources, in the manner of REBOUNDx's
effects registry.

Example:
    >>> import granrs
    >>> granrs.EFFECT_INFO["drag"].velocity_dependent
    True
    >>> [p.name for p in granrs.EFFECT_INFO["static_v"].parameters]
    ['coefficients.eta_v', 'coefficients.lam', 'rho_g', 'g']
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EFFECTS", "EFFECT_INFO", "Effect", "Parameter"]


@dataclass(frozen=True)
class Parameter:
    """One parameter of an effect: the scene field that holds it, its unit and source."""

    name: str
    unit: str
    description: str


@dataclass(frozen=True)
class Effect:
    """A named force term.

    Attributes:
        name: the name a scene lists in ``effects``.
        description: what the term is.
        equation: the term as written in granrs's frame (MODEL.md; thesis equation numbers).
        parameters: the scene fields it reads.
        velocity_dependent: whether its magnitude depends on the velocity (the static terms
            only take the velocity's sign, and are False here).
        state_dependent: what else it depends on.
        bodies: the bodies it acts on.
    """

    name: str
    description: str
    equation: str
    parameters: tuple[Parameter, ...]
    velocity_dependent: bool
    state_dependent: str
    bodies: tuple[str, ...] = ("free_link", "chain", "leg")


_RHO = Parameter("rho_g", "kg/m^3", "bulk density of the sand (thesis sec. 3.3.1: 1650)")
_G = Parameter("g", "m/s^2", "gravitational acceleration (9.81)")

#: Every effect a scene may list, by name.
EFFECT_INFO: dict[str, Effect] = {
    "gravity": Effect(
        name="gravity",
        description="uniform gravity on every link (and the chain's pin mass)",
        equation="F = -m g e_y on each link's centre of mass",
        parameters=(_G,),
        velocity_dependent=False,
        state_dependent="none",
    ),
    "drag": Effect(
        name="drag",
        description="dynamic drag of the sand, quadratic in the speed of the immersed centroid",
        equation="F_d = -eta_d rho_g A_r |v_E| v_E (thesis eqs. 2.1, 3.1)",
        parameters=(
            Parameter("coefficients.eta_d", "-", "dynamic scaling constant (Table 3.4)"),
            _RHO,
        ),
        velocity_dependent=True,
        state_dependent="immersed length, angle between the axis and v_E",
    ),
    "static_h": Effect(
        name="static_h",
        description="static horizontal resistance, growing with depth squared",
        equation="F_sh = -sgn(v_Ex) eta_h g rho_g w d^2 (thesis eqs. 2.2, 3.2)",
        parameters=(
            Parameter("coefficients.eta_h", "-", "horizontal static constant (Table 3.4)"),
            _RHO,
            _G,
        ),
        velocity_dependent=False,
        state_dependent="depth; the sign of v_Ex (Coulomb-like, sticks at v_Ex = 0)",
    ),
    "static_v": Effect(
        name="static_v",
        description="static vertical resistance, growing with depth and immersed volume",
        equation="F_sv = -sgn(v_Ey) eta_v (d / L_ref)^lambda g rho_g V (thesis eqs. 2.3, 3.3)",
        parameters=(
            Parameter("coefficients.eta_v", "-", "vertical static constant (Table 3.4)"),
            Parameter("coefficients.lam", "-", "depth exponent lambda (Table 3.4)"),
            _RHO,
            _G,
        ),
        velocity_dependent=False,
        state_dependent="depth, immersed volume; the sign of v_Ey (sticks at v_Ey = 0)",
    ),
    "joint_springs": Effect(
        name="joint_springs",
        description="torques of the joints given as spring-dampers; without this effect "
        "such joints are free (locked joints are constraints, not effects, and stay locked)",
        equation="tau = -k (phi - phi_0) - c dphi/dt on the relative angle phi",
        parameters=(
            Parameter("pin_joint / ankle / knee / hip .k", "N m/rad", "stiffness"),
            Parameter("pin_joint / ankle / knee / hip .c", "N m s/rad", "damping"),
        ),
        velocity_dependent=True,
        state_dependent="relative joint angle",
        bodies=("chain", "leg"),
    ),
}

#: Names of the effects, in order (the default of ``Scene.effects``: all of them).
EFFECTS: tuple[str, ...] = tuple(EFFECT_INFO)
