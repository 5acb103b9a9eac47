//! Baking any scale inheritance into plain glTF: the fix for the shear bonescope diagnoses.
//!
//! A glTF node is translation·rotation·scale, and glTF composes nodes with full inheritance, so a bone whose model
//! matrix `W` shears under its parent cannot be one node. It can be two. Shoemake's decomposition of the local matrix
//! a bone needs, `L = W'_parent⁻¹·W = T·R·U·K·Uᵀ` (seed 000: `U` is the "stretch quaternion"), splits as
//!
//! ```text
//! L = (T · (R·U) · K) · (Uᵀ)
//!      └─ helper node ─┘  └ the bone's own node: a rotation
//! ```
//!
//! so a helper node `<bone>.stretch` carrying `T`, `R·U`, `K` between the bone and its parent, with the bone
//! carrying `Uᵀ`, reproduces `W` exactly in any engine that composes glTF nodes. Bones whose `U` never matters get
//! no helper. That is [`Strategy::Exact`]; [`Strategy::Trs`] keeps one node per bone, each the closest TRS to what it
//! needs under its already-baked parent, for runtimes whose transforms cannot shear.
//!
//! The steps: sample every clip at its frames, key times and the midpoints between ([`times`]); solve each bone's
//! nodes at each sample ([`nodes`]); keep the fewest keys that reproduce the samples within the tolerance ([`keys`]);
//! and write the scene ([`document`], [`glb`]). [`report`] measures the result against the source.

mod document;
mod glb;
mod keys;
mod nodes;
mod refine;
pub mod report;
mod times;

pub use report::{BakeReport, report};
pub use times::bake_times;

use glam::{DMat3, DMat4, DQuat};
use rayon::prelude::*;

use document::{Animation, Channel, Document, MeshGroup, Node, Property, SkinOut};
use keys::{BoneMetric, reduce, weights_error};
use nodes::{NodeSample, Sampled};
use refine::refine;

use crate::diff::{HELPER_SUFFIX, Side, rig_size};
use crate::eval::{LayerStack, MorphPose, Pose};
use crate::model::{Clip, InheritMode, Mesh, Rig};

/// How bones become glTF nodes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// A helper node above every bone that needs its stretch rotation: exact.
    #[default]
    Exact,
    /// One TRS node per bone, re-solved against its baked parent: for runtimes that cannot shear.
    Trs,
}

/// The default tolerance: keys reproduce the source within this fraction of the rig's size.
pub const DEFAULT_TOLERANCE: f64 = 1e-4;

/// One animation to bake.
#[derive(Clone, Debug)]
pub struct ClipToBake<'a> {
    pub name: String,
    /// The clip (`None`: the rest pose).
    pub clip: Option<&'a Clip>,
    /// Layers the clip plays through (a blend, an additive layer or a shake baked into a new clip).
    pub layers: Option<LayerStack>,
}

/// What to bake.
#[derive(Clone, Debug)]
pub struct Request<'a> {
    pub rig: &'a Rig,
    /// One per bone: the inheritance the source is evaluated with.
    pub modes: Vec<InheritMode>,
    pub clips: Vec<ClipToBake<'a>>,
    pub strategy: Strategy,
    /// Between keys, the result stays within this fraction of the rig's size of the source (0 keeps every sample).
    pub tolerance: f64,
}

impl Request<'_> {
    /// The source evaluation of clip `index`.
    pub fn side(&self, index: usize) -> Side<'_> {
        let clip = &self.clips[index];
        let side = Side::new(self.rig, clip.clip, &self.modes);
        match &clip.layers {
            Some(layers) => side.with_layers(layers.clone()),
            None => side,
        }
    }
}

/// One baked animation.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BakedAnimation {
    pub name: String,
    /// The sampled times.
    pub times: Vec<f64>,
    /// How many keys were written, over all channels.
    pub keys: usize,
}

