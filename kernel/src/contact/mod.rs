//! Contact.
//!
//! * [`wall`]: kinematic contact of nodes with a rigid plane, with friction.

pub mod wall;
