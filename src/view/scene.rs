//! What the viewport draws, in model space: one or two evaluated poses (the current mode and a ghost mode), the
//! skinned meshes, the bind pose. Built from the library alone, painted by [`super::paint`].

use glam::{DMat4, DVec3};

use super::camera::Bounds;
use super::style::Badge;
use crate::analysis::{Assessment, Findings, Tolerances};
use crate::eval::skinning::skin_meshes_with;
use crate::eval::{MorphPose, SkinningMethod, bind_model_matrices, skin_meshes};
use crate::model::{Choice, Clip, NodeRole, Rig, Span};

/// Which bones have their axis triads drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Triads {
    None,
    /// The selected bones and their chains (each up to its root).
    Selected,
    /// The selected bones' chains and every stretched bone: the frames that show something.
    #[default]
    Stretched,
    All,
}

impl Choice for Triads {
    const ALL: &'static [Triads] = &[Triads::None, Triads::Selected, Triads::Stretched, Triads::All];

    fn id(self) -> &'static str {
        match self {
            Triads::None => "none",
            Triads::Selected => "selected",
            Triads::Stretched => "stretched",
            Triads::All => "all",
        }
    }

    fn description(self) -> &'static str {
        match self {
            Triads::None => "no axis triads",
            Triads::Selected => "the selected bones and their chains up to the root",
            Triads::Stretched => "the selected bones' chains and every stretched bone",
            Triads::All => "every bone",
        }
    }
}

/// What to show, as toggled in the viewport's toolbar (persisted with the settings).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SceneOptions {
    pub grid: bool,
    pub bones: bool,
    pub mesh: bool,
    /// The mesh painted by the shear each vertex's bones give it ([`crate::eval::skinning::vertex_shears`]).
    pub shear: bool,
    pub wireframe: bool,
    /// Whose axis triads are drawn, from their model matrix columns (a sheared frame loses its right angles).
    pub triads: Triads,
    /// A unit box per bone transformed by its model matrix (shear shows as a slanted parallelepiped).
    pub boxes: bool,
    pub names: bool,
    pub bind_pose: bool,
    /// Cameras, lights, meshes' nodes and other helpers the file carries beside the figure, drawn as bones too.
    pub helpers: bool,
    pub legend: bool,
    /// How meshes are skinned: as the file declares, or linear / dual quaternion everywhere (engines differ).
    pub skinning: SkinningMethod,
}

impl Default for SceneOptions {
    fn default() -> Self {
        SceneOptions {
            grid: true,
            bones: true,
            mesh: true,
            shear: true,
            wireframe: false,
            triads: Triads::default(),
            boxes: false,
            names: false,
            bind_pose: false,
            helpers: false,
            legend: true,
            skinning: SkinningMethod::AsFile,
        }
    }
}

