//! Contact geometry of a foot: the sole as a box (MODEL.md, "Contact geometry", Foot).
//!
//! In the plane the foot is a rectangle fixed on its link: `length` f_s along the link's
//! axis, from the sole up to the ankle (`height`), and `width` w_s out of the plane. Its
//! immersed part is the rectangle clipped by the surface y = 0, a convex polygon of up to
//! six vertices. From it:
//!
//! - immersed volume `V = w_s * area` (finite for a flat, heel-first or toe-first landing);
//! - reference area `A_r = w_s * (extent of the polygon normal to v_E)`, so that
//!   `A_r |v_E| = w_s (max_i p_i x v_E - min_i p_i x v_E)`, with no division by |v_E|;
//! - the depth of the force law, `d = area / f_s`: the sole's depth in a flat landing,
//!   positive as soon as any corner is in, and continuous as the foot tilts;
//! - the centroid E of the polygon.
//!
//! The thesis's eqs. 5.5-5.7 divide by cos q and sin q of the same angle, so one of them is
//! infinite for any posture; [`SoleModel::Thesis`] offers them only where both are finite.

use nalgebra::Vector2;

/// Which reference area and volume the foot uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SoleModel {
    /// The geometric box (default): A_r and V from the immersed part of the box.
    Box,
    /// The thesis's eqs. 5.5-5.7 with q the shank's angle from the vertical:
    /// `A_r |v_E| = f_s (d / cos q) |e x v_E|`, `V = f_s w_s d / |sin q|`. Finite only for
    /// 0 < |q| < 90 deg; a run that reaches either end stops with an error.
    Thesis,
}

/// A sole contact: a box on one link of a mechanism.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoleContact {
    /// The foot's link.
    pub link: usize,
    /// The link whose angle is the thesis form's q (the shank).
    pub angle_link: usize,
    /// Local (s, n) coordinates of the sole's heel corner [m]; the sole runs along +s for
    /// `length`, and the box rises from the sole towards -n for `height`.
    pub heel: Vector2<f64>,
    /// Foot length f_s [m] (also the width w of the horizontal static term, eq. 5.3).
    pub length: f64,
    /// Height of the box from the sole to the ankle [m].
    pub height: f64,
    /// Shoe width w_s out of the plane [m].
    pub width: f64,
    /// Reference length of the depth factor, the tibia l_l [m] (eq. 5.4).
    pub l_ref: f64,
    /// Reference area and volume model.
    pub model: SoleModel,
}

/// The immersed part of a sole at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoleGeometry {
    /// Depth of the force law, in-plane immersed area / f_s [m].
    pub depth: f64,
    /// Immersed in-plane area [m^2].
    pub area: f64,
    /// Centroid E of the immersed part, world coordinates [m] (the reference point when
    /// nothing is immersed).
    pub centroid: Vector2<f64>,
    /// Vertices of the immersed polygon, world coordinates [m].
    pub vertices: [Vector2<f64>; 6],
    /// Number of vertices used.
    pub n_vertices: usize,
    /// Lowest y of the box [m] (the entry function).
    pub lowest: f64,
    /// Highest y of the box [m] (negative when wholly immersed).
    pub highest: f64,
    /// y of each corner, in the order of [`SoleContact::corners_local`] [m]: where one
    /// crosses the surface the immersed polygon gains or loses a vertex (a located event).
    pub corners_y: [f64; 4],
}

/// Below this area, as a fraction of `length^2`, the immersed polygon is a sliver whose
/// area centroid is round-off (1e-9: a depth of about 1e-9 of the sole's length).
const SLIVER: f64 = 1e-9;

/// The centroid of a polygon's edges below the surface (those with both ends on y = 0,
/// the waterline, left out), weighted by length; `None` without any.
fn sliver_centroid(vertices: &[Vector2<f64>]) -> Option<Vector2<f64>> {
    let n = vertices.len();
    let mut sum = Vector2::zeros();
    let mut total = 0.0;
    for i in 0..n {
        let (p, q) = (vertices[i], vertices[(i + 1) % n]);
        if p.y == 0.0 && q.y == 0.0 {
            continue;
        }
        let len = (q - p).norm();
        sum += len * 0.5 * (p + q);
        total += len;
    }
    (total > 0.0).then(|| sum / total)
}