/// The result of a bake.
#[derive(Clone, Debug)]
pub struct Baked {
    /// The glTF binary.
    pub glb: Vec<u8>,
    /// Per source bone: whether it got a helper node.
    pub helpers: Vec<bool>,
    pub animations: Vec<BakedAnimation>,
    /// The rig's size ([`rig_size`]) and the tolerance in model units.
    pub rig_size: f64,
    pub tolerance: f64,
    /// What a user should know about the result.
    pub notes: Vec<String>,
}

/// Bakes `request` into a glTF binary.
pub fn bake(request: &Request) -> Baked {
    let (rig, strategy) = (request.rig, request.strategy);
    let sides: Vec<Side> = (0..request.clips.len()).map(|i| request.side(i)).collect();
    let base_times: Vec<Vec<f64>> = sides.iter().map(bake_times).collect();
    let rest_side = Side::new(rig, None, &request.modes);
    let size = sides.iter().zip(&base_times).map(|(side, times)| rig_size(side, times)).fold(0.0, f64::max);
    let size = if size > 0.0 { size } else { rig_size(&rest_side, &[0.0]) };
    let tolerance = request.tolerance.max(0.0) * size;
    let metrics = Metrics::new(&rest_side, size, tolerance);
    let clips: Vec<(Vec<f64>, Sampled)> = sides
        .iter()
        .zip(base_times)
        .map(|(side, times)| {
            let mut sampled = nodes::sample(side, &times, strategy);
            nodes::follow_frames(&mut sampled);
            if metrics.budget == 0.0 {
                return (times, sampled);
            }
            let gains = sampled.stats.parent_gain.clone();
            let misses = |bone: usize, interpolated: &NodeSample, exact: &NodeSample| {
                metrics.bone(&gains, bone).distance(interpolated, exact) > metrics.budget
            };
            refine(side, strategy, times, sampled, &misses)
        })
        .collect();
    let rest = nodes::rest(&rest_side, strategy);
    let helpers: Vec<bool> = (0..rig.skeleton.len())
        .map(|bone| rest.stats.stretched[bone] || clips.iter().any(|(_, s)| s.stats.stretched[bone]))
        .collect();
    let layout = Layout::new(rig, &helpers);
    let mut document = layout.document(rig, &rest);
    let mut animations = Vec::new();
    for ((clip, side), (times, sampled)) in request.clips.iter().zip(&sides).zip(&clips) {
        let animation = layout.animation(&clip.name, side, times, sampled, &metrics, &document);
        let keys = animation.channels.iter().map(|c| c.times.len()).sum();
        animations.push(BakedAnimation { name: clip.name.clone(), times: times.clone(), keys });
        document.animations.push(animation);
    }
    let mut notes = layout.notes.clone();
    notes.extend(source_notes(rig, clips.iter().map(|(_, s)| s.stats.singular).sum()));
    Baked { glb: glb::encode(&document), helpers, animations, rig_size: size, tolerance, notes }
}

/// What the source has that glTF says differently.
fn source_notes(rig: &Rig, singular: usize) -> Vec<String> {
    let mut notes = Vec::new();
    let dual: Vec<&str> =
        rig.meshes.iter().filter(|m| m.dq_weights.iter().any(|&w| w > 0.0)).map(|m| m.name.as_str()).collect();
    if !dual.is_empty() {
        notes.push(format!(
            "skinned with dual quaternions in the file, linearly in glTF (see the vertex errors): {}",
            dual.join(", ")
        ));
    }
    for skin in rig.skins.iter().filter(|s| s.node_bind.is_some()) {
        notes.push(format!(
            "skin `{}` follows its mesh node's motion since the bind (Maya); glTF skins ignore the mesh node",
            skin.name.as_deref().unwrap_or("unnamed")
        ));
    }
    if singular > 0 {
        notes.push(format!("{singular} bone samples under a parent scaled to nothing took the source's local transform"));
    }
    notes
}