impl SceneOptions {
    /// The names `--show` takes, in toolbar order.
    pub const NAMES: [&'static str; 11] =
        ["bones", "axes", "boxes", "mesh", "shear", "wireframe", "bind-pose", "helpers", "names", "grid", "legend"];

    /// The switch called `name`, but `axes`, which is a choice.
    fn switch(&mut self, name: &str) -> Option<&mut bool> {
        Some(match name {
            "bones" => &mut self.bones,
            "boxes" => &mut self.boxes,
            "mesh" => &mut self.mesh,
            "shear" => &mut self.shear,
            "wireframe" => &mut self.wireframe,
            "bind-pose" => &mut self.bind_pose,
            "helpers" => &mut self.helpers,
            "names" => &mut self.names,
            "grid" => &mut self.grid,
            "legend" => &mut self.legend,
            _ => return None,
        })
    }

    /// Applies a comma-separated list: `bones,axes` shows exactly those; `+boxes,-grid` changes these defaults.
    /// `axes` is every bone's triad, `-axes` none, `axes=stretched` a choice of [`Triads`]; `shear` paints the mesh,
    /// so it shows the mesh too unless the list says `-mesh` after it.
    pub fn parse_list(list: &str) -> Result<Self, String> {
        let items: Vec<&str> = list.split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
        let relative = items.iter().all(|s| s.starts_with(['+', '-']));
        let mut options = if relative { SceneOptions::default() } else { SceneOptions::none() };
        for item in items {
            let (on, name) = match item.split_at_checked(1) {
                Some(("-", name)) => (false, name),
                Some(("+", name)) => (true, name),
                _ => (true, item),
            };
            options.set(name, on)?;
        }
        Ok(options)
    }

    /// Turns the item `name` of [`SceneOptions::parse_list`] on or off.
    fn set(&mut self, name: &str, on: bool) -> Result<(), String> {
        if let Some(choice) = name.strip_prefix("axes=") {
            let known = Triads::ALL.iter().map(|t| t.id()).collect::<Vec<_>>().join(", ");
            self.triads = Triads::from_id(choice).ok_or_else(|| format!("unknown axes `{choice}` (known: {known})"))?;
            return Ok(());
        }
        match name {
            "axes" => self.triads = if on { Triads::All } else { Triads::None },
            "shear" if on => (self.shear, self.mesh) = (true, true),
            _ => {
                let known = Self::NAMES.join(", ");
                *self.switch(name).ok_or_else(|| format!("unknown item `{name}` (known: {known})"))? = on;
            }
        }
        Ok(())
    }

    fn none() -> Self {
        SceneOptions {
            grid: false,
            bones: false,
            mesh: false,
            shear: false,
            wireframe: false,
            triads: Triads::None,
            boxes: false,
            names: false,
            bind_pose: false,
            helpers: false,
            legend: false,
            skinning: SkinningMethod::AsFile,
        }
    }

    /// Whether the mesh is drawn painted by shear.
    pub fn paints_shear(&self) -> bool {
        self.mesh && self.shear
    }
}

/// One evaluated pose: model matrices, findings and skinned meshes.
#[derive(Clone, Debug, Default)]
pub struct DrawnPose {
    pub model: Vec<DMat4>,
    pub findings: Vec<Findings>,
    /// Per bone, its shear angle in degrees (how severe a stretched bone is).
    pub shear_deg: Vec<f64>,
    /// Per mesh of the rig, vertex positions in model space.
    pub meshes: Vec<Vec<DVec3>>,
}

impl DrawnPose {
    /// The findings of `model` and the meshes morphed by `morph` and skinned by `skinning` at it.
    pub fn from_model(
        rig: &Rig,
        model: Vec<DMat4>,
        morph: &MorphPose,
        skinning: SkinningMethod,
        tolerances: &Tolerances,
    ) -> DrawnPose {
        let assessments = Assessment::all(&model, tolerances);
        let findings = assessments.iter().map(|a| a.findings).collect();
        let shear_deg = assessments.iter().map(|a| a.shear_deg).collect();
        let meshes = skin_meshes_with(rig, &model, morph, skinning);
        DrawnPose { model, findings, shear_deg, meshes }
    }

    /// The colour of the bone's most important finding, stretched bones by their shear; `None` without one.
    pub fn finding_color(&self, bone: usize) -> Option<egui::Color32> {
        let badge = Badge::primary(self.findings.get(bone)?)?;
        Some(badge.color_for_shear(self.shear_deg.get(bone).copied().unwrap_or(0.0)))
    }

    /// The bind pose to draw beside `pose`: where the skins were bound, in model space. A rig without skins (motion
    /// capture) has only its rest pose, which stands wherever the file's offsets put it (a BVH's at the origin,
    /// hips on the floor and legs below it, while the take walks away): each root is moved to where `pose` has it,
    /// so the rest skeleton stands over the character.
    pub fn bind(rig: &Rig, pose: &DrawnPose) -> DrawnPose {
        let mut model = bind_model_matrices(rig);
        if rig.skins.is_empty() && model.len() == pose.model.len() {
            let mut shift = vec![DVec3::ZERO; model.len()];
            for (bone, b) in rig.skeleton.bones().iter().enumerate() {
                shift[bone] = b.parent.map_or_else(|| pose.head(bone) - model[bone].w_axis.truncate(), |p| shift[p]);
                model[bone].w_axis += shift[bone].extend(0.0);
            }
        }
        DrawnPose { model, ..DrawnPose::default() }
    }

