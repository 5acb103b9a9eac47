//! Sampling, layering and local→model evaluation.
pub mod blender;
