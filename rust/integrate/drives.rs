//! The times of the table-driven joints ([`DriveTable`]): each is a located event of known
//! time. The run ends a step on it (a clamp of the step, not a root find: the time is known,
//! and a step that ends there is a whole RK4 step, so the order holds between the times),
//! then takes the impulse that puts the rates on the new segments
//! ([`crate::dynamics::Model::drive_impulse`]).

use crate::body::DriveTable;

/// The table-driven joints of a run and their times.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Drives {
    /// Each table-driven joint: the link it carries (the model's order) and its table.
    joints: Vec<(usize, DriveTable)>,
    /// Every table's times after the start (t > 0), sorted, each once [s].
    times: Vec<f64>,
}

impl Drives {
    /// The drives of `joints` (`(link, table)`).
    pub fn new(joints: Vec<(usize, DriveTable)>) -> Self {
        let mut times: Vec<f64> = joints
            .iter()
            .flat_map(|(_, d)| d.times.iter().copied())
            .filter(|&t| t > 0.0)
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        Drives { joints, times }
    }

    /// The `k`-th time after the start, if there is one.
    #[inline]
    pub fn time(&self, k: usize) -> Option<f64> {
        self.times.get(k).copied()
    }

    /// The joints with a time at `t`, each with its new rate: `(link, slope after t)`.
    pub fn targets(&self, t: f64) -> Vec<(usize, f64)> {
        self.joints
            .iter()
            .filter(|(_, d)| d.times.contains(&t))
            .map(|(link, d)| (*link, d.slope(t)))
            .collect()
    }
}
