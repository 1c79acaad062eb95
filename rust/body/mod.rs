//! Bodies: planar trees of rigid links with a floating base, and the contact geometry of
//! rods, soles and arcs.
//!
//! One formulation serves every body model (free link, two-link chain, leg): generalized
//! coordinates `[x_root, y_root, q_0, ..., q_{n-1}]` (a root point and the absolute angle
//! of each link from the vertical), a mass matrix and generalized forces obtained from
//! each contact's force through the Jacobian of its point of application.

pub mod arc;
pub mod mechanism;
pub mod rod;
pub mod sole;
pub mod table;

pub use arc::{ArcContact, ArcGeometry};
pub use mechanism::{HeldRow, Joint, Link, Mechanism};
pub use rod::{RodContact, RodGeometry};
pub use sole::{SoleContact, SoleGeometry, SoleModel};
pub use table::DriveTable;
