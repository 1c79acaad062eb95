//! Contact geometry of a round rod (free link, chain links): immersed length, centroid E
//! of the immersed part, reference area and immersed volume.
//!
//! Source: thesis eqs. 3.4-3.15, as fixed by `shared/MODEL.md` ("Contact geometry"): the
//! immersed length is `l = min(d / cos q, L)`, which stays finite at and past horizontal.

use nalgebra::Vector2;

/// Where the resistance force acts on the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ApplyAt {
    /// At the tip T, as in the thesis's CAD runs (sec. 3.3.2, 3.4): the default, because it
    /// produced the thesis's tables. Not strictly dissipative.
    Tip,
    /// At the centroid E of the immersed part, as in the thesis's analysis (sec. 3.3.1):
    /// every term then does non-positive work.
    Centroid,
}

/// A rod contact: a round rod fixed on one link of a mechanism, meeting the sand with its tip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodContact {
    /// The link the rod belongs to.
    pub link: usize,
    /// The tip T in the link's local (s, n) coordinates [m]; the rod runs from T along +e.
    pub tip: Vector2<f64>,
    /// Rod length L [m] (also the reference length L_ref of the depth factor).
    pub length: f64,
    /// Rod diameter d_c [m] (also the width w of the horizontal static term).
    pub diameter: f64,
}

/// The geometry of one rod contact at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodGeometry {
    /// Depth of the tip below the surface, d = max(0, -y_T) [m].
    pub depth: f64,
    /// Immersed length l = min(d / cos q, L) [m].
    pub immersed_length: f64,
    /// Local s coordinate of the immersed centroid E on the link [m].
    pub centroid_s: f64,
}

impl RodContact {
    /// Immersed length and centroid for a tip at height `tip_y` and an axis `axis`.
    #[inline]
    pub fn geometry(&self, tip_y: f64, axis: Vector2<f64>) -> RodGeometry {
        let depth = (-tip_y).max(0.0);
        // l = d / cos q, capped at L; cos q = e_y <= d / L (at or past horizontal) gives L.
        let immersed_length = if depth >= self.length * axis.y {
            self.length
        } else {
            depth / axis.y
        };
        RodGeometry {
            depth,
            immersed_length,
            centroid_s: self.tip.x + 0.5 * immersed_length,
        }
    }

    /// Rate of change of the immersed length for a tip sinking at `depth_rate` = -v_Ty [m/s]
    /// while the axis turns at `e_y_rate` = d(cos q)/dt.
    #[inline]
    pub fn immersed_length_rate(
        &self,
        geom: &RodGeometry,
        axis: Vector2<f64>,
        depth_rate: f64,
        e_y_rate: f64,
    ) -> f64 {
        if geom.depth <= 0.0 || geom.immersed_length >= self.length {
            0.0
        } else {
            depth_rate / axis.y - geom.depth * e_y_rate / (axis.y * axis.y)
        }
    }

    /// Reference area A_r = d_c l |sin(angle between e and v_E)| [m^2] (eq. 3.13).
    pub fn reference_area(&self, geom: &RodGeometry, axis: Vector2<f64>, v_e: Vector2<f64>) -> f64 {
        let speed = v_e.norm();
        if speed == 0.0 {
            0.0
        } else {
            self.diameter * geom.immersed_length * (axis.x * v_e.y - axis.y * v_e.x).abs() / speed
        }
    }

    /// Immersed volume V = pi d_c^2 / 4 * l [m^3] (eq. 3.15).
    pub fn immersed_volume(&self, geom: &RodGeometry) -> f64 {
        std::f64::consts::FRAC_PI_4 * self.diameter * self.diameter * geom.immersed_length
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rod() -> RodContact {
        RodContact {
            link: 0,
            tip: Vector2::new(-0.095, 0.0),
            length: 0.19,
            diameter: 0.0127,
        }
    }

    #[test]
    fn immersed_length_is_capped_and_finite_at_horizontal() {
        let r = rod();
        let g = r.geometry(-0.01, Vector2::new(1.0, 0.0));
        assert_eq!(g.immersed_length, 0.19);
        let q: f64 = 0.5;
        let g = r.geometry(-0.02, Vector2::new(q.sin(), q.cos()));
        assert!((g.immersed_length - 0.02 / q.cos()).abs() < 1e-15);
        assert!((g.centroid_s - (-0.095 + 0.01 / q.cos())).abs() < 1e-15);
        assert_eq!(r.geometry(0.01, Vector2::new(0.0, 1.0)).depth, 0.0);
    }

    #[test]
    fn reference_area_of_axial_and_broadside_motion() {
        let r = rod();
        let g = r.geometry(-0.05, Vector2::new(0.0, 1.0));
        assert_eq!(
            r.reference_area(&g, Vector2::new(0.0, 1.0), Vector2::new(0.0, -2.0)),
            0.0
        );
        let broad = r.reference_area(&g, Vector2::new(0.0, 1.0), Vector2::new(3.0, 0.0));
        assert!((broad - 0.0127 * 0.05).abs() < 1e-15);
        assert_eq!(
            r.reference_area(&g, Vector2::new(0.0, 1.0), Vector2::zeros()),
            0.0
        );
    }
}