    pub fn head(&self, bone: usize) -> DVec3 {
        self.model[bone].w_axis.truncate()
    }
}

/// Everything the viewport draws for one frame.
#[derive(Clone, Debug)]
pub struct Scene<'a> {
    pub rig: &'a Rig,
    pub primary: DrawnPose,
    /// The same pose under a second inheritance mode, drawn translucent over the first.
    pub ghost: Option<DrawnPose>,
    /// What the ghost is, for the legend.
    pub ghost_label: String,
    /// Lines naming what is shown (file, clip, time, modes, layers), drawn in the corner opposite the legend.
    pub caption: Vec<String>,
    /// The bind pose (from the skins' inverse bind matrices in model space, the rest pose elsewhere), drawn as a
    /// translucent skeleton where the character is.
    pub bind_pose: Option<DrawnPose>,
    pub selected: Vec<usize>,
    pub options: SceneOptions,
    /// How long axis triads and boxes are drawn, in model units, for a bone of the rig's typical scale.
    pub gizmo_size: f64,
    /// The same length in the units of a bone of the rig's typical scale: a triad is `model`'s columns times this,
    /// so a centimetre rig under a 0.01 conversion gets triads of `gizmo_size`, while a bone scaled or sheared
    /// relative to the rest shows it in the lengths and angles of its axes.
    pub gizmo_unit: f64,
    /// Below this shear, in degrees, a vertex is painted the mesh's own colour: the tolerance under which a bone is
    /// not flagged as stretched ([`Tolerances::min_shear_deg`]).
    pub neutral_shear_deg: f64,
    /// Each bone's first child of the figure (a helper below a joint, a camera's target, say, does not end its
    /// bone), found once: the tail of every bone is asked for each frame.
    first_child: Vec<Option<usize>>,
}

impl<'a> Scene<'a> {
    pub fn new(rig: &'a Rig, primary: DrawnPose, options: SceneOptions) -> Self {
        let gizmo_size = gizmo_size(rig);
        let gizmo_unit = gizmo_size / typical_scale(rig);
        let figure = rig.skeleton.figure();
        let mut first_child = vec![None; rig.skeleton.len()];
        for (bone, b) in rig.skeleton.bones().iter().enumerate().rev() {
            if let Some(parent) = b.parent.filter(|&p| figure[bone] || !figure[p]) {
                first_child[parent] = Some(bone);
            }
        }
        Scene {
            rig,
            primary,
            ghost: None,
            ghost_label: String::new(),
            caption: Vec::new(),
            bind_pose: None,
            selected: Vec::new(),
            options,
            gizmo_size,
            gizmo_unit,
            neutral_shear_deg: Tolerances::default().min_shear_deg,
            first_child,
        }
    }

    /// Whether `bone` has its axis triad drawn, as [`SceneOptions::triads`] chooses; `chain` marks the selected bones
    /// and their ancestors ([`Scene::selected_chains`]).
    pub fn shows_triad(&self, drawn: &DrawnPose, chain: &[bool], bone: usize) -> bool {
        let in_chain = chain.get(bone).copied().unwrap_or(false);
        match self.options.triads {
            Triads::None => false,
            Triads::Selected => in_chain,
            Triads::Stretched => in_chain || drawn.findings.get(bone).is_some_and(|f| f.stretched),
            Triads::All => true,
        }
    }

