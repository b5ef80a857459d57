//! Volumes in pinned, device-mapped host memory, for volumes larger than the GPU.
//!
//! Empty until the zero-copy issue: it builds on the CUDA backend's device volumes.
