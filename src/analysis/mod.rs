//! Decomposition of every bone, findings and whole-clip scans.