    /// Per bone, whether it is selected or above a selected bone.
    pub fn selected_chains(&self) -> Vec<bool> {
        let mut chain = vec![false; self.rig.skeleton.len()];
        for &selected in &self.selected {
            let mut bone = Some(selected).filter(|&b| b < chain.len());
            while let Some(b) = bone.filter(|&b| !chain[b]) {
                chain[b] = true;
                bone = self.rig.skeleton.parent(b);
            }
        }
        chain
    }

    /// Whether `bone` is drawn: a bone of the figure, a helper when they are shown, or anything selected (picked in
    /// the outliner's list of helpers, a camera shows where it is).
    pub fn shows(&self, bone: usize) -> bool {
        self.rig.skeleton.figure().get(bone).copied().unwrap_or(false)
            || self.options.helpers
            || self.selected.contains(&bone)
    }

    /// The tail of a bone: the head of its first child, or for a leaf a third of its parent's length further on. An
    /// end site has none: it is the tail of its parent's bone.
    pub fn tail(&self, drawn: &DrawnPose, bone: usize) -> Option<DVec3> {
        if let Some(child) = self.first_child[bone] {
            return Some(drawn.head(child));
        }
        if self.rig.skeleton.bone(bone).role == NodeRole::EndSite {
            return None;
        }
        let parent = self.rig.skeleton.parent(bone)?;
        let along = drawn.head(bone) - drawn.head(parent);
        (along.length() > 1e-9).then(|| drawn.head(bone) + along * 0.35)
    }

    /// What framing the camera on this pose should keep in view: the figure's joints and the meshes.
    pub fn bounds(&self) -> Option<Bounds> {
        let heads = self
            .primary
            .model
            .iter()
            .zip(self.rig.skeleton.figure())
            .filter(|(_, f)| **f)
            .map(|(m, _)| m.w_axis.truncate());
        let vertices = self.primary.meshes.iter().flatten().copied();
        Bounds::of(heads.chain(vertices))
    }
}

/// Axis triads and boxes are drawn at 40 % of the median bone length of the rest pose, so they read at the scale
/// of the rig whatever its units.
fn gizmo_size(rig: &Rig) -> f64 {
    let model = rig.skeleton.rest_model_matrices();
    let mut lengths: Vec<f64> = rig
        .skeleton
        .bones()
        .iter()
        .enumerate()
        .filter_map(|(b, bone)| bone.parent.map(|p| (model[b].w_axis - model[p].w_axis).truncate().length()))
        .filter(|l| *l > 1e-9)
        .collect();
    lengths.sort_by(f64::total_cmp);
    lengths.get(lengths.len() / 2).map_or_else(|| rest_bounds(rig).map_or(0.1, |b| b.radius() * 0.1), |l| l * 0.4)
}

/// The rig's typical uniform scale: the median over bones of the cube root of `|det|` of the rest model matrices
/// (0.01 for a centimetre file converted to metres at its top node, 1 for most rigs); 1 when none is usable.
pub fn typical_scale(rig: &Rig) -> f64 {
    let mut scales: Vec<f64> = rig
        .skeleton
        .rest_model_matrices()
        .iter()
        .map(|m| glam::DMat3::from_mat4(*m).determinant().abs().cbrt())
        .filter(|s| s.is_finite() && *s > 1e-12)
        .collect();
    scales.sort_by(f64::total_cmp);
    scales.get(scales.len() / 2).copied().unwrap_or(1.0)
}

/// What the viewport frames of a clip: the figure in every posture it takes, and the bone it travels with.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Motion {
    /// The figure's joints (those its anchor carries, where it travels) and skinned meshes at times through the
    /// clip, each pose moved over the ground so that its `anchor` stands above the origin: a walk is framed as one
    /// figure-sized box of its postures, not as its whole path (where the figure would be a speck at one end).
    pub points: Vec<DVec3>,
    /// The bone whose course over the ground the figure travels along (the hips of a walk), where it travels more
    /// than a quarter of its size; `None` for a clip played in place, whose points are where they are.
    pub anchor: Option<usize>,
}

