"""The term constructors of :mod:`granrs.forces`, for type checkers and editors.

Generated from the core's registry by ``python -m granrs._stubgen``: do not edit. A
test regenerates it and compares.
"""

import math
from collections.abc import Mapping

from .forces import ParamValue, Term

__all__ = [
    "axial_drag",
    "drag",
    "gravity",
    "joint_springs",
    "poncelet",
    "rft",
    "rft3d",
    "rft3d_inertial",
    "rft_inertial",
    "static_h",
    "static_v",
]

def gravity() -> Term:
    """``gravity``: the weight of every link, at its centre of mass.

    Equation, in granrs's frame::

        F_i = -m_i g y_hat  (each link i)

    Acts on the body (through the mechanism). Reads each link's mass and centre of mass; g
    of the medium. Source: granrs's model, docs/model.md (frame, units and the impact).

    Generated from the core's registry (``granrs.forces.info('gravity')``); unknown or bad
    parameters raise a :class:`granrs.GranrsError` naming ``gravity.<parameter>``.

    Returns:
        The term, its parameters checked by the core.
    """

def drag(
    eta_d: ParamValue = 15.2,
) -> Term:
    """``drag``: dynamic drag, quadratic in the speed of the immersed centroid E.

    Equation, in granrs's frame::

        F_d = -eta_d rho_g A_r |v_E| v_E,  A_r |v_E| = d_c l |e x v_E| (rod)

    Acts on each contact in the sand (adds to the thesis's F_d). Reads rho_g; the contact's
    A_r |v_E| and v_E. Owns the switches: sign of e x v_E. Series columns with
    ``record=('forces',)``: ``F_dx``, ``F_dy``. Source: thesis eqs. 2.1, 3.1, 3.13-3.14
    (docs/model.md).

    Generated from the core's registry (``granrs.forces.info('drag')``); unknown or bad
    parameters raise a :class:`granrs.GranrsError` naming ``drag.<parameter>``.

    Args:
        eta_d: dynamic scaling constant [-]; default 15.2 (thesis Table 3.4, q = 0).

    Returns:
        The term, its parameters checked by the core.
    """

def static_h(
    eta_h: ParamValue = 6.5,
) -> Term:
    """``static_h``: static horizontal resistance, Coulomb-like in the sign of v_Ex.

    Equation, in granrs's frame::

        F_sh = -sgn(v_Ex) eta_h g rho_g w d^2  (along x)

    Acts on each contact in the sand (adds to the thesis's F_s). Reads g, rho_g; the
    contact's width w, depth d and the sign of v_Ex. Owns the switches: sign of v_Ex,
    sticking in x. Series columns with ``record=('forces',)``: ``F_sh``. Source: thesis eqs.
    2.2, 3.2 (docs/model.md).

    Generated from the core's registry (``granrs.forces.info('static_h')``); unknown or bad
    parameters raise a :class:`granrs.GranrsError` naming ``static_h.<parameter>``.

    Args:
        eta_h: horizontal static scaling constant [-]; default 6.5 (thesis Table 3.4,
            q = 0).

    Returns:
        The term, its parameters checked by the core.
    """

def static_v(
    eta_v: ParamValue = 248.0,
    lam: ParamValue = 0.106,
) -> Term:
    """``static_v``: static vertical resistance, Coulomb-like in the sign of v_Ey.

    Equation, in granrs's frame::

        F_sv = -sgn(v_Ey) eta_v (d / L_ref)^lam g rho_g V  (along y)

    Acts on each contact in the sand (adds to the thesis's F_s). Reads g, rho_g; the
    contact's depth d, L_ref, immersed volume V and the sign of v_Ey. Owns the switches:
    sign of v_Ey, sticking in y. Series columns with ``record=('forces',)``: ``F_sv``.
    Source: thesis eqs. 2.3-2.4, 3.3, 3.15 (docs/model.md).

    Generated from the core's registry (``granrs.forces.info('static_v')``); unknown or bad
    parameters raise a :class:`granrs.GranrsError` naming ``static_v.<parameter>``.

    Args:
        eta_v: vertical static scaling constant [-]; default 248.0 (thesis Table 3.4,
            q = 0).
        lam: depth exponent lambda [-]; default 0.106 (thesis Table 3.4, q = 0).

    Returns:
        The term, its parameters checked by the core.
    """

def joint_springs() -> Term:
    """``joint_springs``: the joints' rotational spring-dampers (k, c on each joint).

    Equation, in granrs's frame::

        tau = -k (theta - theta_rest) - c dtheta/dt  (each spring-damper joint)

    Acts on the body (through the mechanism). Reads each spring-damper joint's relative
    angle and rate. Source: granrs (docs/bodies/leg.md, docs/bodies/linkage.md).

    Generated from the core's registry (``granrs.forces.info('joint_springs')``); unknown or
    bad parameters raise a :class:`granrs.GranrsError` naming ``joint_springs.<parameter>``.

    Returns:
        The term, its parameters checked by the core.
    """

