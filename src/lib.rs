//! bonescope: see what a skeletal animation really does to every bone.
//!
//! Data flows one way: `import` turns a file into a [`model::Rig`]; `eval` samples a clip into local transforms,
//! layers a game runtime's techniques on them (`eval::layers`: blends, additive clips, crossfades, shake, targets)
//! and combines them into model matrices with each bone's scale-inheritance mode; `analysis` runs Shoemake's polar
//! decomposition on every matrix and flags stretched, mirrored and degenerate bones; `cli` prints the result;
//! `export` writes skinned meshes at a pose (OBJ).
//!
//! Conventions, kept everywhere: column vectors (`W_child = W_parent · L_child`), quaternions `[x, y, z, w]`,
//! seconds inside the library, right-handed Y-up.

pub mod analysis;
pub mod app;
pub mod bake;
pub mod cli;
pub mod diff;
pub mod eval;
pub mod export;
pub mod import;
pub mod library;
pub mod math;
pub mod model;
pub mod render;
pub mod view;
