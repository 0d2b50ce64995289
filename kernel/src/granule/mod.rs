//! Operations on one deformable granule over its own node and element
//! buffers, using the shared reference mesh.
//!
//! * [`forces`]: the element loop (internal + hourglass forces, energies);
//! * [`damping`]: rigid-body projection and selective damping;
//! * [`dynamics`]: the central-difference step around a contact pass;
//! * [`timestep`]: the stable time step.

pub mod damping;
pub mod dynamics;
pub mod forces;
pub mod quality;
pub mod timestep;