def poncelet(
    c: ParamValue,
    k: ParamValue,
) -> Term:
    """``poncelet``: Poncelet / Katsuragi-Durian impact law at the reference point.

    Equation, in granrs's frame::

        F = -c rho_g A |v| v - k d v/|v|  at E (v: E's velocity; d: the depth; A: immersed
            cross-section normal to v)

    Acts on each contact in the sand (adds to the thesis's F_s). Reads rho_g; the contact's
    depth d, v_E and E, its axis and immersed outline; the held signs of v_E (sticking).
    Owns the switches: sign of v_Ey, sticking in y. Series columns with
    ``record=('forces',)``: ``F_px``, ``F_py``. Source: Katsuragi & Durian, Nature Physics 3
    (2007) 420, eq. 1.

    Generated from the core's registry (``granrs.forces.info('poncelet')``); unknown or bad
    parameters raise a :class:`granrs.GranrsError` naming ``poncelet.<parameter>``.

    Args:
        c: inertial drag coefficient [-]; required (no default; none: fitted per body and
            medium (m / d1 = c rho_g A; granrs.media)).
        k: depth-friction coefficient [N/m]; required (no default; none: fitted per body and
            medium (granrs.media)).

    Returns:
        The term, its parameters checked by the core.
    """

def axial_drag(
    eta_a: ParamValue,
) -> Term:
    """``axial_drag``: quadratic drag along a rod's axis, on its end face, at the immersed
    centroid E.

    Equation, in granrs's frame::

        F = -eta_a rho_g (pi d_c^2 / 4) |v_a| v_a e  at E,  v_a = e . v_E (e: the rod's
            axis)

    Acts on each contact in the sand (adds to the thesis's F_d). Reads rho_g; the contact's
    axis e, diameter d_c, E and v_E; the held signs of v_E (sticking). Series columns with
    ``record=('forces',)``: ``F_ax``, ``F_ay``. Source: Katsuragi & Durian, Nature Physics 3
    (2007) 420, eq. 1 (the inertial term), along the rod's axis.

    Generated from the core's registry (``granrs.forces.info('axial_drag')``); unknown or
    bad parameters raise a :class:`granrs.GranrsError` naming ``axial_drag.<parameter>``.

    Args:
        eta_a: axial drag coefficient on the rod's end face [-]; required (no default; none:
            fitted per medium (c_a = eta_a rho_g pi d_c^2 / 4 [kg/m]; granrs.media)).

    Returns:
        The term, its parameters checked by the core.
    """

def rft(
    zeta: ParamValue,
    elements: int = 8,
    A00: ParamValue = 0.206,
    A10: ParamValue = 0.169,
    B11: ParamValue = 0.212,
    B01: ParamValue = 0.358,
    Bm11: ParamValue = 0.055,
    C11: ParamValue = -0.124,
    C01: ParamValue = 0.253,
    Cm11: ParamValue = 0.007,
    D10: ParamValue = 0.088,
    *,
    coefficients: Mapping[str, float] | None = None,
) -> Term:
    """``rft``: planar resistive force theory over the contact's boundary elements.

    Equation, in granrs's frame::

        dF = zeta |z| dA (-alpha_x(beta, gamma), alpha_z(beta, gamma)), summed over the
            immersed elements

    Acts on each contact in the sand (adds to the thesis's F_s). Reads the contact's
    boundary plates (frame and outline), each element's depth and velocity; the held signs
    of v_E (sticking). Owns the switches: sign of v_Ey, sticking in y. Series columns with
    ``record=('forces',)``: ``F_rft_x``, ``F_rft_y``. Source: Li, Zhang & Goldman, Science
    339 (2013) 1408, eq. 1 and Table S2.

    Generated from the core's registry (``granrs.forces.info('rft')``); unknown or bad
    parameters raise a :class:`granrs.GranrsError` naming ``rft.<parameter>``.

    Args:
        zeta: alpha_z of a horizontal plate pushed straight down, per unit depth [N/m^3];
            required (no default; none: a property of the medium (granrs.media's cards give
            values with sources; the docs tabulate them)).
        elements: elements per boundary plate [-], an integer from 1 to 1024; default 8
            (granrs (convergence study, docs/laws.md)).
        A00: Fourier coefficient A00 of alpha_z [-]; default 0.206 (Li, Zhang & Goldman
            2013, generic coefficients).
        A10: Fourier coefficient A10 of alpha_z [-]; default 0.169 (Li, Zhang & Goldman
            2013, generic coefficients).
        B11: Fourier coefficient B11 of alpha_z [-]; default 0.212 (Li, Zhang & Goldman
            2013, generic coefficients).
        B01: Fourier coefficient B01 of alpha_z [-]; default 0.358 (Li, Zhang & Goldman
            2013, generic coefficients).
        Bm11: Fourier coefficient B-11 of alpha_z [-]; default 0.055 (Li, Zhang & Goldman
            2013, generic coefficients).
        C11: Fourier coefficient C11 of alpha_x [-]; default -0.124 (Li, Zhang & Goldman
            2013, generic coefficients).
        C01: Fourier coefficient C01 of alpha_x [-]; default 0.253 (Li, Zhang & Goldman
            2013, generic coefficients).
        Cm11: Fourier coefficient C-11 of alpha_x [-]; default 0.007 (Li, Zhang & Goldman
            2013, generic coefficients).
        D10: Fourier coefficient D10 of alpha_x [-]; default 0.088 (Li, Zhang & Goldman
            2013, generic coefficients).
        coefficients: the coefficients A00, A10, B11, B01, Bm11, C11, C01, Cm11, D10 as one
            mapping by name (the paper's ``B-11``, ``C-11`` are also accepted); those left
            out keep their defaults.

    Returns:
        The term, its parameters checked by the core.
    """

