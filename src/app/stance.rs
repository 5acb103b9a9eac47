//! Which way up a file is shown. bonescope's space is Y-up; a file that states no axes (BVH) or states them wrongly
//! may lie down in it, in the view or beside the document it is compared with. The document and the compared file
//! are stood up alike, each with its picker in the menu bar.

use crate::model::UpAxis;

/// The axis a file is read as standing along (Y: as it says), and, where its figure lies down beside what it is
/// shown with, the axes `[that one's, its own]` each stands along as it plays ([`crate::diff::standing`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stance {
    pub up: UpAxis,
    pub apart: Option<[UpAxis; 2]>,
}

impl Stance {
    /// Whether the axis is the user's to pick: the file states none (`states_axes` false, a BVH), it lies down
    /// beside what it is shown with, or it was stood up already.
    pub fn pickable(&self, states_axes: bool) -> bool {
        !states_axes || self.apart.is_some() || self.up != UpAxis::Y
    }
}