impl SoleContact {
    /// The reference point T: the middle of the sole (local coordinates).
    #[inline]
    pub fn reference_point(&self) -> Vector2<f64> {
        self.heel + Vector2::new(0.5 * self.length, 0.0)
    }

    /// The four corners in local coordinates: heel, toe (on the sole), then the top.
    #[inline]
    pub fn corners_local(&self) -> [Vector2<f64>; 4] {
        let h = self.heel;
        [
            h,
            h + Vector2::new(self.length, 0.0),
            h + Vector2::new(self.length, -self.height),
            h + Vector2::new(0.0, -self.height),
        ]
    }

    /// The immersed polygon for a link at `joint` with axis `axis` and normal `normal`.
    pub fn geometry(
        &self,
        joint: Vector2<f64>,
        axis: Vector2<f64>,
        normal: Vector2<f64>,
    ) -> SoleGeometry {
        let corners = self
            .corners_local()
            .map(|r| joint + r.x * axis + r.y * normal);
        let lowest = corners.iter().fold(f64::INFINITY, |m, p| m.min(p.y));
        let highest = corners.iter().fold(f64::NEG_INFINITY, |m, p| m.max(p.y));
        // Clip the (convex) rectangle to y <= 0 (Sutherland-Hodgman against one line).
        let mut vertices = [Vector2::zeros(); 6];
        let mut n = 0;
        for i in 0..4 {
            let a = corners[i];
            let b = corners[(i + 1) % 4];
            let a_in = a.y <= 0.0;
            let b_in = b.y <= 0.0;
            if a_in {
                vertices[n] = a;
                n += 1;
            }
            if a_in != b_in {
                let t = a.y / (a.y - b.y);
                vertices[n] = Vector2::new(a.x + t * (b.x - a.x), 0.0);
                n += 1;
            }
        }
        // Area and centroid by the shoelace formula (clockwise or not: take |area|).
        let mut a2 = 0.0;
        let mut cx = 0.0;
        let mut cy = 0.0;
        for i in 0..n {
            let p = vertices[i];
            let q = vertices[(i + 1) % n];
            let cr = p.x * q.y - q.x * p.y;
            a2 += cr;
            cx += (p.x + q.x) * cr;
            cy += (p.y + q.y) * cr;
        }
        let area = 0.5 * a2.abs();
        let centroid = if n >= 3 && area > SLIVER * self.length * self.length {
            Vector2::new(cx / (3.0 * a2), cy / (3.0 * a2))
        } else {
            // A sliver (a flat sole at touchdown): its area centroid is round-off (its
            // corners' heights are known to ~1e-17 m only); its limit is the centroid of
            // its edges in the sand (the waterline left out): a flat sole's middle, a
            // tilted one's corner.
            sliver_centroid(&vertices[..n]).unwrap_or_else(|| {
                let r = self.reference_point();
                joint + r.x * axis + r.y * normal
            })
        };
        SoleGeometry {
            depth: area / self.length,
            area,
            centroid,
            vertices,
            n_vertices: n,
            lowest,
            highest,
            corners_y: corners.map(|p| p.y),
        }
    }

    /// `A_r |v_E|` of the box: w_s times the extent of the immersed polygon normal to v_E,
    /// times |v_E| [m^3/s].
    pub fn drag_area_speed(&self, geom: &SoleGeometry, v_e: Vector2<f64>) -> f64 {
        if geom.n_vertices < 3 {
            return 0.0;
        }
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for p in &geom.vertices[..geom.n_vertices] {
            let c = p.x * v_e.y - p.y * v_e.x;
            lo = lo.min(c);
            hi = hi.max(c);
        }
        self.width * (hi - lo)
    }

    /// Immersed volume V = w_s * area [m^3].
    #[inline]
    pub fn volume(&self, geom: &SoleGeometry) -> f64 {
        self.width * geom.area
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sole() -> SoleContact {
        SoleContact {
            link: 0,
            angle_link: 0,
            heel: Vector2::new(-0.127, 0.07),
            length: 0.254,
            height: 0.07,
            width: 0.086,
            l_ref: 0.432,
            model: SoleModel::Box,
        }
    }

    /// A flat foot: axis +x, normal -y, ankle at height `y`.
    fn flat(s: &SoleContact, ankle_y: f64) -> SoleGeometry {
        s.geometry(
            Vector2::new(0.0, ankle_y),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.0, -1.0),
        )
    }

