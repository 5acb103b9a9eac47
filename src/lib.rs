//! bonescope: see what a skeletal animation really does to every bone.
//!
//! Data flows one way: `import` turns a file into a [`model::Rig`]; an [`eval::Evaluation`] says what is evaluated
//! (a clip, each bone's scale-inheritance mode, the layers of a game runtime's techniques, the skinning, the times
//! a whole-clip pass visits) and evaluates poses: local transforms combined into model matrices with each bone's
//! mode. On top of it: `analysis` decomposes every matrix (Shoemake's polar decomposition) and flags stretched,
//! mirrored and degenerate bones; `fit` says which mode a runtime's pose dump implements; `explain` says whose scale shears a bone and which fix costs least; `diff`
//! compares two evaluations; `bake` writes one as plain glTF; `library` scans folders of files; `cli` prints it all, and the `gui` feature adds the app (`app`, `view`, `render`).
//!
//! Load a file (here the built-in demo rig), scan a clip, and decompose a bone where it shears most:
//!
//! ```
//! use bonescope::analysis::{ScanOptions, scan};
//! use bonescope::eval::Evaluation;
//! use bonescope::math::decompose;
//!
//! let rig = bonescope::import::demo_rig(); // a file: bonescope::import::load(path)?
//! let evaluation = Evaluation::declared(&rig, rig.clips.first());
//! let summary = scan(&evaluation, &ScanOptions::default(), &|_, _| {});
//! let forearm = &summary.bones[rig.skeleton.find("forearm").unwrap()];
//! assert!(forearm.stretched(), "the demo's forearm shears under its parent's squash");
//!
//! let pose = evaluation.pose_at(forearm.worst_shear_time);
//! let parts = decompose(&pose.model.model[forearm.index]); // M = T·F·R·U·K·Uᵀ
//! assert!(parts.scale.max_element() / parts.scale.min_element() > 1.01, "non-uniform: {:?}", parts.scale);
//! ```
//!
//! Conventions, kept everywhere: column vectors (`W_child = W_parent · L_child`), quaternions `[x, y, z, w]`,
//! seconds inside the library, right-handed Y-up.

pub mod analysis;
#[cfg(feature = "gui")]
pub mod app;
pub mod bake;
#[cfg(feature = "cli")]
pub mod cli;
pub mod diff;
pub mod eval;
pub mod explain;
pub mod export;
pub mod fit;
pub mod import;
pub mod library;
pub mod math;
pub mod model;
#[cfg(feature = "gui")]
pub mod render;
#[cfg(feature = "gui")]
pub mod view;
