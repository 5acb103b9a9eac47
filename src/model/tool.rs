//! The tool that wrote a file, where it has scale-inheritance settings of its own: the modes an artist can set
//! there are the fixes to offer first.

use super::InheritMode;

/// A tool with scale-inheritance settings of its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tool {
    Maya,
    /// 3ds Max: its Link Info scale flags, cleared, are read as segment scale compensate by pipelines.
    Max,
    Blender,
}

impl Tool {
    /// The tool named by a file's "written by" text (an FBX file's original application), if it is one of these.
    pub fn named(application: &str) -> Option<Tool> {
        let lower = application.to_ascii_lowercase();
        [("maya", Tool::Maya), ("3ds max", Tool::Max), ("blender", Tool::Blender)]
            .into_iter()
            .find_map(|(name, tool)| lower.contains(name).then_some(tool))
    }

    /// The modes the tool's own settings give, its default first.
    pub fn modes(self) -> &'static [InheritMode] {
        match self {
            Tool::Maya | Tool::Max => &[InheritMode::Full, InheritMode::SegmentCompensate],
            Tool::Blender => &[
                InheritMode::Full,
                InheritMode::BlenderFixShear,
                InheritMode::BlenderAligned,
                InheritMode::BlenderAverage,
                InheritMode::BlenderNone,
                InheritMode::BlenderNoneLegacy,
            ],
        }
    }

    /// Its name, as its users write it.
    pub fn label(self) -> &'static str {
        match self {
            Tool::Maya => "Maya",
            Tool::Max => "3ds Max",
            Tool::Blender => "Blender",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_files_application_names_its_tool() {
        assert_eq!(Tool::named("Maya"), Some(Tool::Maya));
        assert_eq!(Tool::named("Autodesk 3ds Max 2021"), Some(Tool::Max));
        assert_eq!(Tool::named("Blender (stable FBX IO)"), Some(Tool::Blender));
        assert_eq!(Tool::named("FBX SDK/FBX Plugins version 2020.2"), None);
        assert!(Tool::Blender.modes().iter().all(|m| *m == InheritMode::Full || m.is_blender()));
    }
}
