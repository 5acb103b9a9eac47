//! How a bone combines its parent's model matrix with its own local transform.
//!
//! The ids are what the command line and the JSON reports use; `docs/inheritance-modes.md` gives the model matrix of
//! every mode and which setting of which tool each one is.

use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

use super::{Choice, Skeleton};

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

impl Choice for InheritMode {
    /// Every mode, in the order of the reference table.
    const ALL: &'static [InheritMode] = &[
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
    fn id(self) -> &'static str {
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

    /// One line on what the mode models, for help texts and tooltips.
    fn description(self) -> &'static str {
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
}

impl fmt::Display for InheritMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id())
    }
}

/// The error of parsing an unknown mode id.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown inheritance mode `{0}` (expected one of: {ids})", ids = InheritMode::ALL.iter().map(|m| m.id()).collect::<Vec<_>>().join(", "))]
pub struct UnknownInheritMode(pub String);

impl FromStr for InheritMode {
    type Err = UnknownInheritMode;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        InheritMode::from_id(s).ok_or_else(|| UnknownInheritMode(s.to_owned()))
    }
}

/// Modes for a set of bones: one mode for all, or each bone's own as its file declares it. What a mode edit sets,
/// what a ghost shows, and each side of `diff` and `scan --compare-inherit`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ModeChoice {
    #[default]
    Declared,
    Mode(InheritMode),
}

impl Choice for ModeChoice {
    /// `declared` first, then every mode.
    const ALL: &'static [ModeChoice] = &[
        ModeChoice::Declared,
        ModeChoice::Mode(InheritMode::Full),
        ModeChoice::Mode(InheritMode::UnscaledParent),
        ModeChoice::Mode(InheritMode::SegmentCompensate),
        ModeChoice::Mode(InheritMode::Componentwise),
        ModeChoice::Mode(InheritMode::BlenderFixShear),
        ModeChoice::Mode(InheritMode::BlenderAligned),
        ModeChoice::Mode(InheritMode::BlenderAverage),
        ModeChoice::Mode(InheritMode::BlenderNone),
        ModeChoice::Mode(InheritMode::BlenderNoneLegacy),
    ];

    /// `declared`, or the mode's id.
    fn id(self) -> &'static str {
        match self {
            ModeChoice::Declared => "declared",
            ModeChoice::Mode(mode) => mode.id(),
        }
    }

    fn description(self) -> &'static str {
        match self {
            ModeChoice::Declared => "each bone as its file declares it",
            ModeChoice::Mode(mode) => mode.description(),
        }
    }
}

impl ModeChoice {
    /// The mode this choice gives a bone whose file declares `declared`.
    pub fn mode_for(self, declared: InheritMode) -> InheritMode {
        match self {
            ModeChoice::Declared => declared,
            ModeChoice::Mode(mode) => mode,
        }
    }
}

impl fmt::Display for ModeChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id())
    }
}

impl serde::Serialize for ModeChoice {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.id())
    }
}

impl<'de> serde::Deserialize<'de> for ModeChoice {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let id = String::deserialize(deserializer)?;
        id.parse().map_err(serde::de::Error::custom)
    }
}

/// Every bone's mode: one choice for all, and the bones given a mode of their own. What the app's mode edits and an
/// explained fix change, and what `--inherit` and `--inherit-bone` say on the command line.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Modes {
    /// The mode of every bone not in `bones`.
    pub all: ModeChoice,
    /// Bones, by index, whose mode differs from what `all` gives them.
    pub bones: BTreeMap<usize, InheritMode>,
}

impl Modes {
    /// One choice for every bone.
    pub fn all(choice: ModeChoice) -> Self {
        Modes { all: choice, bones: BTreeMap::new() }
    }

    /// `modes` (one per bone of `skeleton`): the file's, with the bones that differ from it given their own.
    pub fn of_bones(skeleton: &Skeleton, modes: &[InheritMode]) -> Self {
        let mut all = Modes::default();
        for (bone, &mode) in modes.iter().enumerate().take(skeleton.len()) {
            all.set(skeleton, bone, ModeChoice::Mode(mode));
        }
        all
    }