/// How far each bone's nodes may stray between keys, and how it is measured ([`BoneMetric`]).
struct Metrics {
    /// Each bone's share of the tolerance: the tolerance over the longest chain of bones, since the errors of a
    /// chain's bones add up at its end.
    budget: f64,
    /// Per bone: how far its subtree reaches in its own units (the rig's size over the bone's scale at rest).
    reach: Vec<f64>,
    /// How far a morph target's displacement reaches in model units per unit of offset.
    model_scale: f64,
}

impl Metrics {
    /// For the rig of `rest` (its rest pose under the bake's modes), `size` and `tolerance` in model units.
    fn new(rest: &Side, size: f64, tolerance: f64) -> Self {
        let mut pose = Pose::default();
        rest.evaluate(&mut pose, &mut None, 0.0);
        let scales: Vec<f64> = pose.model.model.iter().map(uniform_scale).collect();
        let mut sorted: Vec<f64> = scales.iter().copied().filter(|s| *s > 0.0).collect();
        sorted.sort_by(f64::total_cmp);
        let typical = sorted.get(sorted.len() / 2).copied().unwrap_or(1.0);
        let reach = scales.iter().map(|&s| size / if s > 1e-6 * typical { s } else { typical }).collect();
        let chain = rest.rig.skeleton.depths().into_iter().max().map_or(1, |d| d + 1);
        Metrics { budget: tolerance / chain as f64, reach, model_scale: typical }
    }

    /// The metric of `bone`, whose parent scales lengths by at most `gains[bone]`.
    fn bone(&self, gains: &[f64], bone: usize) -> BoneMetric {
        BoneMetric { gain: gains[bone].max(f64::MIN_POSITIVE), reach: self.reach[bone] }
    }
}

/// `|det|^(1/3)` of the 3×3 part: how much the matrix scales lengths on average.
fn uniform_scale(m: &DMat4) -> f64 {
    DMat3::from_mat4(*m).determinant().abs().cbrt()
}

/// Which glTF node each bone and helper becomes, and which meshes hang where.
struct Layout {
    /// The node of each bone.
    bone_node: Vec<usize>,
    /// The helper node above each bone that has one.
    helper_node: Vec<Option<usize>>,
    /// Per mesh group: the node it is on and the source meshes (indices into `Rig::meshes`).
    groups: Vec<(usize, Vec<usize>)>,
    /// Extra nodes for meshes that could not share their bone's node: (parent node, mesh).
    extra: Vec<(usize, usize)>,
    notes: Vec<String>,
}

impl Layout {
    fn new(rig: &Rig, helpers: &[bool]) -> Self {
        let mut bone_node = Vec::with_capacity(helpers.len());
        let mut helper_node = Vec::with_capacity(helpers.len());
        let mut next = 0;
        for &helper in helpers {
            helper_node.push(helper.then(|| {
                next += 1;
                next - 1
            }));
            bone_node.push(next);
            next += 1;
        }
        let mut layout = Layout { bone_node, helper_node, groups: Vec::new(), extra: Vec::new(), notes: Vec::new() };
        layout.place_meshes(rig);
        layout
    }

    /// Every mesh on its bone's node; meshes that share a bone share its glTF mesh as primitives when they can
    /// (the same skin and as many morph targets), else hang on child nodes of their own.
    fn place_meshes(&mut self, rig: &Rig) {
        let mut by_bone: Vec<Vec<usize>> = vec![Vec::new(); rig.skeleton.len()];
        for (m, mesh) in rig.meshes.iter().enumerate() {
            if let Some(list) = by_bone.get_mut(mesh.bone) {
                list.push(m);
            }
        }
        let mut moved = Vec::new();
        for (bone, meshes) in by_bone.into_iter().enumerate() {
            let Some(&first) = meshes.first() else { continue };
            let fits = |m: &usize| {
                let (a, b) = (&rig.meshes[first], &rig.meshes[*m]);
                a.skin == b.skin && a.morph_targets.len() == b.morph_targets.len()
            };
            let (shared, apart): (Vec<usize>, Vec<usize>) = meshes.into_iter().partition(fits);
            self.groups.push((self.bone_node[bone], shared));
            for m in apart {
                self.extra.push((self.bone_node[bone], m));
                moved.push(rig.meshes[m].name.clone());
            }
        }
        if !moved.is_empty() {
            self.notes.push(format!("meshes on child nodes of their own (a glTF node shows one mesh): {}", moved.join(", ")));
        }
    }

