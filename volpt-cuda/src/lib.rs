//! volpt's CUDA backend.
//!
//! The kernels, the device volumes and the launchers arrive with the GPU backend issue; this crate
//! holds their place in the workspace and offers nothing yet, so that nothing can call a GPU path that
//! does not exist.
