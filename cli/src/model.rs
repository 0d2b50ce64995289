//! Owned storage for the kernel's caller-buffer APIs: the reference mesh
//! (full sphere, octant or cube) with its element data, and the run
//! buffers. It lives in `granbed-host` (kernel/host), shared with the
//! browser front end; re-exported here under the names the CLI uses.

pub use granbed_host::{
    GranuleStore, MeshLevel, OwnedReference, PlatenStore, PourStore, PowerStore, regrouped,
};