def rft_inertial(
    lam: ParamValue = 1.0,
    elements: int = 8,
) -> Term:
    """``rft_inertial``: the inertial term of dynamic RFT: momentum flux on the leading
    elements.

    Equation, in granrs's frame::

        dF = -lam rho_g |v_n| v_n n dA,  v_n = v . n, summed over the immersed elements

    Acts on each contact in the sand (adds to the thesis's F_d). Reads rho_g; the contact's
    boundary plates (frame and outline), each element's velocity normal to it. Series
    columns with ``record=('forces',)``: ``F_ri_x``, ``F_ri_y``. Source: Agarwal, Karsai,
    Goldman & Kamrin, Science Advances 7 (2021) eabe0631 (dynamic RFT).

    Generated from the core's registry (``granrs.forces.info('rft_inertial')``); unknown or
    bad parameters raise a :class:`granrs.GranrsError` naming ``rft_inertial.<parameter>``.

    Args:
        lam: scale of the momentum flux rho_g v_n^2 [-]; default 1.0 (the momentum-flux
            value (sand brought to the element's normal speed)).
        elements: elements per boundary plate [-], an integer from 1 to 1024; default 8
            (granrs (convergence study, docs/laws.md)).

    Returns:
        The term, its parameters checked by the core.
    """

def rft3d(
    zeta: ParamValue,
    mu_surf: ParamValue = math.inf,
    grazing: int = 1,
) -> Term:
    """``rft3d``: three-dimensional resistive force theory on a body's surface elements.

    Equation, in granrs's frame::

        dF = zeta |z| dA (f1 m + f2 v^ - f3 z^) on leading elements (n . v >= 0); m: the
            element's normal facing down; f_i: cubic fits in (-v^_z, |n_z|, m . v^)

    Acts on each contact in the sand (adds to the thesis's F_s). Reads each surface
    element's normal, depth, area and velocity direction. Source: Agarwal, Goldman & Kamrin,
    PNAS 120 (2023) e2214017120, SI sec. S3.

    Generated from the core's registry (``granrs.forces.info('rft3d')``); unknown or bad
    parameters raise a :class:`granrs.GranrsError` naming ``rft3d.<parameter>``.

    Args:
        zeta: material scale of the generic stress [N/m^3]; required (no default; none: the
            medium's scale xi_n (granrs.space.xi_n from its density and internal friction, a
            granrs.media card, or fitted)).
        mu_surf: surface friction: cap on the stress's tangential part [-]; default inf (no
            cap unless given (the public codes take 0.15 to 0.4)).
        grazing: whether elements moving along their own surface count (1 or 0) [-], an
            integer from 0 to 1; default 1 (1 as the public codes of the paper (grazing
            elements count)).

    Returns:
        The term, its parameters checked by the core.
    """

def rft3d_inertial(
    lam: ParamValue = 1.0,
) -> Term:
    """``rft3d_inertial``: the inertial term of dynamic RFT on a body's surface elements in
    space.

    Equation, in granrs's frame::

        dF = -lam rho_g (n . v)^2 n dA on leading elements (n . v > 0)

    Acts on each contact in the sand (adds to the thesis's F_d). Reads rho_g; each surface
    element's normal, area and velocity. Source: Agarwal, Karsai, Goldman & Kamrin, Science
    Advances 7 (2021) eabe0631 (dynamic RFT).

    Generated from the core's registry (``granrs.forces.info('rft3d_inertial')``); unknown
    or bad parameters raise a :class:`granrs.GranrsError` naming
    ``rft3d_inertial.<parameter>``.

    Args:
        lam: scale of the momentum flux rho_g v_n^2 [-]; default 1.0 (the momentum-flux
            value (sand brought to the element's normal speed)).

    Returns:
        The term, its parameters checked by the core.
    """
