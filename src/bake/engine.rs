//! The runtime a bake is for (`bonescope bake --for ENGINE`): what it can play, so that users pick an engine rather
//! than a strategy and an interpolation.
//!
//! Two things differ between runtimes that play glTF:
//! - whether their transforms can shear: a node of Unreal's is an `FTransform` (translation, rotation, scale), and a
//!   parent's non-uniform scale never shears its children there, so a helper node cannot carry the stretch rotation
//!   and each bone is the closest TRS ([`Strategy::Trs`]); the others compose full matrices ([`Strategy::Exact`]);
//! - how they interpolate rotation keys: three.js and Godot slerp, as glTF says; Blender's importer, Unity's
//!   quaternion curves and Unreal's tracks interpolate each quaternion component and normalise (nlerp).
//!
//! Units, up axis and root stay glTF's for every engine (metres, +Y up, the source's roots, a common one added
//! above the joints of a skin that has none): each engine's glTF importer converts them to its own.

use super::{EVERY_RUNTIME, Strategy};
use crate::eval::layers::RotationInterpolation;
use crate::model::Choice;

/// The runtime a bake is for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Engine {
    /// Safe in every runtime below: helper nodes, keys that survive slerp and nlerp.
    #[default]
    Generic,
    Blender,
    Three,
    Godot,
    Unity,
    Unreal,
}

impl Choice for Engine {
    const ALL: &'static [Engine] =
        &[Engine::Generic, Engine::Blender, Engine::Three, Engine::Godot, Engine::Unity, Engine::Unreal];

    fn id(self) -> &'static str {
        match self {
            Engine::Generic => "generic",
            Engine::Blender => "blender",
            Engine::Three => "three",
            Engine::Godot => "godot",
            Engine::Unity => "unity",
            Engine::Unreal => "unreal",
        }
    }

    fn description(self) -> &'static str {
        match self {
            Engine::Generic => "every runtime: helper nodes where bones shear, keys that survive slerp and nlerp",
            Engine::Blender => "Blender's glTF importer: helper nodes, keys that survive its per-component F-curves",
            Engine::Three => "three.js: helper nodes, keys that survive slerp",
            Engine::Godot => "Godot: helper nodes, keys that survive slerp",
            Engine::Unity => "Unity (glTFast, UnityGLTF): helper nodes, keys that survive per-component curves",
            Engine::Unreal => "Unreal: one TRS node per bone (FTransform cannot shear), keys that survive nlerp",
        }
    }
}

impl Engine {
    /// How its bones become nodes.
    pub fn strategy(self) -> Strategy {
        match self {
            Engine::Unreal => Strategy::Trs,
            _ => Strategy::Exact,
        }
    }

    /// How it interpolates rotation keys: the interpolations the keys must survive.
    pub fn rotations(self) -> &'static [RotationInterpolation] {
        match self {
            Engine::Generic => EVERY_RUNTIME,
            Engine::Three | Engine::Godot => &[RotationInterpolation::Slerp],
            Engine::Blender | Engine::Unity | Engine::Unreal => &[RotationInterpolation::Nlerp],
        }
    }
}
