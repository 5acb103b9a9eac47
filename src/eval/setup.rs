//! What is evaluated besides the rig: the clip, every bone's mode, the layers, the skinning and the unit lengths are
//! measured in. A plain value, compared, stored and serialised: the app's document holds one (and its history the
//! ones before), the command line builds one from its options, an explained fix turns one into another, and
//! [`Evaluation::of`] makes one an evaluation of a rig.

use super::layers::LayerError;
use super::{Evaluation, LayerStack, Layers, SkinningMethod};
use crate::model::{Modes, Rig, Unit};

/// Everything that decides an evaluation of a rig, the rig aside.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Setup {
    /// Index into the rig's clips; `None` for the rest pose.
    pub clip: Option<usize>,
    pub modes: Modes,
    /// The runtime techniques played over the clip (how its keys are interpolated among them).
    pub layers: Layers,
    pub skinning: SkinningMethod,
    /// The unit lengths are measured in (a compared file is measured in its document's); `None`: the rig's own.
    pub unit: Option<Unit>,
}

/// Why a setup does not fit a rig.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SetupError {
    #[error("no animation {index} (the file has {count})")]
    NoClip { index: usize, count: usize },
    #[error("no bone {index} to give its own mode (the rig has {count})")]
    NoBone { index: usize, count: usize },
    #[error(transparent)]
    Layers(#[from] LayerError),
}

impl Setup {
    /// The file as it declares itself: its first clip (the rest pose without one), its declared modes, no layers.
    pub fn declared(rig: &Rig) -> Self {
        Setup { clip: (!rig.clips.is_empty()).then_some(0), ..Setup::default() }
    }

    /// Checks every index against `rig` and prepares the layers (what does not change with time).
    pub fn prepare(&self, rig: &Rig) -> Result<LayerStack, SetupError> {
        let count = rig.clips.len();
        if let Some(index) = self.clip.filter(|&c| c >= count) {
            return Err(SetupError::NoClip { index, count });
        }
        let count = rig.skeleton.len();
        if let Some(index) = self.modes.missing_bone(count) {
            return Err(SetupError::NoBone { index, count });
        }
        Ok(LayerStack::new(rig, &self.layers)?)
    }
}

impl<'a> Evaluation<'a> {
    /// `setup` of `rig`; refused where it names a clip or a bone the rig lacks.
    pub fn of(rig: &'a Rig, setup: &Setup) -> Result<Self, SetupError> {
        Ok(Evaluation::prepared(rig, setup, setup.prepare(rig)?))
    }

    /// `setup` of `rig` through `layers`, what [`Setup::prepare`] made of it for `rig` (prepared once, evaluated
    /// often).
    pub fn prepared(rig: &'a Rig, setup: &Setup, layers: LayerStack) -> Self {
        let clip = setup.clip.and_then(|c| rig.clips.get(c));
        Evaluation::new(rig, clip, &setup.modes.resolve(&rig.skeleton))
            .with_layers(layers)
            .with_skinning(setup.skinning)
            .measured_in(setup.unit)
            .chosen_as(setup.modes.clone())
    }

    /// The setup this evaluation is of: what [`Evaluation::of`] makes it again.
    pub fn setup(&self) -> Setup {
        Setup {
            clip: self.clip.map(|c| self.rig.clips.iter().position(|own| std::ptr::eq(own, c)).unwrap_or(c.index)),
            modes: self.chosen_modes(),
            layers: self.layers().map(|l| l.layers().clone()).unwrap_or_default(),
            skinning: self.skinning,
            unit: self.unit(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::layers::Blend;
    use crate::import::demo_rig;
    use crate::model::{InheritMode, ModeChoice};

    fn forearm_aligned(rig: &Rig) -> Setup {
        let mut modes = Modes::all(ModeChoice::Mode(InheritMode::SegmentCompensate));
        modes.set(&rig.skeleton, rig.skeleton.find("forearm").unwrap(), ModeChoice::Mode(InheritMode::BlenderAligned));
        let blend = Blend { clip: 1, weight: 0.25, sync: true, rotation: Default::default() };
        Setup {
            clip: Some(0),
            modes,
            layers: Layers { blend: Some(blend), ..Layers::default() },
            skinning: SkinningMethod::DualQuaternion,
            unit: "cm".parse().ok(),
        }
    }

    #[test]
    fn an_evaluation_is_its_setup_made() {
        // Made an evaluation and read back, a setup is itself; the evaluation is the one the builders make.
        let rig = demo_rig();
        let setup = forearm_aligned(&rig);
        let evaluation = Evaluation::of(&rig, &setup).unwrap();
        assert_eq!(evaluation.setup(), setup);
        let modes = setup.modes.resolve(&rig.skeleton);
        let built = Evaluation::new(&rig, rig.clips.first(), &modes)
            .with_layers(LayerStack::new(&rig, &setup.layers).unwrap())
            .with_skinning(SkinningMethod::DualQuaternion)
            .measured_in("cm".parse().ok());
        for time in [0.0, 0.37, 1.2] {
            assert_eq!(evaluation.pose_at(time).model.model, built.pose_at(time).model.model, "at {time}");
        }
        assert_eq!(Evaluation::of(&rig, &Setup::declared(&rig)).unwrap().setup(), Setup::declared(&rig));
    }

    #[test]
    fn a_setup_round_trips_through_json() {
        let rig = demo_rig();
        let setup = forearm_aligned(&rig);
        let json = serde_json::to_string(&setup).unwrap();
        assert_eq!(serde_json::from_str::<Setup>(&json).unwrap(), setup);
        assert_eq!(serde_json::from_str::<Setup>("{}").unwrap(), Setup::default());
        assert!(serde_json::from_str::<Setup>(r#"{"unit":-1}"#).is_err(), "a unit is a positive length");
    }

    #[test]
    fn a_setup_naming_what_the_rig_lacks_is_refused() {
        let rig = demo_rig();
        let no_clip = Setup { clip: Some(9), ..Setup::default() };
        assert_eq!(Evaluation::of(&rig, &no_clip).unwrap_err(), SetupError::NoClip { index: 9, count: 2 });
        let mut modes = Modes::default();
        modes.bones.insert(40, InheritMode::BlenderNone);
        let error = Evaluation::of(&rig, &Setup { modes, ..Setup::default() }).unwrap_err();
        assert_eq!(error, SetupError::NoBone { index: 40, count: rig.skeleton.len() });
        let blend = Blend { clip: 5, weight: 0.5, sync: false, rotation: Default::default() };
        let layered = Setup { layers: Layers { blend: Some(blend), ..Layers::default() }, ..Setup::default() };
        assert!(Evaluation::of(&rig, &layered).unwrap_err().to_string().contains("no animation 5"));
    }
}
