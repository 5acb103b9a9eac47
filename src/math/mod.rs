//! Polar decomposition and quaternion helpers on top of glam.
