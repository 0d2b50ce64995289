//! Complete experiments over caller buffers, shared by the CLI and the
//! browser front end.
//!
//! * [`platens`]: one granule compressed between two rigid platens.

pub mod platens;