    #[test]
    fn flat_landing_is_a_rectangle() {
        let s = sole();
        let g = flat(&s, 0.07 - 0.03);
        assert!((g.depth - 0.03).abs() < 1e-15);
        assert!((s.volume(&g) - 0.086 * 0.254 * 0.03).abs() < 1e-15);
        assert!((g.centroid - Vector2::new(0.0, -0.015)).norm() < 1e-15);
        // Sinking straight down: the projected area is the sole, w_s f_s.
        let k = s.drag_area_speed(&g, Vector2::new(0.0, -2.0));
        assert!((k - 0.086 * 0.254 * 2.0).abs() < 1e-14);
        // Sliding sideways: the side of the immersed part, w_s d.
        let k = s.drag_area_speed(&g, Vector2::new(3.0, 0.0));
        assert!((k - 0.086 * 0.03 * 3.0).abs() < 1e-14);
        // Out of the sand: nothing.
        let g = flat(&s, 0.08);
        assert_eq!(g.area, 0.0);
        assert_eq!(s.drag_area_speed(&g, Vector2::new(0.0, -1.0)), 0.0);
        assert!((g.lowest - 0.01).abs() < 1e-15);
    }

    #[test]
    fn a_flat_sole_at_touchdown_acts_at_its_middle() {
        // Heel and toe a few 1e-17 m deep, unevenly (round-off of a flat landing): the
        // area centroid of that sliver is round-off, its limit the sole's middle.
        let s = sole();
        let a: f64 = 1e-16; // a tilt at round-off level
        let axis = Vector2::new(a.cos(), a.sin());
        let normal = Vector2::new(a.sin(), -a.cos());
        let g = s.geometry(Vector2::new(0.0, 0.07 - 3e-17), axis, normal);
        assert!(g.n_vertices >= 3 && g.area < 1e-15);
        assert!(g.centroid.x.abs() < 1e-12, "{}", g.centroid);
        // Tilted by a visible angle, the sliver's limit is the corner that went in first.
        let a: f64 = 0.2;
        let axis = Vector2::new(a.cos(), a.sin());
        let normal = Vector2::new(a.sin(), -a.cos());
        let heel = s.heel.x * axis + s.heel.y * normal;
        let g = s.geometry(Vector2::new(0.0, -heel.y - 1e-13), axis, normal);
        assert!(
            (g.centroid - Vector2::new(heel.x, -1e-13)).norm() < 1e-12,
            "{}",
            g.centroid
        );
    }

    #[test]
    fn heel_first_is_a_triangle_and_continuous() {
        let s = sole();
        let a: f64 = 0.2; // toe up by 0.2 rad
        let axis = Vector2::new(a.cos(), a.sin());
        let normal = Vector2::new(a.sin(), -a.cos());
        // Heel corner at depth 0.01.
        let heel_world = |joint: Vector2<f64>| joint + s.heel.x * axis + s.heel.y * normal;
        let j0 = Vector2::new(0.0, 0.0);
        let shift = Vector2::new(0.0, -0.01 - heel_world(j0).y);
        let g = s.geometry(j0 + shift, axis, normal);
        // A right triangle with legs 0.01/sin(a) along the sole and 0.01/cos(a) up the heel.
        let expect = 0.5 * (0.01 / a.sin()) * (0.01 / a.cos());
        assert!((g.area - expect).abs() < 1e-15, "{} vs {expect}", g.area);
        assert!((g.lowest + 0.01).abs() < 1e-15);
        // Area is continuous as the foot goes in.
        let mut last = 0.0;
        for k in 0..200 {
            let dy = -1e-3 * k as f64;
            let g = s.geometry(j0 + shift + Vector2::new(0.0, dy), axis, normal);
            assert!(
                g.area >= last - 1e-15 && g.area - last < 0.3e-3,
                "{k}: {} {last}",
                g.area
            );
            last = g.area;
        }
    }
}
