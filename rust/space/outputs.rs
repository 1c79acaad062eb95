//! What a run of a body in space reports: one table of its summary fields and one of its
//! series columns, each with its unit and meaning. Python's result, the docs and the CLI
//! read these tables; nothing else lists the names.

use super::solve::{Outcome, Sample};

/// A summary field: name, unit, meaning, and how to read it.
pub struct SummaryField {
    /// Its name (`result.summary[name]`).
    pub name: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// What it is.
    pub description: &'static str,
    /// Its value in an outcome.
    pub read: fn(&Outcome) -> f64,
}

/// A series column: name, unit, meaning, and how to read it from a sample.
pub struct SeriesColumn {
    /// Its name (`result.series[name]`).
    pub name: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// What it is.
    pub description: &'static str,
    /// Its value at a sample.
    pub read: fn(&Sample) -> f64,
}

macro_rules! summary {
    ($($name:literal, $unit:literal, $desc:literal, |$o:ident| $e:expr;)*) => {
        /// Every summary field of a run in space, in the order the docs list them.
        pub static SUMMARY: &[SummaryField] = &[$(SummaryField {
            name: $name,
            unit: $unit,
            description: $desc,
            read: |$o: &Outcome| $e,
        },)*];
    };
}

macro_rules! series {
    ($($name:literal, $unit:literal, $desc:literal, |$s:ident| $e:expr;)*) => {
        /// Every series column of a run in space (`record=True`), in order.
        pub static SERIES: &[SeriesColumn] = &[$(SeriesColumn {
            name: $name,
            unit: $unit,
            description: $desc,
            read: |$s: &Sample| $e,
        },)*];
    };
}

summary! {
    "t_s", "s", "time of the stop: the lowest point's vertical velocity turned >= 0 in the sand (NaN: none)", |o| o.t_s;
    "t_entry", "s", "time the lowest point reached the surface (0: it started in the sand; NaN: never)", |o| o.t_entry;
    "t_final", "s", "time the run ended (the stop, or t_end)", |o| o.t_end;
    "depth", "m", "the lowest point's depth below the surface at the end", |o| o.depth;
    "max_depth", "m", "the deepest the lowest point went", |o| o.max_depth;
    "F_max", "N", "the largest magnitude of the sand's force", |o| o.force_max;
    "Fx_end", "N", "the sand's force at the end, x", |o| o.load_end.force.x;
    "Fy_end", "N", "the sand's force at the end, y", |o| o.load_end.force.y;
    "Fz_end", "N", "the sand's force at the end, z (up)", |o| o.load_end.force.z;
    "Mx_end", "N m", "the sand's moment about the centre of mass at the end, x", |o| o.load_end.moment.x;
    "My_end", "N m", "the sand's moment about the centre of mass at the end, y", |o| o.load_end.moment.y;
    "Mz_end", "N m", "the sand's moment about the centre of mass at the end, z", |o| o.load_end.moment.z;
    "x_end", "m", "the centre of mass at the end, x", |o| o.end.c.x;
    "y_end", "m", "the centre of mass at the end, y", |o| o.end.c.y;
    "z_end", "m", "the centre of mass at the end, z", |o| o.end.c.z;
    "vx_end", "m/s", "the centre's velocity at the end, x", |o| o.end.v.x;
    "vy_end", "m/s", "the centre's velocity at the end, y", |o| o.end.v.y;
    "vz_end", "m/s", "the centre's velocity at the end, z", |o| o.end.v.z;
    "tilt_end", "deg", "the angle between the body's z axis and the vertical at the end", |o| {
        let a = o.end.rotation() * nalgebra::Vector3::z();
        a.z.clamp(-1.0, 1.0).acos().to_degrees()
    };
    "energy_start", "J", "mechanical energy at the start (kinetic, and m g z where gravity acts)", |o| o.energy_start;
    "energy_end", "J", "mechanical energy at the end", |o| o.energy_end;
    "dE", "J", "energy the sand took: energy_start - energy_end", |o| o.energy_start - o.energy_end;
    "wetted_area_end", "m^2", "the immersed surface's area at the end", |o| o.load_end.wetted_area;
    "h_lambda", "-", "the step times the sand's fastest rate (RK4 is stable below 2.785)", |o| o.h_lambda;
    "steps", "-", "steps taken", |o| o.steps as f64;
    "rhs_evals", "-", "right-hand-side evaluations", |o| o.rhs_evals as f64;
    "events", "-", "events located (entries and the stop)", |o| o.events as f64;
    "max_elements", "-", "the most surface elements in one evaluation", |o| o.max_elements as f64;
}

series! {
    "t", "s", "time", |s| s.t;
    "x", "m", "centre of mass, x", |s| s.state.c.x;
    "y", "m", "centre of mass, y", |s| s.state.c.y;
    "z", "m", "centre of mass, z", |s| s.state.c.z;
    "qw", "-", "orientation (unit quaternion, body to world), w", |s| s.state.rotation().w;
    "qx", "-", "orientation, x", |s| s.state.rotation().i;
    "qy", "-", "orientation, y", |s| s.state.rotation().j;
    "qz", "-", "orientation, z", |s| s.state.rotation().k;
    "vx", "m/s", "velocity of the centre, x", |s| s.state.v.x;
    "vy", "m/s", "velocity of the centre, y", |s| s.state.v.y;
    "vz", "m/s", "velocity of the centre, z", |s| s.state.v.z;
    "wx", "rad/s", "angular velocity (world frame), x", |s| s.state.omega().x;
    "wy", "rad/s", "angular velocity (world frame), y", |s| s.state.omega().y;
    "wz", "rad/s", "angular velocity (world frame), z", |s| s.state.omega().z;
    "Fx", "N", "the sand's force, x", |s| s.load.force.x;
    "Fy", "N", "the sand's force, y", |s| s.load.force.y;
    "Fz", "N", "the sand's force, z", |s| s.load.force.z;
    "Mx", "N m", "the sand's moment about the centre of mass, x", |s| s.load.moment.x;
    "My", "N m", "the sand's moment about the centre of mass, y", |s| s.load.moment.y;
    "Mz", "N m", "the sand's moment about the centre of mass, z", |s| s.load.moment.z;
    "depth", "m", "the lowest point's depth (negative above the surface)", |s| s.depth;
    "energy", "J", "mechanical energy", |s| s.energy;
}
