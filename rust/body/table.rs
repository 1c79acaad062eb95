//! A joint driven along a piecewise-linear table of (time, relative angle): the angle is the
//! table's linear interpolation, held at its first angle before the first time and at its
//! last after the last time.
//!
//! Between two times the joint is a constant-rate drive (`qdot_i - qdot_parent` = the
//! segment's slope, zero relative acceleration), which RK4 keeps exactly. At each time the
//! rate jumps: the run lands a step on it ([`crate::integrate`]) and takes the impulse that
//! puts the rates on the new segment ([`crate::dynamics::Model::drive_impulse`]).

/// The table of one driven joint: times [s], strictly increasing, and the relative angle
/// `q_child - q_parent` at each [rad]; at least two points (checked by the linkage).
#[derive(Debug, Clone, PartialEq)]
pub struct DriveTable {
    /// The times [s].
    pub times: Vec<f64>,
    /// The relative angle at each time [rad].
    pub angles: Vec<f64>,
}

impl DriveTable {
    /// The segment `t` lies in: `k` for `times[k-1] <= t < times[k]`, 0 before the first
    /// time and `len` at or after the last (right-continuous: a time belongs to the segment
    /// it starts).
    #[inline]
    fn segment(&self, t: f64) -> usize {
        self.times.partition_point(|&tk| tk <= t)
    }

    /// The relative angle at `t` [rad].
    pub fn angle(&self, t: f64) -> f64 {
        let k = self.segment(t);
        let n = self.times.len();
        if k == 0 {
            self.angles[0]
        } else if k >= n {
            self.angles[n - 1]
        } else {
            let (t0, t1) = (self.times[k - 1], self.times[k]);
            let (a0, a1) = (self.angles[k - 1], self.angles[k]);
            a0 + (a1 - a0) * ((t - t0) / (t1 - t0))
        }
    }

    /// The relative rate on the segment that starts at or before `t` and ends after it
    /// [rad/s]: 0 before the first time and from the last on.
    pub fn slope(&self, t: f64) -> f64 {
        let k = self.segment(t);
        if k == 0 || k >= self.times.len() {
            0.0
        } else {
            (self.angles[k] - self.angles[k - 1]) / (self.times[k] - self.times[k - 1])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds_the_ends() {
        let d = DriveTable {
            times: vec![0.5, 1.0, 2.0],
            angles: vec![1.0, 2.0, 0.0],
        };
        assert_eq!((d.angle(0.0), d.slope(0.0)), (1.0, 0.0));
        assert_eq!((d.angle(0.5), d.slope(0.5)), (1.0, 2.0));
        assert_eq!((d.angle(0.75), d.slope(0.75)), (1.5, 2.0));
        assert_eq!((d.angle(1.0), d.slope(1.0)), (2.0, -2.0));
        assert_eq!((d.angle(1.5), d.slope(1.5)), (1.0, -2.0));
        assert_eq!((d.angle(2.0), d.slope(2.0)), (0.0, 0.0));
        assert_eq!((d.angle(9.0), d.slope(9.0)), (0.0, 0.0));
    }
}
