//! The viewport: camera, what to draw from a pose, and painting it with egui's painter. The app and the headless
//! renderer both draw through [`paint::paint`], so a screenshot shows exactly what the app shows.

pub mod camera;
pub mod paint;
pub mod scene;
pub mod style;

pub use camera::{Bounds, Camera, Projection, ViewKind};
pub use scene::{DrawnPose, Motion, Scene, SceneOptions, Triads, ground, motion, rest_bounds};
pub use style::{Badge, Palette};