    /// The nodes, meshes and skins, with each node's default TRS from the rest pose.
    fn document<'a>(&self, rig: &'a Rig, rest: &Sampled) -> Document<'a> {
        let mut document = Document { generator: format!("bonescope {}", env!("CARGO_PKG_VERSION")), ..Document::default() };
        for (bone, b) in rig.skeleton.bones().iter().enumerate() {
            let node = &rest.at(0, bone).as_baked(self.helper_node[bone].is_some());
            let parent = b.parent.map(|p| self.bone_node[p]);
            match self.helper_node[bone] {
                Some(helper) => {
                    document.nodes.push(node_with(&format!("{}{HELPER_SUFFIX}", b.name), parent, node));
                    let own = NodeSample { rotation: node.stretch.conjugate(), ..IDENTITY_NODE };
                    document.nodes.push(node_with(&b.name, Some(helper), &own));
                }
                None => document.nodes.push(node_with(&b.name, parent, node)),
            }
        }
        for (node, meshes) in &self.groups {
            document.nodes[*node].mesh = Some(document.meshes.len());
            document.meshes.push(group(rig, meshes));
        }
        for &(parent, mesh) in &self.extra {
            let name = rig.meshes[mesh].name.clone();
            document.nodes.push(Node { mesh: Some(document.meshes.len()), ..node_with(&name, Some(parent), &IDENTITY_NODE) });
            document.meshes.push(group(rig, &[mesh]));
        }
        for node in &mut document.nodes {
            node.skin = node.mesh.and_then(|m| document.meshes[m].primitives[0].skin);
        }
        document.skins = rig
            .skins
            .iter()
            .map(|skin| SkinOut {
                name: skin.name.clone(),
                joints: skin.joints.iter().map(|&bone| self.bone_node[bone]).collect(),
                inverse_bind: skin.inverse_bind.clone(),
            })
            .collect();
        document
    }

    /// One clip's channels: every bone's nodes at its kept keys, and the morph weights the clip animates.
    fn animation(
        &self,
        name: &str,
        side: &Side,
        times: &[f64],
        sampled: &Sampled,
        metrics: &Metrics,
        document: &Document,
    ) -> Animation {
        let per_bone: Vec<Vec<Channel>> = (0..sampled.bones)
            .into_par_iter()
            .map(|bone| {
                let metric = metrics.bone(&sampled.stats.parent_gain, bone);
                let helper = self.helper_node[bone].is_some();
                let error = |i, j, k| metric.error(sampled, times, bone, helper, (i, j, k));
                let kept = reduce(times.len(), metrics.budget, error);
                self.bone_channels(bone, &kept, times, sampled, document)
            })
            .collect();
        let mut channels: Vec<Channel> = per_bone.into_iter().flatten().collect();
        channels.extend(self.weight_channels(side, times, metrics, document));
        if channels.is_empty()
            && let Some(node) = document.nodes.first()
        {
            // glTF wants at least one channel; one that holds the first node still says how long the clip is.
            let end = times.last().copied().unwrap_or(0.0) as f32;
            let times = if end > 0.0 { vec![0.0, end] } else { vec![0.0] };
            let values = times.iter().flat_map(|_| node.rotation).collect();
            channels.push(Channel { node: 0, property: Property::Rotation, times, values });
        }
        Animation { name: name.to_owned(), channels }
    }

    /// The channels of one bone's nodes at the samples `kept`, leaving out those that only repeat the node's default.
    fn bone_channels(&self, bone: usize, kept: &[usize], times: &[f64], sampled: &Sampled, document: &Document) -> Vec<Channel> {
        let kept = distinct_f32_times(kept, times);
        let key_times: Vec<f32> = kept.iter().map(|&k| times[k] as f32).collect();
        let helper = self.helper_node[bone].is_some();
        let samples: Vec<NodeSample> = kept.iter().map(|&k| sampled.at(k, bone).as_baked(helper)).collect();
        let mut channels = Vec::new();
        let mut add = |node: usize, property: Property, values: Vec<f32>| {
            let default = default_values(&document.nodes[node], property);
            if let Some(channel) = channel(node, property, &key_times, values, &default) {
                channels.push(channel);
            }
        };
        let (outer, own) = (self.helper_node[bone].unwrap_or(self.bone_node[bone]), self.bone_node[bone]);
        add(outer, Property::Translation, samples.iter().flat_map(|s| s.translation.as_vec3().to_array()).collect());
        add(outer, Property::Rotation, continuous(samples.iter().map(|s| s.rotation)));
        add(outer, Property::Scale, samples.iter().flat_map(|s| s.scale.as_vec3().to_array()).collect());
        if self.helper_node[bone].is_some() {
            add(own, Property::Rotation, continuous(samples.iter().map(|s| s.stretch.conjugate())));
        }
        channels
    }

    /// The morph weights of every mesh group whose bone the clip animates them on.
    fn weight_channels(&self, side: &Side, times: &[f64], metrics: &Metrics, document: &Document) -> Vec<Channel> {
        let Some(clip) = side.clip else { return Vec::new() };
        let mut channels = Vec::new();
        let mut morph = MorphPose::default();
        for (group, (node, meshes)) in document.meshes.iter().zip(&self.groups) {
            let mesh = &side.rig.meshes[meshes[0]];
            if group.weights.is_empty() || clip.morph().iter().all(|m| m.bone != mesh.bone) {
                continue;
            }
            let samples: Vec<Vec<f64>> = times
                .iter()
                .map(|&t| {
                    morph.evaluate(Some(clip), t);
                    morph.weights(mesh).into_owned()
                })
                .collect();
            let amplitude: Vec<f64> = (0..group.weights.len())
                .map(|k| {
                    let longest = group.primitives.iter().flat_map(|p| &p.morph_targets[k].offsets).map(|o| o.length());
                    f64::from(longest.fold(0.0, f32::max)) * metrics.model_scale
                })
                .collect();
            let kept = reduce(times.len(), metrics.budget, |i, j, k| weights_error(&samples, times, &amplitude, (i, j, k)));
            let kept = distinct_f32_times(&kept, times);
            let key_times: Vec<f32> = kept.iter().map(|&k| times[k] as f32).collect();
            let values = kept.iter().flat_map(|&k| samples[k].iter().map(|&w| w as f32)).collect();
            if let Some(channel) = channel(*node, Property::Weights, &key_times, values, &group.weights) {
                channels.push(channel);
            }
        }
        channels
    }
}

