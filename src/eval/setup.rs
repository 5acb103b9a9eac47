//! What is evaluated besides the rig: the clip, every bone's mode, the layers, the skinning and the unit lengths are
//! measured in. A plain value, compared, stored and serialised: the app's document holds one (and its history the
//! ones before), the command line builds one from its options, an explained fix turns one into another, and
//! [`Evaluation::of`] makes one an evaluation of a rig.

use super::layers::LayerError;
use super::{Evaluation, Hierarchy, LayerStack, Layers, SkinningMethod};
use crate::model::{Choice, Modes, Rig, Skeleton, Transform, Unit};

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
    /// The file as it declares itself: the clip it opens on ([`Rig::opening_clip`]; the rest pose without one), its
    /// declared modes, no layers.
    pub fn declared(rig: &Rig) -> Self {
        Setup { clip: rig.opening_clip(), ..Setup::default() }
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

impl Setup {
    /// What changed from `before` to this setup of `rig`, in a few words for people ("forearm → blender-aligned",
    /// "every bone → full", "animation walk", "blend on"); empty where nothing did.
    pub fn change_from(&self, before: &Setup, rig: &Rig) -> String {
        let mut parts = Vec::new();
        if self.clip != before.clip {
            let clip = self.clip.and_then(|c| rig.clips.get(c));
            parts.push(clip.map_or_else(|| "rest pose".to_owned(), |c| format!("animation {}", c.label())));
        }
        if self.modes != before.modes {
            parts.push(mode_change(&before.modes, &self.modes, &rig.skeleton));
        }
        parts.extend(layer_changes(&before.layers, &self.layers, &rig.skeleton));
        if self.skinning != before.skinning {
            parts.push(format!("skinning {}", self.skinning.id()));
        }
        if self.unit != before.unit {
            parts.push(self.unit.map_or_else(|| "the rig's own unit".to_owned(), |u| format!("unit {u}")));
        }
        parts.join(", ")
    }
}

impl Setup {
    /// The bones whose evaluation this setup changes from `before` by name (a mode, a scale made uniform, a shake,
    /// a target), parents first: where an undo shows its step. Empty for a change of the whole clip (another clip,
    /// a blend) or of every bone.
    pub fn changed_bones(&self, before: &Setup, skeleton: &Skeleton) -> Vec<usize> {
        let (old, new) = (before.modes.resolve(skeleton), self.modes.resolve(skeleton));
        let mut bones: Vec<usize> = (0..new.len()).filter(|&b| old.get(b) != new.get(b)).collect();
        let (a, b) = (&before.layers, &self.layers);
        bones.extend(a.uniform_scale.iter().filter(|x| !b.uniform_scale.contains(x)));
        bones.extend(b.uniform_scale.iter().filter(|x| !a.uniform_scale.contains(x)));
        if a.shake != b.shake {
            bones.extend(a.shake.iter().chain(&b.shake).map(|s| s.bone));
        }
        bones.extend(a.targets.iter().filter(|t| !b.targets.contains(t)).map(|t| t.bone));
        bones.extend(b.targets.iter().filter(|t| !a.targets.contains(t)).map(|t| t.bone));
        bones.sort_unstable();
        bones.dedup();
        if bones.len() == skeleton.len() { Vec::new() } else { bones }
    }
}

/// The modes `after` gives, as it differs from `before`: every bone's, one bone's, a subtree's, or a count.
fn mode_change(before: &Modes, after: &Modes, skeleton: &Skeleton) -> String {
    let (old, new) = (before.resolve(skeleton), after.resolve(skeleton));
    let changed: Vec<usize> = (0..new.len()).filter(|&b| old.get(b) != new.get(b)).collect();
    let choice = |bone: usize| after.bones.get(&bone).map_or(after.all.id(), |m| m.id());
    let name = |bone: usize| skeleton.bone(bone).name.as_str();
    match changed.as_slice() {
        _ if after.bones.is_empty() && after.all != before.all => format!("every bone → {}", after.all.id()),
        [] => format!("modes → {}", after.label()),
        [bone] => format!("{} → {}", name(*bone), choice(*bone)),
        [top, ..] if skeleton.subtree(*top) == changed => format!("{}'s subtree → {}", name(*top), choice(*top)),
        bones => format!("{} bones' modes", bones.len()),
    }
}

/// Each layer `after` changes from `before`: turned on or off, or changed.
fn layer_changes(before: &Layers, after: &Layers, skeleton: &Skeleton) -> Vec<String> {
    let mut parts = Vec::new();
    let mut toggled = |name: &str, was: bool, is: bool, same: bool| match (was, is) {
        (false, true) => parts.push(format!("{name} on")),
        (true, false) => parts.push(format!("{name} off")),
        _ if !same => parts.push(name.to_owned()),
        _ => {}
    };
    // A weight is a slider's: its step says where it was left ("bind weight 0.50"), as a name never could.
    let bind = format!("bind weight {:.2}", after.bind_weight);
    toggled(&bind, false, false, before.bind_weight == after.bind_weight);
    let interpolation = before.interpolation == after.interpolation;
    toggled("interpolation", false, false, interpolation);
    let blend = weight_alone(before.blend, after.blend, |b| &mut b.weight).map(|w| format!("blend weight {w:.2}"));
    toggled(
        blend.as_deref().unwrap_or("blend"),
        before.blend.is_some(),
        after.blend.is_some(),
        before.blend == after.blend,
    );
    let additive =
        weight_alone(before.additive, after.additive, |a| &mut a.weight).map(|w| format!("additive weight {w:.2}"));
    let same = before.additive == after.additive;
    toggled(additive.as_deref().unwrap_or("additive"), before.additive.is_some(), after.additive.is_some(), same);
    toggled("crossfade", before.crossfade.is_some(), after.crossfade.is_some(), before.crossfade == after.crossfade);
    toggled("shake", before.shake.is_some(), after.shake.is_some(), before.shake == after.shake);
    toggled("targets", !before.targets.is_empty(), !after.targets.is_empty(), before.targets == after.targets);
    let name = |bone: &usize| skeleton.bones().get(*bone).map_or("?", |b| b.name.as_str());
    for bone in after.uniform_scale.iter().filter(|b| !before.uniform_scale.contains(b)) {
        parts.push(format!("{}'s scale made uniform", name(bone)));
    }
    for bone in before.uniform_scale.iter().filter(|b| !after.uniform_scale.contains(b)) {
        parts.push(format!("{}'s scale as authored", name(bone)));
    }
    parts
}

/// The weight of a layer on before and after whose weight alone changed (a slider dragged); `None` otherwise.
fn weight_alone<T: Copy + PartialEq>(
    before: Option<T>,
    after: Option<T>,
    weight: fn(&mut T) -> &mut f64,
) -> Option<f64> {
    let (mut before, mut after) = (before?, after?);
    let (was, is) = (*weight(&mut before), *weight(&mut after));
    *weight(&mut before) = is;
    (was != is && before == after).then_some(is)
}

impl<'a> Evaluation<'a> {
    /// `setup` of `rig`; refused where it names a clip or a bone the rig lacks.
    pub fn of(rig: &'a Rig, setup: &Setup) -> Result<Self, SetupError> {
        Ok(Evaluation::prepared(rig, setup, setup.prepare(rig)?))
    }

    /// [`Evaluation::of`], given the rig's bind pose ([`super::bind_pose`]: where the Blender modes' bones rest):
    /// found once for the many setups of one rig a caller evaluates.
    pub fn of_bound(rig: &'a Rig, setup: &Setup, bind_pose: &[Transform]) -> Result<Self, SetupError> {
        let hierarchy = Hierarchy::of_rig_bound(rig, &setup.modes.resolve(&rig.skeleton), Some(bind_pose));
        Ok(Evaluation::with_hierarchy(rig, setup, setup.prepare(rig)?, hierarchy))
    }

    /// `setup` of `rig` through `layers`, what [`Setup::prepare`] made of it for `rig` (prepared once, evaluated
    /// often).
    pub fn prepared(rig: &'a Rig, setup: &Setup, layers: LayerStack) -> Self {
        let hierarchy = Hierarchy::of_rig_bound(rig, &setup.modes.resolve(&rig.skeleton), None);
        Evaluation::with_hierarchy(rig, setup, layers, hierarchy)
    }

    /// `setup` of `rig` through `layers`, its modes made `hierarchy`.
    fn with_hierarchy(rig: &'a Rig, setup: &Setup, layers: LayerStack, hierarchy: Hierarchy) -> Self {
        let clip = setup.clip.and_then(|c| rig.clips.get(c));
        Evaluation::under(rig, clip, hierarchy)
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
            .unwrap()
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

    #[test]
    fn a_change_of_setup_is_said_in_a_few_words() {
        let rig = demo_rig();
        let skeleton = &rig.skeleton;
        let (forearm, upper_arm) = (skeleton.find("forearm").unwrap(), skeleton.find("upper_arm").unwrap());
        let before = Setup::declared(&rig);
        let with = |f: &dyn Fn(&mut Setup)| {
            let mut after = before.clone();
            f(&mut after);
            after.change_from(&before, &rig)
        };
        assert_eq!(with(&|_| {}), "");
        let aligned = ModeChoice::Mode(InheritMode::BlenderAligned);
        assert_eq!(with(&|s| s.modes.set(skeleton, forearm, aligned)), "forearm → blender-aligned");
        let subtree = |s: &mut Setup| {
            (0..skeleton.len())
                .filter(|&b| skeleton.is_in_subtree(b, upper_arm))
                .for_each(|b| s.modes.set(skeleton, b, aligned))
        };
        assert_eq!(with(&subtree), "upper_arm's subtree → blender-aligned");
        assert_eq!(with(&|s| s.modes = Modes::all(aligned)), "every bone → blender-aligned");
        assert_eq!(with(&|s| s.clip = Some(1)), "animation bend");
        assert_eq!(with(&|s| s.layers.make_scale_uniform(upper_arm)), "upper_arm's scale made uniform");
        let blend = Blend { clip: 1, weight: 0.5, sync: false, rotation: Default::default() };
        assert_eq!(with(&|s| s.layers.blend = Some(blend)), "blend on");
        assert_eq!(
            with(&|s| {
                s.layers.bind_weight = 0.5;
                s.clip = None;
            }),
            "rest pose, bind weight 0.50"
        );
        let lighter = |s: &mut Setup| {
            s.layers.blend = Some(Blend { weight: 0.25, ..blend });
        };
        let blended = Setup { layers: Layers { blend: Some(blend), ..Layers::default() }, ..before.clone() };
        let mut after = blended.clone();
        lighter(&mut after);
        assert_eq!(after.change_from(&blended, &rig), "blend weight 0.25", "a slider's step names its value");
    }
}
