//! Blender's bone scale inheritance (stand-in until the real port lands: every mode behaves as Full).

use glam::DMat4;

use crate::model::InheritMode;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlenderInherit {
    Full,
    FixShear,
    Aligned,
    Average,
    None,
    NoneLegacy,
}

impl BlenderInherit {
    pub fn from_mode(mode: InheritMode) -> Option<Self> {
        Some(match mode {
            InheritMode::BlenderFixShear => BlenderInherit::FixShear,
            InheritMode::BlenderAligned => BlenderInherit::Aligned,
            InheritMode::BlenderAverage => BlenderInherit::Average,
            InheritMode::BlenderNone => BlenderInherit::None,
            InheritMode::BlenderNoneLegacy => BlenderInherit::NoneLegacy,
            _ => return None,
        })
    }
}

pub fn child_pose(_mode: BlenderInherit, parent: &DMat4, offset: &DMat4, channel: &DMat4) -> DMat4 {
    *parent * *offset * *channel
}
