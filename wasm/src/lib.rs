//! Browser front end of granbed. Until the browser issue lands this crate
//! only re-exports the kernel, so that the workspace builds it for wasm32.
pub use granbed_kernel as kernel;
