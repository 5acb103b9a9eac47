//! Sampling, layering and local→model evaluation.
