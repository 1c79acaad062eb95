//! Contact geometry of a thin circular arc (a C-shaped leg), as a chain of chords.
//!
//! The arc sits on its link with its centre `c` at local `(s, n)` coordinates, radius `r`,
//! and runs from the angle `start` to `start + span`, the angles measured in the link's
//! frame from its `+s` axis towards its `+n` axis: the point at angle `phi` is
//! `c + r (cos phi, sin phi)` in `(s, n)`. (The normal `n` is the axis turned 90 degrees
//! clockwise, so in the world a growing `phi` turns clockwise.) It is `width` wide out of
//! the plane and has no thickness in the plane.
//!
//! The engine sees the arc as its `chords` chords, from vertex `k` at `phi_k = start + k
//! span / chords` to vertex `k + 1`: each chord is a thin plate of the boundary for the terms
//! that integrate over it (`rft`, `rft_inertial`), clipped at the surface like a rod's or a
//! box's plates. Its immersion is the chord polyline's:
//!
//! - **entry and exit:** its lowest vertex crossing the surface (a located event);
//! - **full immersion:** its highest vertex going under (a located event);
//! - **depth:** the lowest vertex's depth;
//! - **E:** the centroid of the immersed chords (length-weighted; the reference point T
//!   while nothing is immersed);
//! - **T, the reference point:** the arc's middle, the point at `start + span / 2`.
//!
//! A vertex crossing the surface between the lowest and the highest is a kink of the
//! immersed length that is not located (a box's four corners are; an arc has up to
//! [`MAX_CHORDS`] + 1 vertices): a free arc converges at first order in the step across
//! those instants, a driven one (its motion prescribed) is exact at each sample.

use nalgebra::Vector2;

/// Chords of an arc unless the scene says otherwise.
pub const DEFAULT_CHORDS: usize = 16;

/// Most chords of an arc.
pub const MAX_CHORDS: usize = 64;

/// A thin circular arc on one link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcContact {
    /// The link the arc belongs to.
    pub link: usize,
    /// Its centre, local (s, n) [m].
    pub centre: Vector2<f64>,
    /// Its radius [m].
    pub radius: f64,
    /// The angle of its first end, from +s towards +n [rad].
    pub start: f64,
    /// Its angular extent, 0 < span <= 2 pi [rad].
    pub span: f64,
    /// Width out of the plane [m].
    pub width: f64,
    /// The chords it is cut into, 1..=[`MAX_CHORDS`].
    pub chords: usize,
}

/// The immersed part of an arc at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcGeometry {
    /// Depth of the lowest vertex, max(0, -y) [m].
    pub depth: f64,
    /// Immersed length of the chord polyline [m].
    pub immersed_length: f64,
    /// Centroid E of the immersed chords, world coordinates [m] (T when nothing is in).
    pub centroid: Vector2<f64>,
    /// Lowest vertex's y [m] (the entry function).
    pub lowest: f64,
    /// Highest vertex's y [m] (negative when wholly immersed).
    pub highest: f64,
}

impl ArcContact {
    /// The local (s, n) point at angle `phi` [rad] on the circle.
    #[inline]
    pub fn point_at(&self, phi: f64) -> Vector2<f64> {
        let (s, c) = phi.sin_cos();
        self.centre + self.radius * Vector2::new(c, s)
    }

    /// The angle step of one chord [rad].
    #[inline]
    pub fn chord_angle(&self) -> f64 {
        self.span / self.chords as f64
    }

    /// Vertex `k` (0..=chords), local (s, n) [m].
    #[inline]
    pub fn vertex(&self, k: usize) -> Vector2<f64> {
        self.point_at(self.start + k as f64 * self.chord_angle())
    }

    /// The reference point T: the arc's middle (local coordinates).
    #[inline]
    pub fn reference_point(&self) -> Vector2<f64> {
        self.point_at(self.start + 0.5 * self.span)
    }