/// The motion of the clip: the pose sampled at `samples` evenly spaced times over `span` by `pose_at` (model
/// matrices). Only the joints that matter count (the figure's, [`Skeleton::figure`](crate::model::Skeleton::figure)),
/// and the skinned meshes. A camera framed on the points and following the anchor over the ground need not zoom
/// while the clip plays.
pub fn motion(
    rig: &Rig,
    clip: Option<&Clip>,
    span: Span,
    samples: usize,
    mut pose_at: impl FnMut(f64) -> Vec<DMat4>,
) -> Motion {
    let framed = rig.skeleton.figure();
    let mut morph = MorphPose::default();
    let poses: Vec<(Vec<DVec3>, Vec<DVec3>)> = (0..samples.max(1))
        .map(|i| {
            let time = span.start + span.length() * i as f64 / (samples.max(2) - 1) as f64;
            let model = pose_at(time);
            morph.evaluate(clip, time);
            let meshes = skin_meshes(rig, &model, &morph).into_iter().flatten().filter(|p| p.is_finite()).collect();
            (model.iter().map(|m| m.w_axis.truncate()).collect(), meshes)
        })
        .collect();
    let anchor = travelling_bone(rig, poses.iter().map(|(joints, _)| joints.as_slice()));
    // A travelling figure is what its anchor carries: a reference node left at the origin is not framed.
    let framed: Vec<bool> = (0..rig.skeleton.len())
        .map(|bone| framed[bone] && anchor.is_none_or(|a| rig.skeleton.is_in_subtree(bone, a)))
        .collect();
    let mut points = Vec::new();
    for (joints, meshes) in poses {
        let offset = anchor.map_or(DVec3::ZERO, |bone| ground(joints[bone]));
        points.extend(joints.iter().zip(&framed).filter(|(_, f)| **f).map(|(p, _)| *p - offset));
        points.extend(meshes.iter().map(|p| *p - offset));
    }
    Motion { points, anchor }
}

/// Where a point is over the ground (Y is up in the view).
pub fn ground(p: DVec3) -> DVec3 {
    DVec3::new(p.x, 0.0, p.z)
}

/// The bone the figure travels with over these poses (each the heads of every bone): the topmost bone carrying at
/// least half of the figure whose course over the ground spans more than a quarter of the figure's size (a
/// reference node that stays at the origin while the hips walk away is passed over; a waving hand carries too
/// little of the figure to count). `None` when the figure stays in place.
fn travelling_bone<'a>(rig: &Rig, poses: impl Iterator<Item = &'a [DVec3]> + Clone) -> Option<usize> {
    let skeleton = &rig.skeleton;
    let figure = skeleton.figure();
    // Figure bones at and below each bone (parents come before children, so one backwards pass counts them).
    let mut carried: Vec<usize> = figure.iter().map(|&f| usize::from(f)).collect();
    for bone in (0..skeleton.len()).rev() {
        if let Some(parent) = skeleton.parent(bone) {
            carried[parent] += carried[bone];
        }
    }
    let whole = figure.iter().filter(|f| **f).count();
    let posture = |joints: &[DVec3]| {
        Bounds::of(joints.iter().zip(figure).filter(|(_, f)| **f).map(|(p, _)| *p)).map_or(0.0, |b| b.radius() * 2.0)
    };
    let size = poses.clone().map(posture).fold(0.0, f64::max);
    let course =
        |bone: usize| Bounds::of(poses.clone().map(|joints| ground(joints[bone]))).map_or(0.0, |b| b.radius() * 2.0);
    (0..skeleton.len()).find(|&bone| figure[bone] && carried[bone] * 2 >= whole && course(bone) > size * 0.25)
}

