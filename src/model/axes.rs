//! Which way is up in a file that does not say (BVH states no axes; a file exported with the wrong ones says
//! wrongly): bonescope's space is Y-up, and a Z-up file is turned into it as every exporter's conversion does.

use glam::{DMat4, DVec3};

use super::Choice;

/// The axis a file's skeleton stands along.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum UpAxis {
    #[default]
    Y,
    Z,
}

impl Choice for UpAxis {
    const ALL: &'static [Self] = &[UpAxis::Y, UpAxis::Z];

    fn id(self) -> &'static str {
        match self {
            UpAxis::Y => "y",
            UpAxis::Z => "z",
        }
    }

    fn description(self) -> &'static str {
        match self {
            UpAxis::Y => "Y up (glTF, Maya, most BVH): taken as it is",
            UpAxis::Z => "Z up (Blender, 3ds Max): turned −90° about X, so Z becomes Y and Y becomes −Z",
        }
    }
}

impl UpAxis {
    /// The turn from a space that is up along this axis into bonescope's Y-up one.
    pub fn to_y_up(self) -> DMat4 {
        match self {
            UpAxis::Y => DMat4::IDENTITY,
            UpAxis::Z => DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2),
        }
    }

    /// The axis `points` (joint positions) spread along most, of Y and Z, where it is clearly the longer one (half
    /// as long again): a standing figure's height; `None` where neither stands out (a figure lying across, a
    /// T-pose as wide as it is tall along the other).
    pub fn standing(points: impl IntoIterator<Item = DVec3>) -> Option<UpAxis> {
        let (lo, hi) = points
            .into_iter()
            .filter(|p| p.is_finite())
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        let extent = hi - lo;
        if !extent.is_finite() {
            return None;
        }
        if extent.y > 1.5 * extent.z {
            Some(UpAxis::Y)
        } else if extent.z > 1.5 * extent.y {
            Some(UpAxis::Z)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_up_turns_as_exporters_turn_it_and_a_figure_stands_along_its_height() {
        // Blender's Z-up, −Y-forward space into glTF's Y-up one: (x, y, z) → (x, z, −y).
        let turned = UpAxis::Z.to_y_up().transform_point3(DVec3::new(1.0, 2.0, 3.0));
        assert!((turned - DVec3::new(1.0, 3.0, -2.0)).length() < 1e-12, "{turned}");
        assert_eq!(UpAxis::Y.to_y_up(), DMat4::IDENTITY);
        let tall = [DVec3::ZERO, DVec3::new(0.3, 1.8, 0.1)];
        assert_eq!(UpAxis::standing(tall), Some(UpAxis::Y));
        assert_eq!(UpAxis::standing(tall.map(|p| DVec3::new(p.x, -p.z, p.y))), Some(UpAxis::Z));
        assert_eq!(UpAxis::standing([DVec3::ZERO, DVec3::new(0.0, 1.0, 1.2)]), None, "neither stands out");
        assert_eq!(UpAxis::standing([]), None);
    }
}