    /// One mode per bone of `skeleton` (a bone past its end, which [`Modes::missing_bone`] finds, is no bone).
    pub fn resolve(&self, skeleton: &Skeleton) -> Vec<InheritMode> {
        let mut modes = skeleton.modes(self.all);
        for (&bone, &mode) in &self.bones {
            if let Some(slot) = modes.get_mut(bone) {
                *slot = mode;
            }
        }
        modes
    }

    /// Gives `bone` of `skeleton` the mode `choice` gives it (its file's for `declared`).
    pub fn set(&mut self, skeleton: &Skeleton, bone: usize, choice: ModeChoice) {
        let declared = skeleton.bone(bone).inherit;
        let mode = choice.mode_for(declared);
        if mode == self.all.mode_for(declared) {
            self.bones.remove(&bone);
        } else {
            self.bones.insert(bone, mode);
        }
    }

    /// A bone given its own mode that a skeleton of `bones` bones lacks.
    pub fn missing_bone(&self, bones: usize) -> Option<usize> {
        self.bones.keys().copied().find(|&b| b >= bones)
    }

    /// What reports say the modes are: the choice for all, or `mixed` where single bones have their own (as the
    /// app says of a rig whose bones differ).
    pub fn label(&self) -> &'static str {
        if self.bones.is_empty() { self.all.id() } else { "mixed" }
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
        for &choice in ModeChoice::ALL {
            assert_eq!(choice.id().parse::<ModeChoice>(), Ok(choice));
            assert_eq!(serde_json::to_string(&choice).unwrap(), format!("\"{choice}\""));
            assert_eq!(serde_json::from_str::<ModeChoice>(&format!("\"{choice}\"")).unwrap(), choice);
        }
        assert_eq!(ModeChoice::ALL.len(), InheritMode::ALL.len() + 1);
        assert!(ModeChoice::ALL[1..].iter().zip(InheritMode::ALL).all(|(c, &m)| *c == ModeChoice::Mode(m)));
        let error = "sideways".parse::<ModeChoice>().unwrap_err();
        assert!(error.to_string().starts_with("unknown inheritance mode `sideways`"), "{error}");
        assert!(error.to_string().ends_with(", or `declared`"), "{error}");
    }

    #[test]
    fn ids_round_trip() {
        for &mode in InheritMode::ALL {
            assert_eq!(mode.id().parse::<InheritMode>(), Ok(mode));
            assert_eq!(serde_json::to_string(&mode).unwrap(), format!("\"{}\"", mode.id()));
        }
        assert!("fulll".parse::<InheritMode>().is_err());
    }

    #[test]
    fn modes_keep_only_the_bones_that_differ() {
        // The demo arm declares full everywhere: a bone set to full under `declared` is no override, and the modes
        // any per-bone list makes resolve back to that list.
        let skeleton = crate::import::demo_rig().skeleton;
        let mut modes = Modes::default();
        modes.set(&skeleton, 2, ModeChoice::Mode(InheritMode::Full));
        assert_eq!(modes, Modes::default());
        modes.set(&skeleton, 2, ModeChoice::Mode(InheritMode::BlenderAligned));
        assert_eq!((modes.label(), modes.bones.len()), ("mixed", 1));
        let resolved = modes.resolve(&skeleton);
        assert_eq!(resolved[2], InheritMode::BlenderAligned);
        assert_eq!(Modes::of_bones(&skeleton, &resolved), modes);
        modes.set(&skeleton, 2, ModeChoice::Declared);
        assert_eq!(modes, Modes::default());
        let compensated = Modes::all(ModeChoice::Mode(InheritMode::SegmentCompensate));
        assert_eq!(compensated.label(), "segment-compensate");
        assert!(compensated.resolve(&skeleton).iter().all(|&m| m == InheritMode::SegmentCompensate));
        let json = serde_json::to_string(&modes_with(&skeleton)).unwrap();
        assert_eq!(json, r#"{"all":"segment-compensate","bones":{"1":"full"}}"#);
        assert_eq!(serde_json::from_str::<Modes>(&json).unwrap(), modes_with(&skeleton));
        assert_eq!(modes_with(&skeleton).missing_bone(skeleton.len()), None);
        assert_eq!(modes_with(&skeleton).missing_bone(1), Some(1));
    }

    fn modes_with(skeleton: &Skeleton) -> Modes {
        let mut modes = Modes::all(ModeChoice::Mode(InheritMode::SegmentCompensate));
        modes.set(skeleton, 1, ModeChoice::Declared);
        modes
    }
}
