//! How a bone combines its parent's model matrix with its own local transform.
//!
//! The ids are what the command line and the JSON reports use; `docs/inheritance-modes.md` gives the model matrix of
//! every mode and which setting of which tool each one is.

use std::fmt;
use std::str::FromStr;

/// A bone's scale-inheritance mode. Roots behave the same in every mode (`W = L`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InheritMode {
    /// `W = W_p·L`: glTF, FBX RSrs, Blender Full, Unity, Godot, ozz. Shears under a rotated child.
    #[default]
    Full,
    /// A runtime's two-pass "don't inherit scale" (bone matrices from translations and rotations first, the scale
    /// added after): `W = G_p·L` with `G` the rigid (T·R only) chain.
    UnscaledParent,
    /// Maya segment scale compensate / FBX Rrs: `W = U_p·T(s_p⊙t)·R·S`.
    SegmentCompensate,
    /// FBX RrSs as ufbx reads it, Unreal's FTransform: parent scale applied along the child's axes.
    Componentwise,
    /// Blender Inherit Scale: Fix Shear.
    BlenderFixShear,
    /// Blender Inherit Scale: Aligned.
    BlenderAligned,
    /// Blender Inherit Scale: Average.
    BlenderAverage,
    /// Blender Inherit Scale: None.
    BlenderNone,
    /// Blender Inherit Scale: None (Legacy).
    BlenderNoneLegacy,
}

impl InheritMode {
    /// Every mode, in the order of the reference table.
    pub const ALL: [InheritMode; 9] = [
        InheritMode::Full,
        InheritMode::UnscaledParent,
        InheritMode::SegmentCompensate,
        InheritMode::Componentwise,
        InheritMode::BlenderFixShear,
        InheritMode::BlenderAligned,
        InheritMode::BlenderAverage,
        InheritMode::BlenderNone,
        InheritMode::BlenderNoneLegacy,
    ];

    /// The stable id used on the command line and in reports.
    pub fn id(self) -> &'static str {
        match self {
            InheritMode::Full => "full",
            InheritMode::UnscaledParent => "unscaled-parent",
            InheritMode::SegmentCompensate => "segment-compensate",
            InheritMode::Componentwise => "componentwise",
            InheritMode::BlenderFixShear => "blender-fix-shear",
            InheritMode::BlenderAligned => "blender-aligned",
            InheritMode::BlenderAverage => "blender-average",
            InheritMode::BlenderNone => "blender-none",
            InheritMode::BlenderNoneLegacy => "blender-none-legacy",
        }
    }

    /// A few characters for tight places (the outliner's rows): `SSC` for segment scale compensate, `B align` for
    /// Blender's Aligned.
    pub fn abbreviation(self) -> &'static str {
        match self {
            InheritMode::Full => "full",
            InheritMode::UnscaledParent => "no-scale",
            InheritMode::SegmentCompensate => "SSC",
            InheritMode::Componentwise => "comp",
            InheritMode::BlenderFixShear => "B fix",
            InheritMode::BlenderAligned => "B align",
            InheritMode::BlenderAverage => "B avg",
            InheritMode::BlenderNone => "B none",
            InheritMode::BlenderNoneLegacy => "B legacy",
        }
    }

    /// One line on what the mode models, for help texts and tooltips.
    pub fn description(self) -> &'static str {
        match self {
            InheritMode::Full => "full matrix inheritance (glTF, FBX RSrs, Unity, Godot, ozz)",
            InheritMode::UnscaledParent => {
                "parent matrix from the rigid T·R chain (the two-pass \"don't inherit scale\")"
            }
            InheritMode::SegmentCompensate => "Maya segment scale compensate, FBX Rrs",
            InheritMode::Componentwise => "parent scale along the child's axes (FBX RrSs, Unreal FTransform)",
            InheritMode::BlenderFixShear => "Blender Inherit Scale: Fix Shear",
            InheritMode::BlenderAligned => "Blender Inherit Scale: Aligned",
            InheritMode::BlenderAverage => "Blender Inherit Scale: Average",
            InheritMode::BlenderNone => "Blender Inherit Scale: None",
            InheritMode::BlenderNoneLegacy => "Blender Inherit Scale: None (Legacy)",
        }
    }

    /// Whether the mode follows Blender's bone model (rest offset `O` and channel `C`).
    pub fn is_blender(self) -> bool {
        matches!(
            self,
            InheritMode::BlenderFixShear
                | InheritMode::BlenderAligned
                | InheritMode::BlenderAverage
                | InheritMode::BlenderNone
                | InheritMode::BlenderNoneLegacy
        )
    }
}

impl fmt::Display for InheritMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id())
    }
}

/// The error of parsing an unknown mode id.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown inheritance mode `{0}` (expected one of: {ids})", ids = InheritMode::ALL.map(InheritMode::id).join(", "))]
pub struct UnknownInheritMode(pub String);

impl FromStr for InheritMode {
    type Err = UnknownInheritMode;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        InheritMode::ALL.into_iter().find(|m| m.id() == s).ok_or_else(|| UnknownInheritMode(s.to_owned()))
    }
}

/// Modes for a set of bones: one mode for all, or each bone's own as its file declares it. What a mode edit sets,
/// what a ghost shows, and each side of `diff` and `scan --compare-inherit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeChoice {
    Declared,
    Mode(InheritMode),
}

impl ModeChoice {
    /// "declared" first, then every mode.
    pub fn all() -> impl Iterator<Item = ModeChoice> {
        std::iter::once(ModeChoice::Declared).chain(InheritMode::ALL.into_iter().map(ModeChoice::Mode))
    }

    /// `declared`, or the mode's id.
    pub fn label(self) -> &'static str {
        match self {
            ModeChoice::Declared => "declared",
            ModeChoice::Mode(mode) => mode.id(),
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            ModeChoice::Declared => "each bone as its file declares it",
            ModeChoice::Mode(mode) => mode.description(),
        }
    }

    /// The mode this choice gives a bone whose file declares `declared`.
    pub fn mode_for(self, declared: InheritMode) -> InheritMode {
        match self {
            ModeChoice::Declared => declared,
            ModeChoice::Mode(mode) => mode,
        }
    }
}

/// The error of parsing a choice that is neither `declared` nor a mode id.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}, or `declared`")]
pub struct UnknownModeChoice(pub UnknownInheritMode);

impl FromStr for ModeChoice {
    type Err = UnknownModeChoice;

    /// `declared` or a mode id.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "declared" => Ok(ModeChoice::Declared),
            mode => mode.parse().map(ModeChoice::Mode).map_err(UnknownModeChoice),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_round_trip_through_their_labels() {
        for choice in ModeChoice::all() {
            assert_eq!(choice.label().parse::<ModeChoice>(), Ok(choice));
        }
        assert_eq!(ModeChoice::all().count(), InheritMode::ALL.len() + 1);
        let error = "sideways".parse::<ModeChoice>().unwrap_err();
        assert!(error.to_string().starts_with("unknown inheritance mode `sideways`"), "{error}");
        assert!(error.to_string().ends_with(", or `declared`"), "{error}");
    }

    #[test]
    fn ids_round_trip() {
        for mode in InheritMode::ALL {
            assert_eq!(mode.id().parse::<InheritMode>(), Ok(mode));
            assert_eq!(serde_json::to_string(&mode).unwrap(), format!("\"{}\"", mode.id()));
        }
        assert!("fulll".parse::<InheritMode>().is_err());
    }
}