    /// The immersed chords for a link at `joint` with axis `axis` and normal `normal`.
    pub fn geometry(
        &self,
        joint: Vector2<f64>,
        axis: Vector2<f64>,
        normal: Vector2<f64>,
    ) -> ArcGeometry {
        let world = |r: Vector2<f64>| joint + r.x * axis + r.y * normal;
        let mut a = world(self.vertex(0));
        let (mut lowest, mut highest) = (a.y, a.y);
        let mut length = 0.0;
        let mut moment = Vector2::zeros();
        for k in 1..=self.chords {
            let b = world(self.vertex(k));
            lowest = lowest.min(b.y);
            highest = highest.max(b.y);
            // The chord's part at or below y = 0.
            let (a_in, b_in) = (a.y <= 0.0, b.y <= 0.0);
            let part = match (a_in, b_in) {
                (true, true) => Some((a, b)),
                (false, false) => None,
                _ => {
                    let t = a.y / (a.y - b.y);
                    let cut = Vector2::new(a.x + t * (b.x - a.x), 0.0);
                    Some(if a_in { (a, cut) } else { (cut, b) })
                }
            };
            if let Some((p, q)) = part {
                let l = (q - p).norm();
                length += l;
                moment += l * 0.5 * (p + q);
            }
            a = b;
        }
        let centroid = if length > 0.0 {
            moment / length
        } else {
            world(self.reference_point())
        };
        ArcGeometry {
            depth: (-lowest).max(0.0),
            immersed_length: length,
            centroid,
            lowest,
            highest,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn arc(chords: usize) -> ArcContact {
        ArcContact {
            link: 0,
            centre: Vector2::new(0.0, 0.0),
            radius: 0.035,
            start: 0.0,
            span: PI,
            width: 0.01,
            chords,
        }
    }

    /// A link at q = 90 deg: axis +x, normal -y (phi from +x clockwise, i.e. downwards).
    fn level(a: &ArcContact, centre_y: f64) -> ArcGeometry {
        a.geometry(
            Vector2::new(0.0, centre_y),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.0, -1.0),
        )
    }

    #[test]
    fn a_lower_half_circle_immerses_like_the_circle() {
        // Wholly under: the chords' length n 2 r sin(d/2) falls short of r pi by r pi d^2/24,
        // 4x less per doubling.
        let r = 0.035;
        let mut last = f64::NAN;
        for n in [8, 16, 32, 64] {
            let g = level(&arc(n), -0.01);
            let err = (g.immersed_length - r * PI).abs();
            if last.is_finite() {
                let ratio = last / err;
                assert!(ratio > 3.9 && ratio < 4.1, "{n}: {ratio}");
            }
            last = err;
            assert!((g.highest - (-0.01)).abs() < 1e-15 && g.depth > 0.0);
        }
        // Its centre h above the surface: the exact immersed arc is 2 r acos(h / r) long,
        // centred on the vertical through the centre. Where the surface cuts a chord moves
        // from one count to the next, so the error is bounded (by r d^2, second order) rather
        // than falling by exactly 4.
        let h: f64 = 0.01;
        let exact = 2.0 * r * (h / r).acos();
        let mut errs = Vec::new();
        for n in [8, 16, 32, 64] {
            let g = level(&arc(n), h);
            assert!((g.lowest - (h - r)).abs() < 1e-15, "{}", g.lowest);
            assert!(g.centroid.x.abs() < 1e-15);
            let d = PI / n as f64;
            let err = (g.immersed_length - exact).abs();
            assert!(err < r * d * d, "{n}: {err}");
            errs.push(err);
        }
        assert!(errs[3] < errs[0] / 16.0, "{errs:?}");
        // Out of the sand: nothing, E at the middle.
        let g = level(&arc(16), 0.04);
        assert_eq!(g.immersed_length, 0.0);
        assert_eq!(g.depth, 0.0);
        assert!((g.centroid - Vector2::new(0.0, 0.04 - 0.035)).norm() < 1e-15);
    }
}
