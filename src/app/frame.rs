//! What the window draws at the current time: the document's pose and the ghost's, computed once a frame.

use super::document::{Document, Ghost};
use crate::analysis::Tolerances;
use crate::eval::{Pose, SkinningMethod};
use crate::view::DrawnPose;

/// The pose at the current time under the document's modes and layers, and the ghost pose.
pub struct CurrentPose {
    pub pose: Pose,
    pub primary: DrawnPose,
    pub ghost: Option<DrawnPose>,
}

impl CurrentPose {
    pub fn evaluate(doc: &Document, time: f64, skinning: SkinningMethod, tolerances: &Tolerances) -> CurrentPose {
        let rig = &doc.rig;
        let pose = doc.evaluation().pose_at(time);
        let primary = DrawnPose::from_model(rig, pose.model.model.clone(), &pose.morph, skinning, tolerances);
        let ghost = match (&doc.ghost, &doc.compared) {
            (Some(Ghost::Compared), Some(compared)) => {
                Some(compared.ghost(doc.setup().clip, &primary, time, skinning, tolerances))
            }
            _ => doc.ghost_evaluation().map(|evaluation| {
                let ghost = evaluation.pose_at(time);
                DrawnPose::from_model(rig, ghost.model.model, &ghost.morph, skinning, tolerances)
            }),
        };
        CurrentPose { pose, primary, ghost }
    }
}