const IDENTITY_NODE: NodeSample = NodeSample {
    translation: glam::DVec3::ZERO,
    rotation: DQuat::IDENTITY,
    scale: glam::DVec3::ONE,
    stretch: DQuat::IDENTITY,
};

/// A node named `name` with the TRS of `sample` (its stretch is carried by the bone's own node, not here).
fn node_with(name: &str, parent: Option<usize>, sample: &NodeSample) -> Node {
    Node {
        name: name.to_owned(),
        parent,
        translation: sample.translation.as_vec3().to_array(),
        rotation: unit(sample.rotation),
        scale: sample.scale.as_vec3().to_array(),
        mesh: None,
        skin: None,
    }
}

/// Rotation keys in single precision, each in the hemisphere of the one before (slerp between them then takes the
/// short way whether or not a player checks).
fn continuous(rotations: impl Iterator<Item = DQuat>) -> Vec<f32> {
    let mut previous: Option<DQuat> = None;
    let mut values = Vec::new();
    for q in rotations {
        let q = match previous {
            Some(p) if p.dot(q) < 0.0 => -q,
            _ => q,
        };
        values.extend(unit(q));
        previous = Some(q);
    }
    values
}

/// A quaternion in single precision, of unit length there.
fn unit(q: DQuat) -> [f32; 4] {
    q.as_quat().normalize().to_array()
}