/// The bounds of the rest pose's joints and meshes.
pub fn rest_bounds(rig: &Rig) -> Option<Bounds> {
    let model = rig.skeleton.rest_model_matrices();
    let meshes = skin_meshes(rig, &model, &MorphPose::default());
    Bounds::of(model.iter().map(|m| m.w_axis.truncate()).chain(meshes.into_iter().flatten()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_show_list_names_exactly_what_is_shown_or_changes_the_defaults() {
        let only = SceneOptions::parse_list("bones, boxes").unwrap();
        assert_eq!(only, SceneOptions { bones: true, boxes: true, ..SceneOptions::none() });
        let changed = SceneOptions::parse_list("+boxes,-grid").unwrap();
        assert_eq!(changed, SceneOptions { boxes: true, grid: false, ..SceneOptions::default() });
        assert_eq!(SceneOptions::parse_list("").unwrap(), SceneOptions::default());
        let error = SceneOptions::parse_list("bones,sheer").unwrap_err();
        assert!(error.contains("`sheer`") && error.contains("bind-pose"), "{error}");
        // `shear` paints the mesh, so it shows it; the triads are a choice.
        let painted = SceneOptions::parse_list("shear").unwrap();
        assert_eq!(painted, SceneOptions { mesh: true, shear: true, ..SceneOptions::none() });
        assert_eq!(SceneOptions::parse_list("+axes").unwrap().triads, Triads::All);
        assert_eq!(SceneOptions::parse_list("-axes").unwrap().triads, Triads::None);
        assert_eq!(SceneOptions::parse_list("bones,axes=selected").unwrap().triads, Triads::Selected);
        assert!(SceneOptions::parse_list("axes=some").unwrap_err().contains("stretched"));
    }

    /// A joint `y` above its parent at rest.
    fn joint(name: &str, parent: Option<usize>, y: f64) -> crate::model::Bone {
        let rest = crate::model::Transform::from_trs(DVec3::new(0.0, y, 0.0), glam::DQuat::IDENTITY, DVec3::ONE);
        crate::model::Bone::joint(name, parent, rest)
    }

    /// A rig of these joints, no mesh.
    fn skeleton_rig(joints: Vec<crate::model::Bone>) -> Rig {
        Rig { skeleton: crate::model::Skeleton::new(joints).unwrap(), ..Rig::default() }
    }

    #[test]
    fn a_walk_is_framed_as_its_postures_and_followed_along_its_hips() {
        // A reference node staying at the origin, the hips walking 4 along X over 2 s, a knee and a head on them.
        let rig = skeleton_rig(vec![
            joint("reference", None, 0.0),
            joint("hips", Some(0), 1.0),
            joint("knee", Some(1), -0.5),
            joint("head", Some(1), 0.7),
        ]);
        let span = Span { start: 0.0, end: 2.0 };
        let walking = |speed: f64| {
            move |t: f64| {
                let hips = DMat4::from_translation(DVec3::new(speed * t, 1.0, 0.0));
                vec![
                    DMat4::IDENTITY,
                    hips,
                    hips * DMat4::from_translation(-0.5 * DVec3::Y),
                    hips * DMat4::from_translation(0.7 * DVec3::Y),
                ]
            }
        };
        let walk = motion(&rig, None, span, 5, walking(2.0));
        assert_eq!(walk.anchor, Some(1), "the hips, not the reference node that stays behind");
        let framed = Bounds::of(walk.points.iter().copied()).unwrap();
        assert!(framed.min.x >= -1e-12 && framed.max.x <= 1e-12, "one figure's width, not the path: {framed:?}");
        // Swaying in place, a few centimetres: framed where it is, not followed.
        let sway = motion(&rig, None, span, 5, walking(0.05));
        assert_eq!(sway.anchor, None);
        assert!(Bounds::of(sway.points.iter().copied()).unwrap().max.x > 0.09);
    }

    #[test]
    fn a_rig_without_skins_has_its_rest_pose_drawn_where_the_pose_stands() {
        // Mocap: hips at the origin at rest, a knee 0.5 below. The take has the hips at (5, 1, 2), turned.
        let rig = skeleton_rig(vec![joint("hips", None, 0.0), joint("knee", Some(0), -0.5)]);
        let hips = DMat4::from_rotation_translation(glam::DQuat::from_rotation_y(1.0), DVec3::new(5.0, 1.0, 2.0));
        let pose = DrawnPose {
            model: vec![hips, hips * DMat4::from_translation(DVec3::new(0.0, -0.5, 0.0))],
            ..DrawnPose::default()
        };
        let bind = DrawnPose::bind(&rig, &pose);
        // Moved, not turned: the rest pose's own orientation, its hips where the take's are.
        assert!(bind.head(0).abs_diff_eq(DVec3::new(5.0, 1.0, 2.0), 1e-12), "{}", bind.head(0));
        assert!(bind.head(1).abs_diff_eq(DVec3::new(5.0, 0.5, 2.0), 1e-12), "{}", bind.head(1));
        // With skins the bind pose is where the mesh was bound, wherever the pose is.
        let demo = crate::import::demo_rig();
        let far = DrawnPose {
            model: vec![DMat4::from_translation(DVec3::splat(9.0)); demo.skeleton.len()],
            ..DrawnPose::default()
        };
        assert_eq!(DrawnPose::bind(&demo, &far).model, bind_model_matrices(&demo));
    }

    /// The names of the bones whose triads `scene` draws.
    fn with_triads(scene: &Scene) -> Vec<String> {
        let chain = scene.selected_chains();
        let bones = scene.rig.skeleton.bones().iter().enumerate();
        bones
            .filter(|(b, _)| scene.shows_triad(&scene.primary, &chain, *b))
            .map(|(_, bone)| bone.name.clone())
            .collect()
    }

    #[test]
    fn triads_go_to_the_selected_chain_and_the_stretched_bones() {
        // The demo's chain: shoulder → upper_arm → forearm → hand; the upper arm stretched.
        let rig = crate::import::demo_rig();
        let find = |name: &str| rig.skeleton.find(name).unwrap();
        let mut findings = vec![Findings::default(); rig.skeleton.len()];
        findings[find("upper_arm")].stretched = true;
        let mut scene = Scene::new(&rig, DrawnPose { findings, ..DrawnPose::default() }, SceneOptions::default());
        assert_eq!(with_triads(&scene), ["upper_arm"], "nothing selected: the stretched bone alone");
        scene.selected = vec![find("forearm")];
        assert_eq!(with_triads(&scene), ["shoulder", "upper_arm", "forearm"], "and the chain up to the root");
        scene.options.triads = Triads::Selected;
        scene.selected = vec![find("shoulder")];
        assert_eq!(with_triads(&scene), ["shoulder"]);
        scene.options.triads = Triads::None;
        assert!(with_triads(&scene).is_empty());
        scene.options.triads = Triads::All;
        assert_eq!(with_triads(&scene).len(), rig.skeleton.len());
    }

    #[test]
    fn the_typical_scale_is_the_median_uniform_scale_of_the_rest_pose() {
        use crate::model::{Bone, InheritMode, NodeRole, Skeleton, Transform};
        // A centimetre rig under a 0.01 conversion at its top: every bone's model matrix scales by 0.01, one bone
        // is stretched (2, 1, 0.5: cube root of the determinant 1) relative to it.
        let bone = |name: &str, parent: Option<usize>, scale: glam::DVec3| Bone {
            name: name.into(),
            node: 0,
            parent,
            rest: Transform::from_trs(glam::DVec3::X, glam::DQuat::IDENTITY, scale),
            inherit: InheritMode::Full,
            role: NodeRole::Joint,
        };
        let skeleton = Skeleton::new(vec![
            bone("root", None, glam::DVec3::splat(0.01)),
            bone("a", Some(0), glam::DVec3::ONE),
            bone("b", Some(1), glam::DVec3::new(2.0, 1.0, 0.5)),
        ])
        .unwrap();
        let rig = Rig { skeleton, ..Rig::default() };
        assert!((typical_scale(&rig) - 0.01).abs() < 1e-12, "{}", typical_scale(&rig));
        assert_eq!(typical_scale(&Rig::default()), 1.0);
    }
}
