//! The thesis's granular resistance force on a slender body: dynamic drag plus static
//! depth-dependent horizontal and vertical terms.
//!
//! Source: "Bipedal impact with granular matter" (the thesis in `shared/thesis/`),
//! eqs. 2.1-2.4 and 3.1-3.3, with the contact geometry of eqs. 3.13-3.15, read in the
//! single frame of `shared/MODEL.md` (x right, y up, sand surface at y = 0):
//!
//! ```text
//! F_d  = - eta_d * rho_g * A_r * |v_E| * v_E                        (dynamic)
//! F_sh = - sgn(v_Ex) * eta_h * g * rho_g * w * d^2            along x (static, horizontal)
//! F_sv = - sgn(v_Ey) * eta_v * (d / L_ref)^lambda * g * rho_g * V   along y (static, vertical)
//! ```
//!
//! with `A_r |v_E| = d_c * l * |e x v_E|` (eq. 3.13 written without the atan of eq. 3.14,
//! which breaks at v_Ey = 0), `V = pi d_c^2 / 4 * l` (eq. 3.15), `l` the immersed length
//! and `d` the depth of the tip. The signs are supplied by the caller: the solver holds
//! them fixed through a step ("modes"), or evaluates them plainly ("raw", the thesis's
//! `sign()`), or smooths them (`tanh(v / eps)`).

use nalgebra::Vector2;

/// The four fitted constants of the force law (thesis Table 3.2 / 3.4). All dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Horizontal static scaling constant eta_h [-].
    pub eta_h: f64,
    /// Dynamic (drag) scaling constant eta_d [-].
    pub eta_d: f64,
    /// Vertical static scaling constant eta_v [-].
    pub eta_v: f64,
    /// Depth exponent lambda of the vertical static term [-].
    pub lambda: f64,
}

impl Coefficients {
    /// Table 3.4 of the thesis at q = 0 (vertical rod): the default of the free link.
    pub const TABLE_3_4_VERTICAL: Coefficients = Coefficients {
        eta_h: 6.5,
        eta_d: 15.2,
        eta_v: 248.0,
        lambda: 0.106,
    };

    /// Validate: every value finite, etas >= 0, lambda >= 0. `prefix` names the field.
    pub fn validate(&self, prefix: &str) -> crate::error::Result<()> {
        use crate::error::check_range;
        for (name, value) in [
            ("eta_h", self.eta_h),
            ("eta_d", self.eta_d),
            ("eta_v", self.eta_v),
            ("lam", self.lambda),
        ] {
            // The field's name is built only for the error.
            if !(value.is_finite() && value >= 0.0) {
                check_range(&format!("{prefix}.{name}"), value, 0.0, false)?;
            }
        }
        Ok(())
    }
}

/// The granular medium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    /// Bulk density of the sand, packing included [kg/m^3] (thesis sec. 3.3.1: 1650).
    pub rho_g: f64,
    /// Gravitational acceleration [m/s^2] (9.81, as in the thesis).
    pub g: f64,
}

impl Default for Medium {
    fn default() -> Self {
        Medium {
            rho_g: 1650.0,
            g: 9.81,
        }
    }
}

/// Kinematic state of one rod contact, as the force law needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodContactState {
    /// Depth of the tip below the surface, d = max(0, -y_T) [m].
    pub depth: f64,
    /// Immersed length along the axis, l = min(d / cos q, L) [m].
    pub immersed_length: f64,
    /// Unit axis vector e from the tip to the other end [-].
    pub axis: Vector2<f64>,
    /// Velocity of the body's material point at the immersed centroid E [m/s].
    pub v_centroid: Vector2<f64>,
}

/// The three terms of the resistance force on one contact [N].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForceComponents {
    /// Dynamic term F_d (both components) [N].
    pub drag: Vector2<f64>,
    /// Static horizontal term F_sh (x component) [N].
    pub static_h: f64,
    /// Static vertical term F_sv (y component) [N].
    pub static_v: f64,
}

impl ForceComponents {
    /// Total resistance force F_R = F_d + F_s [N].
    #[inline]
    pub fn total(&self) -> Vector2<f64> {
        Vector2::new(self.drag.x + self.static_h, self.drag.y + self.static_v)
    }
    /// |F_d| (thesis eq. 3.23) [N].
    #[inline]
    pub fn drag_magnitude(&self) -> f64 {
        self.drag.norm()
    }
    /// |F_s| = sqrt(F_sh^2 + F_sv^2) (thesis eq. 3.22) [N].
    #[inline]
    pub fn static_magnitude(&self) -> f64 {
        self.static_h.hypot(self.static_v)
    }
    /// |F_r| (thesis eq. 3.24) [N].
    #[inline]
    pub fn total_magnitude(&self) -> f64 {
        self.total().norm()
    }
}