/// The source meshes `meshes` as one glTF mesh, named as the importer will name them back: a single mesh by its own
/// name, primitives `base[0]`, `base[1]`, … by `base`.
fn group<'a>(rig: &'a Rig, meshes: &[usize]) -> MeshGroup<'a> {
    let primitives: Vec<&Mesh> = meshes.iter().map(|&m| &rig.meshes[m]).collect();
    let name = match primitives.as_slice() {
        [one] => one.name.clone(),
        many => {
            let base = many[0].name.strip_suffix("[0]").unwrap_or(&many[0].name);
            base.to_owned()
        }
    };
    MeshGroup { name, weights: primitives[0].morph_weights.clone(), primitives }
}

/// The node's default value of `property`, as the numbers a channel of it holds per key.
fn default_values(node: &Node, property: Property) -> Vec<f32> {
    match property {
        Property::Translation => node.translation.to_vec(),
        Property::Rotation => node.rotation.to_vec(),
        Property::Scale => node.scale.to_vec(),
        Property::Weights => Vec::new(),
    }
}

/// A channel of `values` at `times`, or `None` when every key repeats `default`; a channel whose keys all repeat
/// its first keeps only its first and last key.
fn channel(node: usize, property: Property, times: &[f32], values: Vec<f32>, default: &[f32]) -> Option<Channel> {
    if times.is_empty() || values.is_empty() {
        return None;
    }
    let width = values.len() / times.len();
    let mut keys = values.chunks_exact(width);
    let first = keys.next()?;
    if values.chunks_exact(width).all(|key| key == default) {
        return None;
    }
    if keys.all(|key| key == first) && times.len() > 2 {
        let last = times.len() - 1;
        let values = [first, &values[last * width..]].concat();
        return Some(Channel { node, property, times: vec![times[0], times[last]], values });
    }
    Some(Channel { node, property, times: times.to_vec(), values })
}

/// `kept` without the samples whose time rounds to the same `f32` as an earlier one's (glTF's times are `f32` and
/// strictly increasing).
fn distinct_f32_times(kept: &[usize], times: &[f64]) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::with_capacity(kept.len());
    for &k in kept {
        if out.last().is_none_or(|&last| (times[k] as f32) > (times[last] as f32)) {
            out.push(k);
        }
    }
    out
}

/// The animations to bake for `rig`: every clip (or the one `only` names), or the rest pose for a file without any.
pub fn every_clip<'a>(rig: &'a Rig, only: Option<&'a Clip>) -> Vec<ClipToBake<'a>> {
    let clips: Vec<&Clip> = match only {
        Some(clip) => vec![clip],
        None => rig.clips.iter().collect(),
    };
    if clips.is_empty() {
        return vec![ClipToBake { name: "rest pose".to_owned(), clip: None, layers: None }];
    }
    clips.into_iter().map(|clip| ClipToBake { name: clip.label(), clip: Some(clip), layers: None }).collect()
}

/// Writes `bytes` to `path` atomically: into a temporary file beside it, then renamed over it, so the path holds
/// either its old content or all of the new one, never a half-written file.
pub fn save(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    let mut file = tempfile::NamedTempFile::new_in(folder)?;
    file.write_all(bytes)?;
    file.as_file().sync_all()?;
    file.persist(path).map_err(|e| e.error)?;
    Ok(())
}