/// Magnitudes of the two static terms for any contact shape [N]:
/// (eta_h g rho_g w d^2, eta_v (d/L_ref)^lambda g rho_g V), zero at or above the surface.
#[inline]
pub fn static_terms(
    c: &Coefficients,
    medium: &Medium,
    width: f64,
    l_ref: f64,
    depth: f64,
    volume: f64,
) -> (f64, f64) {
    let d = depth;
    if d <= 0.0 {
        return (0.0, 0.0);
    }
    let rg = medium.g * medium.rho_g;
    let h = c.eta_h * rg * width * d * d;
    // d * (1 / L_ref): the division waits for L_ref alone, not for the depth.
    let depth_factor = if c.lambda == 0.0 {
        1.0
    } else {
        (d * (1.0 / l_ref)).powf(c.lambda)
    };
    (h, c.eta_v * depth_factor * rg * volume)
}

/// Magnitudes of the two static terms of a rod before their signs are applied [N]:
/// (eta_h g rho_g w d^2, eta_v (d/L_ref)^lambda g rho_g V) with V = pi d_c^2 / 4 * l.
#[inline]
pub fn static_bounds(
    c: &Coefficients,
    medium: &Medium,
    width: f64,
    diameter: f64,
    l_ref: f64,
    state: &RodContactState,
) -> (f64, f64) {
    let volume = std::f64::consts::FRAC_PI_4 * diameter * diameter * state.immersed_length;
    static_terms(c, medium, width, l_ref, state.depth, volume)
}

/// Evaluate the rod resistance force with given signs `sx`, `sy` of the static terms
/// (each in [-1, 1]: the sign of v_Ex / v_Ey, or a smoothed or held value).
///
/// `width` is the contact width w of F_sh (d_c for a rod), `diameter` the rod diameter
/// d_c, `l_ref` the body length L_ref of the depth factor. Zero above the surface.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn rod_force(
    c: &Coefficients,
    medium: &Medium,
    width: f64,
    diameter: f64,
    l_ref: f64,
    state: &RodContactState,
    sx: f64,
    sy: f64,
) -> ForceComponents {
    if state.depth <= 0.0 {
        return ForceComponents::default();
    }
    let v = state.v_centroid;
    let e = state.axis;
    // A_r |v_E| = d_c l |e x v_E|: smooth at v_E = 0, no division.
    let cross = (e.x * v.y - e.y * v.x).abs();
    let k = c.eta_d * medium.rho_g * diameter * state.immersed_length * cross;
    let (h, vert) = static_bounds(c, medium, width, diameter, l_ref, state);
    ForceComponents {
        drag: -k * v,
        static_h: -sx * h,
        static_v: -sy * vert,
    }
}

/// The thesis's plain sign: -1, 0 or +1.
#[inline]
pub fn raw_sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(depth: f64, q: f64, v: Vector2<f64>) -> RodContactState {
        let axis = Vector2::new(q.sin(), q.cos());
        RodContactState {
            depth,
            immersed_length: (depth / q.cos()).min(0.19),
            axis,
            v_centroid: v,
        }
    }

    #[test]
    fn zero_above_surface() {
        let s = state(0.0, 0.3, Vector2::new(0.3, -2.0));
        let f = rod_force(
            &Coefficients::TABLE_3_4_VERTICAL,
            &Medium::default(),
            0.0127,
            0.0127,
            0.19,
            &s,
            1.0,
            -1.0,
        );
        assert_eq!(f, ForceComponents::default());
    }

    #[test]
    fn vertical_static_matches_hand_value() {
        // Table 3.6 row q = 0, v0 = 2.24: F_s at the stop 22.87 N at depth ~0.051 m.
        // By hand: 248 * (0.051/0.19)^0.106 * 9.81 * 1650 * pi/4 * 0.0127^2 * 0.051.
        let s = state(0.051, 0.0, Vector2::new(0.0, 0.0));
        let f = rod_force(
            &Coefficients::TABLE_3_4_VERTICAL,
            &Medium::default(),
            0.0127,
            0.0127,
            0.19,
            &s,
            0.0,
            -1.0,
        );
        let by_hand = 248.0 * (0.051f64 / 0.19).powf(0.106) * 9.81 * 1650.0 * std::f64::consts::PI
            / 4.0
            * 0.0127f64.powi(2)
            * 0.051;
        assert!((f.static_v - by_hand).abs() < 1e-12 * by_hand);
        assert!((f.static_v - 22.87).abs() / 22.87 < 0.03);
        // Moving along its own axis, the rod shows no reference area: no drag.
        assert_eq!(f.drag, Vector2::zeros());
    }
}
