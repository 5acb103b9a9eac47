//! A baked scene written as UsdSkel through the `openusd` crate's own writers (its text, crate and archive
//! writers over one `sdf` layer): a `SkelRoot` holding a `Skeleton` whose joints are the baked nodes (a bone's
//! helper node `<bone>.stretch` is a joint too, its bone's joint below it), the `SkelAnimation` of the baked clip,
//! and every mesh bound to the skeleton: skinned by its skin, or rigidly to the joint it hangs on.
//!
//! UsdSkel composes every joint fully with its parent, as glTF composes nodes, so the exact bake's helper joints
//! reproduce a sheared pose here too. What USD says differently:
//! - one timeline a stage, on which a skeleton plays one animation: the bake writes one clip;
//! - a `SkelAnimation` holds every joint's values at each time code, interpolated linearly (rotations by slerp):
//!   the baked keys of all channels are merged, each channel evaluated at the others' keys, which reproduces its
//!   piecewise-linear curve exactly; a stepped key is held until just before the next;
//! - scales are `half3`: eleven significant bits, a relative rounding of at most 2⁻¹¹. Translations are written
//!   to make up for the rounding of every scale above them ([`HalfChain`]), so that it moves no joint's origin; it
//!   still turns and stretches joints' axes by up to 2⁻¹¹, which the report measures;
//! - names are identifiers (`[A-Za-z_][A-Za-z0-9_]*`), unique among siblings; each joint's and mesh's name as
//!   baked is kept in `customData` (`bonescope = { names }` on the skeleton, `bonescope = { name }` on a mesh) for
//!   bonescope's reader, so `diff` pairs the bones of the source and the bake by their own names;
//! - the stage is stated in Y-up metres (`metersPerUnit`, `upAxis`): the source's own unit and axes stand on a joint
//!   `conversion` above its roots where they differ, as in the glTF bake (whose nodes keep the file's numbers), and
//!   the skeleton's `customData` names it (`bonescope = { placing }`) for bonescope's reader to place it outside the
//!   rig. (Stated in the stage's metadata instead, they would also apply to roots that carry them themselves, as an
//!   exporter's armature scaled 100 under a centimetre file does.)

use std::collections::{HashMap, HashSet};
use std::io::Cursor;

use glam::{DMat4, DQuat, Quat, Vec3};
use openusd::gf;
use openusd::sdf::{self, AbstractData, Path, Specifier, Value, Variability};

use super::document::{Animation, Channel, GltfDocument, Interpolation, Node, Property, SkinOut};
use super::glb::skin_attributes;
use super::skins::unique;
use crate::diff::usd_identifier as identifier;
use crate::model::Mesh;

/// Which of USD's three encodings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// `.usda`: text.
    Text,
    /// `.usdc`: the binary crate format.
    Crate,
    /// `.usdz`: a crate layer in an uncompressed zip package.
    Package,
}

/// Where the scene lies on the stage's clock: the clip's span and frame rate. A baked time `t` is at time code
/// `(t − delay) · codes_per_second`: the clip's own clock.
#[derive(Clone, Debug, PartialEq)]
pub struct Clock {
    pub codes_per_second: f64,
    /// Seconds the baked clock runs behind the clip's own (a clip starting before 0 baked from 0).
    pub delay: f64,
    /// The clip's start and end in seconds on the baked clock.
    pub span: (f64, f64),
}

/// The dictionary of a prim's `customData` that holds what bonescope's reader reads back.
pub const CUSTOM_DATA: &str = "bonescope";

/// The layer's root prim, the skeleton and its animation.
const ROOT: &str = "/Root";
const SKELETON: &str = "/Root/Skeleton";
const ANIMATION: &str = "/Root/Skeleton/Animation";

/// How long before a key a stepped channel's held value is written, in seconds: far below a frame, far above the
/// rounding of a time in double precision.
const STEP_LEAD: f64 = 1e-6;

/// `document` (its first animation) written as a UsdSkel layer in `encoding`, its node `conversion` (where it has
/// one) carrying the source's unit and axes; what a user should know of how goes to `notes`.
pub fn encode(
    document: GltfDocument,
    clock: &Clock,
    conversion: Option<usize>,
    encoding: Encoding,
    notes: &mut Vec<String>,
) -> Result<Vec<u8>, String> {
    let (document, conversion) = &parents_first(document, conversion);
    let conversion = *conversion;
    let mut layer = Layer::new();
    layer.stage_metadata(clock);
    let joints = Joints::of(&document.nodes, notes);
    let binds = binds(document, notes);
    layer.skeleton(document, &joints, &binds, conversion);
    let shapes = layer.meshes(document, &binds, notes);
    if let Some(animation) = document.animations.first() {
        let rounding = layer.animation(document, animation, &joints, &shapes, clock);
        if rounding > 0.0 {
            notes.push(format!(
                "UsdSkel keeps animated scales in half precision: the scales written round by up to {rounding:.1e} \
                 of themselves (translations make up for it at every joint's origin; axes and skin move by up to \
                 that fraction of their reach, measured below)"
            ));
        }
    }
    layer.write(encoding)
}

/// `document` with its nodes reordered so that each comes after its parent, as UsdSkel's joints must (a node put
/// above the roots comes after them), every index into them renumbered, `conversion` too.
fn parents_first(mut document: GltfDocument, conversion: Option<usize>) -> (GltfDocument, Option<usize>) {
    let nodes = std::mem::take(&mut document.nodes);
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    for (n, node) in nodes.iter().enumerate() {
        if let Some(p) = node.parent {
            children[p].push(n);
        }
    }
    // Depth first from the roots in their order, children in theirs: the order of the nodes wherever it already
    // puts parents first.
    let mut order = Vec::with_capacity(nodes.len());
    let mut stack: Vec<usize> = (0..nodes.len()).rev().filter(|&n| nodes[n].parent.is_none()).collect();
    while let Some(n) = stack.pop() {
        order.push(n);
        stack.extend(children[n].iter().rev());
    }
    let mut new_index = vec![0; nodes.len()];
    for (i, &n) in order.iter().enumerate() {
        new_index[n] = i;
    }
    document.nodes =
        order.iter().map(|&n| Node { parent: nodes[n].parent.map(|p| new_index[p]), ..nodes[n].clone() }).collect();
    for skin in &mut document.skins {
        skin.joints.iter_mut().for_each(|joint| *joint = new_index[*joint]);
    }
    for channel in document.animations.iter_mut().flat_map(|a| &mut a.channels) {
        channel.node = new_index[channel.node];
    }
    (document, conversion.map(|n| new_index[n]))
}

/// The joints: each node's path (`A/B` is `B` under `A`), its name an identifier unique among its siblings.
struct Joints {
    paths: Vec<String>,
}

impl Joints {
    fn of(nodes: &[Node], notes: &mut Vec<String>) -> Self {
        let mut taken: HashMap<Option<usize>, HashSet<String>> = HashMap::new();
        let (mut paths, mut renamed): (Vec<String>, Vec<String>) = Default::default();
        for node in nodes {
            let siblings = taken.entry(node.parent).or_default();
            let name = unique_in(identifier(&node.name), siblings);
            if name != identifier(&node.name) {
                renamed.push(format!("`{}` → `{name}`", node.name));
            }
            siblings.insert(name.clone());
            let path = match node.parent {
                Some(p) => format!("{}/{name}", paths[p]),
                None => name.clone(),
            };
            paths.push(path);
        }
        if !renamed.is_empty() {
            notes.push(format!("joint names alike once spelt as USD identifiers, made unique: {}", renamed.join(", ")));
        }
        Joints { paths }
    }
}

/// `name`, or `name_1`, `name_2`, … whichever is not `taken` (a dot spells no identifier).
fn unique_in(name: String, taken: &HashSet<String>) -> String {
    unique(&name, '_', |n| taken.contains(n))
}

/// Each node's bind transform in the skeleton's space: the inverse of its inverse bind matrix in the first skin
/// that binds it, else its place at rest. UsdSkel keeps one bind per joint; a skin that binds a joint elsewhere is
/// said in `notes` (its mesh then skins from the skeleton's bind: the report measures it).
fn binds(document: &GltfDocument, notes: &mut Vec<String>) -> Vec<DMat4> {
    let nodes = &document.nodes;
    let mut world: Vec<DMat4> = Vec::with_capacity(nodes.len());
    for node in nodes {
        let local = local_matrix(node);
        world.push(node.parent.map_or(local, |p| world[p] * local));
    }
    let mut bound: Vec<Option<DMat4>> = vec![None; nodes.len()];
    let mut differing = Vec::new();
    for skin in &document.skins {
        for (&node, inverse_bind) in skin.joints.iter().zip(&skin.inverse_bind) {
            let bind = inverse_bind.inverse();
            match bound[node] {
                None => bound[node] = Some(bind),
                Some(first) if !first.abs_diff_eq(bind, 1e-9 * (1.0 + first.w_axis.truncate().length())) => {
                    differing.push(skin.name.clone().unwrap_or_else(|| "unnamed".to_owned()));
                }
                Some(_) => {}
            }
        }
    }
    differing.dedup();
    if !differing.is_empty() {
        notes.push(format!(
            "skins that bind a joint elsewhere than an earlier skin (UsdSkel keeps one bind per joint): {}",
            differing.join(", ")
        ));
    }
    bound.into_iter().zip(world).map(|(bound, rest)| bound.unwrap_or(rest)).collect()
}

/// A node's default TRS as a matrix, in double precision from the single-precision values written.
fn local_matrix(node: &Node) -> DMat4 {
    let [x, y, z, w] = node.rotation.map(f64::from);
    DMat4::from_scale_rotation_translation(
        Vec3::from_array(node.scale).as_dvec3(),
        DQuat::from_xyzw(x, y, z, w),
        Vec3::from_array(node.translation).as_dvec3(),
    )
}

/// A matrix as USD stores it: rows of a row-vector matrix are glam's columns.
fn usd_matrix(m: &DMat4) -> gf::Matrix4d {
    gf::Matrix4d(m.to_cols_array())
}

/// Each mesh's blend shapes: the node its mesh group hangs on, the group, and the names the animation weights the
/// shapes by.
type Shapes = Vec<(usize, usize, Vec<String>)>;

/// One layer being written.
struct Layer {
    data: sdf::Data,
}

impl Layer {
    fn new() -> Self {
        let mut data = sdf::Data::new();
        data.create_spec(Path::abs_root(), sdf::SpecType::PseudoRoot);
        Layer { data }
    }

    /// The stage's metadata: its default prim, unit, up axis and clock.
    fn stage_metadata(&mut self, clock: &Clock) {
        let root = Path::abs_root();
        let (start, end) = clock.span;
        let fields = [
            ("defaultPrim", Value::token("Root")),
            ("metersPerUnit", Value::Double(1.0)),
            ("upAxis", Value::token("Y")),
            ("timeCodesPerSecond", Value::Double(clock.codes_per_second)),
            ("framesPerSecond", Value::Double(clock.codes_per_second)),
            ("startTimeCode", Value::Double(time_code(start, clock))),
            ("endTimeCode", Value::Double(time_code(end, clock))),
            ("documentation", Value::String(format!("baked by bonescope {}", env!("CARGO_PKG_VERSION")))),
        ];
        for (field, value) in fields {
            self.data.set_field(&root, field, value);
        }
    }

    /// A prim `def`ined at `path` of type `kind`.
    fn prim(&mut self, path: &str, kind: &str) {
        sdf::PrimSpecMut::new(&mut self.data, Path::from(path), Specifier::Def, kind).expect("a valid prim path");
    }

    /// An attribute `name` of the prim at `prim`, typed `kind`, holding `value` (uniform where `uniform`).
    fn attribute(&mut self, prim: &str, name: &str, kind: &str, uniform: bool, value: Value) -> Path {
        let path = Path::from(prim).append_property(name).expect("a valid property name");
        let variability = if uniform { Variability::Uniform } else { Variability::Varying };
        sdf::AttributeSpecMut::new(&mut self.data, path.clone(), kind, variability, false)
            .expect("a new attribute")
            .set_default(value);
        path
    }

    /// A relationship `name` of the prim at `prim` targeting `targets`.
    fn relationship(&mut self, prim: &str, name: &str, targets: &[&str]) {
        let path = Path::from(prim).append_property(name).expect("a valid property name");
        // Written as plain `rel`, as Pixar's USD writes relationships (its reader takes no `uniform rel`).
        sdf::RelationshipSpecMut::new(&mut self.data, path, Variability::Varying, false)
            .expect("a new relationship")
            .set_target_paths(targets.iter().map(|&t| Path::from(t)));
    }

    /// The prim at `path` given the applied schema `schema`.
    fn apply(&mut self, path: &str, schema: &str) {
        let ops = sdf::TokenListOp { prepended_items: vec![schema.into()], ..Default::default() };
        self.data.set_field(&Path::from(path), "apiSchemas", Value::TokenListOp(ops));
    }

    /// The `SkelRoot` and its `Skeleton`: joints, rest and bind transforms, the nodes' own names (and which one is
    /// the `conversion` of the source's unit and axes), and the animation bound to it.
    fn skeleton(&mut self, document: &GltfDocument, joints: &Joints, binds: &[DMat4], conversion: Option<usize>) {
        self.prim(ROOT, "SkelRoot");
        self.prim(SKELETON, "Skeleton");
        let tokens = |paths: &[String]| Value::TokenVec(paths.iter().map(|p| p.as_str().into()).collect());
        self.attribute(SKELETON, "joints", "token[]", true, tokens(&joints.paths));
        let rest: Vec<gf::Matrix4d> = document.nodes.iter().map(|n| usd_matrix(&local_matrix(n))).collect();
        self.attribute(SKELETON, "restTransforms", "matrix4d[]", true, Value::Matrix4dVec(rest));
        let bind: Vec<gf::Matrix4d> = binds.iter().map(usd_matrix).collect();
        self.attribute(SKELETON, "bindTransforms", "matrix4d[]", true, Value::Matrix4dVec(bind));
        let names: Vec<String> = document.nodes.iter().map(|n| n.name.clone()).collect();
        let mut ours = vec![("names", Value::StringVec(names))];
        ours.extend(conversion.map(|node| ("placing", Value::IntVec(vec![node as i32]))));
        self.custom_data(SKELETON, ours);
        if !document.animations.is_empty() {
            self.apply(SKELETON, "SkelBindingAPI");
            self.relationship(SKELETON, "skel:animationSource", &[ANIMATION]);
        }
    }

    /// Every mesh of `document` as a `Mesh` prim under the root, bound to the skeleton (skinned by its skin, else
    /// rigidly to the joint it hangs on), with its blend shapes; the names the animation weights each mesh's shapes
    /// by.
    fn meshes(&mut self, document: &GltfDocument, binds: &[DMat4], notes: &mut Vec<String>) -> Shapes {
        let mut taken: HashSet<String> = ["Skeleton".to_owned()].into();
        let mut shapes = Vec::new();
        for (node, group) in document.nodes.iter().enumerate().filter_map(|(n, node)| Some((n, node.mesh?))) {
            for mesh in &document.meshes[group].primitives {
                let name = unique_in(identifier(&mesh.name), &taken);
                taken.insert(name.clone());
                let path = format!("{ROOT}/{name}");
                self.mesh(&path, mesh);
                self.bind(&path, mesh, node, document.skins.get(mesh.skin.unwrap_or(usize::MAX)), binds, notes);
                shapes.push((node, group, self.blend_shapes(&path, &name, mesh)));
            }
        }
        shapes
    }

    /// The mesh's geometry: its points, triangles and normals, not subdivided.
    fn mesh(&mut self, path: &str, mesh: &Mesh) {
        self.prim(path, "Mesh");
        let points = |v: &[Vec3]| v.iter().map(|p| gf::vec3f(p.x, p.y, p.z)).collect::<Vec<_>>();
        self.attribute(path, "points", "point3f[]", false, Value::Vec3fVec(points(&mesh.positions)));
        let triangles = mesh.indices.len() / 3;
        self.attribute(path, "faceVertexCounts", "int[]", false, Value::IntVec(vec![3; triangles]));
        let indices = mesh.indices[..3 * triangles].iter().map(|&i| i32::try_from(i).unwrap_or(i32::MAX)).collect();
        self.attribute(path, "faceVertexIndices", "int[]", false, Value::IntVec(indices));
        if mesh.normals.len() == mesh.positions.len() && !mesh.normals.is_empty() {
            let normals: Vec<Vec3> = mesh.normals.iter().map(|n| n.normalize_or(Vec3::Y)).collect();
            let at = self.attribute(path, "normals", "normal3f[]", false, Value::Vec3fVec(points(&normals)));
            self.data.set_field(&at, "interpolation", Value::token("vertex"));
        }
        self.attribute(path, "subdivisionScheme", "token", true, Value::token("none"));
        self.custom_data(path, vec![("name", Value::String(mesh.name.clone()))]);
    }

    /// The prim at `path` given `customData = { bonescope = { key = value, … } }`.
    fn custom_data(&mut self, path: &str, ours: Vec<(&str, Value)>) {
        let ours = ours.into_iter().map(|(key, value)| (key.to_owned(), value)).collect();
        let custom = HashMap::from([(CUSTOM_DATA.to_owned(), Value::Dictionary(ours))]);
        self.data.set_field(&Path::from(path), "customData", Value::Dictionary(custom));
    }

    /// The mesh bound to the skeleton: per point the joints and weights of `skin` (joints are nodes, numbered
    /// alike), or, unskinned, every point rigidly to `node`'s joint from where it binds; dual-quaternion skinning
    /// where every point of the source asks for it.
    fn bind(
        &mut self,
        path: &str,
        mesh: &Mesh,
        node: usize,
        skin: Option<&SkinOut>,
        binds: &[DMat4],
        notes: &mut Vec<String>,
    ) {
        self.apply(path, "SkelBindingAPI");
        self.relationship(path, "skel:skeleton", &[SKELETON]);
        let skin = skin.filter(|_| mesh.joints.len() == mesh.positions.len() && !mesh.positions.is_empty());
        let (indices, weights, size, constant, geom_bind) = match skin {
            Some(skin) => {
                let (joints, weights) = skin_attributes(mesh, &skin.joint_map);
                let indices = joints.iter().map(|&j| skin.joints[usize::from(j)] as i32).collect();
                (indices, weights, 4, false, DMat4::IDENTITY)
            }
            None => (vec![node as i32], vec![1.0], 1, true, binds[node]),
        };
        let interpolation = Value::token(if constant { "constant" } else { "vertex" });
        for (name, kind, value) in [
            ("primvars:skel:jointIndices", "int[]", Value::IntVec(indices)),
            ("primvars:skel:jointWeights", "float[]", Value::FloatVec(weights)),
        ] {
            let at = self.attribute(path, name, kind, false, value);
            self.data.set_field(&at, "interpolation", interpolation.clone());
            self.data.set_field(&at, "elementSize", Value::Int(size));
        }
        let geom_bind = Value::Matrix4d(usd_matrix(&geom_bind));
        self.attribute(path, "primvars:skel:geomBindTransform", "matrix4d", false, geom_bind);
        let dual = mesh.dq_weights.iter().filter(|&&w| w > 0.0).count();
        if dual > 0 && dual == mesh.positions.len() && mesh.dq_weights.iter().all(|&w| w >= 1.0) {
            let method = Value::token("dualQuaternion");
            self.attribute(path, "primvars:skel:skinningMethod", "token", true, method);
        } else if dual > 0 {
            notes.push(format!(
                "`{}` blends dual-quaternion and linear skinning point by point, which UsdSkel cannot: skinned \
                 linearly (see the vertex errors)",
                mesh.name
            ));
        }
    }

    /// The mesh's morph targets as `BlendShape` prims below it; the names the animation weights them by (the
    /// mesh's prim name and the shape's, one namespace for every mesh of the stage).
    fn blend_shapes(&mut self, path: &str, mesh_name: &str, mesh: &Mesh) -> Vec<String> {
        if mesh.morph_targets.is_empty() {
            return Vec::new();
        }
        let mut taken = HashSet::new();
        let (mut names, mut targets) = (Vec::new(), Vec::new());
        for target in &mesh.morph_targets {
            let name = unique_in(identifier(&target.name), &taken);
            taken.insert(name.clone());
            let shape = format!("{path}/{name}");
            self.prim(&shape, "BlendShape");
            let offsets = target.offsets.iter().map(|o| gf::vec3f(o.x, o.y, o.z)).collect();
            self.attribute(&shape, "offsets", "vector3f[]", true, Value::Vec3fVec(offsets));
            names.push(format!("{mesh_name}_{name}"));
            targets.push(shape);
        }
        self.attribute(path, "skel:blendShapes", "token[]", true, Value::token_vec(names.iter().map(String::as_str)));
        let targets: Vec<&str> = targets.iter().map(String::as_str).collect();
        self.relationship(path, "skel:blendShapeTargets", &targets);
        names
    }

    /// The `SkelAnimation` of `animation`: every joint's translation, rotation and scale at the time codes of
    /// every key of any channel ([`Timeline`]), and every blend shape's weight; the largest relative rounding of a
    /// scale to half precision.
    fn animation(
        &mut self,
        document: &GltfDocument,
        animation: &Animation,
        joints: &Joints,
        shapes: &Shapes,
        clock: &Clock,
    ) -> f64 {
        self.prim(ANIMATION, "SkelAnimation");
        let nodes = &document.nodes;
        let animated = animated(nodes, &animation.channels);
        let listed = joints.paths.iter().zip(&animated).filter(|(_, a)| **a).map(|(path, _)| path.as_str());
        self.attribute(ANIMATION, "joints", "token[]", true, Value::token_vec(listed));
        let timeline = Timeline::of(&animation.channels);
        let codes: Vec<f64> = timeline.times.iter().map(|&t| time_code(t, clock)).collect();
        let mut channels: HashMap<(usize, Property), &Channel> = HashMap::new();
        for channel in &animation.channels {
            channels.insert((channel.node, channel.property), channel);
        }
        let at = |node: usize, property: Property| channels.get(&(node, property)).map(|c| timeline.sampled(c));
        // Each code's values of the joints listed, allocated whole: they are most of what the layer holds.
        let count = animated.iter().filter(|&&a| a).count();
        let (mut translations, mut rotations, mut scales) =
            (per_code(codes.len(), count), per_code(codes.len(), count), per_code(codes.len(), count));
        let sampled = |property| (0..nodes.len()).map(|n| at(n, property)).collect::<Vec<_>>();
        let (t, r, s) = (sampled(Property::Translation), sampled(Property::Rotation), sampled(Property::Scale));
        let mut previous = vec![Quat::IDENTITY; nodes.len()];
        let mut rounding: f64 = 0.0;
        for k in 0..codes.len() {
            let mut chain = HalfChain::new(nodes.len());
            for (n, node) in nodes.iter().enumerate() {
                let q = Quat::from_slice(at_code(&r[n], &node.rotation, k));
                // Each sample on the side of the one before: USD slerps between them along the shorter arc.
                let q = if q.dot(previous[n]) < 0.0 { -q } else { q };
                previous[n] = q;
                let scale = Vec3::from_slice(at_code(&s[n], &node.scale, k));
                let translation = Vec3::from_slice(at_code(&t[n], &node.translation, k));
                let (translation, half) = chain.add(n, node.parent, translation, q, scale, animated[n]);
                if !animated[n] {
                    continue;
                }
                translations[k].push(gf::vec3f(translation.x, translation.y, translation.z));
                rotations[k].push(gf::Quatf { w: q.w, x: q.x, y: q.y, z: q.z });
                rounding = (0..3).fold(rounding, |r, i| r.max(relative_rounding(scale[i], half[i])));
                scales[k].push(gf::Vec3h { x: half[0], y: half[1], z: half[2] });
            }
        }
        self.samples(ANIMATION, "translations", "float3[]", &codes, translations.into_iter().map(Value::Vec3fVec));
        self.samples(ANIMATION, "rotations", "quatf[]", &codes, rotations.into_iter().map(Value::QuatfVec));
        self.samples(ANIMATION, "scales", "half3[]", &codes, scales.into_iter().map(Value::Vec3hVec));
        if shapes.iter().any(|(.., names)| !names.is_empty()) {
            let names = shapes.iter().flat_map(|(.., names)| names.iter().map(String::as_str));
            self.attribute(ANIMATION, "blendShapes", "token[]", true, Value::token_vec(names));
            let mut weights = vec![Vec::new(); codes.len()];
            for (node, group, names) in shapes.iter().filter(|(.., names)| !names.is_empty()) {
                let defaults = &document.meshes[*group].weights;
                let sampled = at(*node, Property::Weights).filter(|v| v.len() == names.len() * codes.len());
                let defaults = || (0..names.len()).map(|k| defaults.get(k).copied().unwrap_or(0.0)).collect::<Vec<_>>();
                let values = sampled.unwrap_or_else(|| defaults().repeat(codes.len()));
                for (k, at) in weights.iter_mut().enumerate() {
                    at.extend_from_slice(&values[k * names.len()..(k + 1) * names.len()]);
                }
            }
            self.samples(ANIMATION, "blendShapeWeights", "float[]", &codes, weights.into_iter().map(Value::FloatVec));
        }
        rounding
    }

    /// An attribute `name` of `prim` typed `kind`, sampled at the time codes `codes` with `values`; one value
    /// where they are all one: USD reads a value between two samples in the precision stored, and a half-precision
    /// scale between two equal samples can read a half step off.
    fn samples(&mut self, prim: &str, name: &str, kind: &str, codes: &[f64], values: impl Iterator<Item = Value>) {
        let samples: sdf::TimeSampleMap = codes.iter().copied().zip(values).collect();
        if let Some((_, first)) = samples.first().filter(|(_, first)| samples.iter().all(|(_, v)| v == first)) {
            self.attribute(prim, name, kind, false, first.clone());
            return;
        }
        let path = Path::from(prim).append_property(name).expect("a valid property name");
        sdf::AttributeSpecMut::new(&mut self.data, path.clone(), kind, Variability::Varying, false)
            .expect("a new attribute");
        self.data.set_field(&path, "timeSamples", Value::TimeSamples(samples));
    }

    /// The layer's bytes in `encoding`.
    fn write(self, encoding: Encoding) -> Result<Vec<u8>, String> {
        let crate_bytes = |data: &sdf::Data| {
            let mut out = Cursor::new(Vec::new());
            openusd::usdc::CrateWriter::write(data, &mut out).map(|()| out.into_inner())
        };
        let written = match encoding {
            Encoding::Text => openusd::usda::TextWriter::write_to_string(&self.data).map(String::into_bytes),
            Encoding::Crate => crate_bytes(&self.data),
            Encoding::Package => crate_bytes(&self.data).and_then(|layer| {
                let mut archive = openusd::usdz::ArchiveWriter::new(Cursor::new(Vec::new()));
                archive.add_layer("root.usdc", &layer)?;
                archive.finish().map(Cursor::into_inner)
            }),
        };
        written.map_err(|e| format!("openusd's writer failed: {e:#}"))
    }
}

/// Every time any channel of an animation has a key at, and just before each key of a stepped channel (which
/// holds the value before it until then): the times a `SkelAnimation` samples every joint at.
struct Timeline {
    times: Vec<f64>,
}

impl Timeline {
    fn of(channels: &[Channel]) -> Self {
        let mut times: Vec<f64> = Vec::new();
        for channel in channels {
            let keys = channel.times.iter().map(|&t| f64::from(t));
            times.extend(keys);
            if channel.interpolation == Interpolation::Step {
                times.extend(channel.times.iter().skip(1).map(|&t| f64::from(t) - STEP_LEAD));
            }
        }
        times.sort_by(f64::total_cmp);
        times.dedup();
        Timeline { times }
    }

    /// `channel`'s values at every time, as a glTF player plays it: held before its first key and after its last,
    /// linear between keys (rotations slerped), stepped where it steps.
    fn sampled(&self, channel: &Channel) -> Vec<f32> {
        let width = channel.values.len() / channel.times.len().max(1);
        let value = |k: usize| &channel.values[k * width..(k + 1) * width];
        let mut out = Vec::with_capacity(self.times.len() * width);
        let mut next = 0;
        for &time in &self.times {
            while next < channel.times.len() && f64::from(channel.times[next]) <= time {
                next += 1;
            }
            match next {
                0 => out.extend_from_slice(value(0)),
                n if n == channel.times.len() || channel.interpolation == Interpolation::Step => {
                    out.extend_from_slice(value(n - 1));
                }
                n => {
                    let (t0, t1) = (f64::from(channel.times[n - 1]), f64::from(channel.times[n]));
                    let f = (time - t0) / (t1 - t0);
                    out.extend(between(value(n - 1), value(n), f, channel.property));
                }
            }
        }
        out
    }
}

/// The linear parts of every joint's model matrix at one time, as baked (`L = L_parent·R·S`) and as played with
/// half-precision scales (`L′ = L′_parent·R·S′`): a joint's translation is written `t′ = L′_parent⁻¹·L_parent·t`, so
/// that the rounding of the scales above it moves no joint's origin, and only turns and stretches its axes by up to
/// 2⁻¹¹ of themselves.
struct HalfChain {
    baked: Vec<glam::DMat3>,
    played: Vec<glam::DMat3>,
}

impl HalfChain {
    fn new(joints: usize) -> Self {
        HalfChain { baked: Vec::with_capacity(joints), played: Vec::with_capacity(joints) }
    }

    /// Joint `n` (under `parent`, added before it) with its baked translation, rotation and scale, its scale
    /// written in half precision where `animated` (else it rests, in double precision): the translation and the
    /// half-precision scale to write.
    fn add(
        &mut self,
        n: usize,
        parent: Option<usize>,
        t: Vec3,
        q: Quat,
        scale: Vec3,
        animated: bool,
    ) -> (Vec3, [gf::f16; 3]) {
        debug_assert_eq!(n, self.baked.len(), "joints in order");
        let half = scale.to_array().map(gf::f16::from_f32);
        let rounded = match animated {
            true => glam::DVec3::from_array(half.map(|h| f64::from(h.to_f32()))),
            false => scale.as_dvec3(),
        };
        let turn = glam::DMat3::from_quat(q.as_dquat());
        let (above, above_played) =
            parent.map_or((glam::DMat3::IDENTITY, glam::DMat3::IDENTITY), |p| (self.baked[p], self.played[p]));
        let t = match above_played.inverse() {
            inverse if inverse.is_finite() => (inverse * above * t.as_dvec3()).as_vec3(),
            // Under a scale that half precision rounds to nothing no translation can make up for it.
            _ => t,
        };
        self.baked.push(above * turn * glam::DMat3::from_diagonal(scale.as_dvec3()));
        self.played.push(above_played * turn * glam::DMat3::from_diagonal(rounded));
        (t, half)
    }
}

/// How far `half` is from `value`, relatively (0 for a value it holds exactly).
fn relative_rounding(value: f32, half: gf::f16) -> f64 {
    let (value, half) = (f64::from(value), f64::from(half.to_f32()));
    if value == half { 0.0 } else { ((half - value) / value).abs() }
}

/// Which nodes the animation lists: those it keys, and every one below a node whose scale it keys (whose
/// translation makes up for the rounding of that scale, [`HalfChain`]). The others hold their rest transforms, in
/// double precision.
fn animated(nodes: &[Node], channels: &[Channel]) -> Vec<bool> {
    let (mut keyed, mut scaled) = (vec![false; nodes.len()], vec![false; nodes.len()]);
    for channel in channels.iter().filter(|c| c.property != Property::Weights) {
        keyed[channel.node] = true;
        scaled[channel.node] |= channel.property == Property::Scale;
    }
    let mut below_scaled = vec![false; nodes.len()];
    for (n, node) in nodes.iter().enumerate() {
        let under = node.parent.is_some_and(|p| scaled[p] || below_scaled[p]);
        below_scaled[n] = under;
        keyed[n] |= under;
    }
    keyed
}

/// `codes` empty lists, each with room for `count` values.
fn per_code<T>(codes: usize, count: usize) -> Vec<Vec<T>> {
    (0..codes).map(|_| Vec::with_capacity(count)).collect()
}

/// The `k`-th value of a channel sampled at every time code (each as wide as `rest`), or `rest` where it is not
/// keyed.
fn at_code<'v>(sampled: &'v Option<Vec<f32>>, rest: &'v [f32], k: usize) -> &'v [f32] {
    let width = rest.len();
    sampled.as_ref().map_or(rest, |values| &values[width * k..width * (k + 1)])
}

/// The time code of baked time `t`: on the 128th of a frame (where a bake's halvings of frames fall) that
/// single-precision key times only missed.
fn time_code(t: f64, clock: &Clock) -> f64 {
    let code = (t - clock.delay) * clock.codes_per_second;
    let snapped = (code * FRAME_PARTS).round() / FRAME_PARTS;
    if (code - snapped).abs() <= SNAP * (1.0 + snapped.abs()) { snapped } else { code }
}

/// The parts of a frame a time code snaps to ([`time_code`]).
const FRAME_PARTS: f64 = 128.0;

/// How close to one, relatively, a key time's code is taken for it: a single-precision time is kept to 6e-8 of
/// itself.
const SNAP: f64 = 1e-6;

/// The value a fraction `f` of the way from `a` to `b`: slerped for a rotation, else linear.
fn between(a: &[f32], b: &[f32], f: f64, property: Property) -> Vec<f32> {
    match property {
        Property::Rotation => {
            let q = |v: &[f32]| DQuat::from_xyzw(v[0].into(), v[1].into(), v[2].into(), v[3].into());
            let r = q(a).slerp(q(b), f);
            [r.x, r.y, r.z, r.w].map(|v| v as f32).to_vec()
        }
        _ => a.iter().zip(b).map(|(&x, &y)| (f64::from(x) + (f64::from(y) - f64::from(x)) * f) as f32).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(name: &str, parent: Option<usize>) -> Node {
        Node { name: name.to_owned(), ..Node::identity(parent) }
    }

    #[test]
    fn names_are_identifiers_unique_among_their_siblings_and_the_renaming_is_said() {
        assert_eq!(identifier("Bone.001"), "Bone_001");
        assert_eq!(identifier("mixamorig:Hips"), "mixamorig_Hips");
        assert_eq!(identifier("1st"), "_1st");
        assert_eq!(identifier(""), "_");
        assert_eq!(identifier("héllo"), "h_llo");
        let nodes = [node("root", None), node("a.b", Some(0)), node("a_b", Some(0)), node("a.b", Some(1))];
        let mut notes = Vec::new();
        let joints = Joints::of(&nodes, &mut notes);
        assert_eq!(joints.paths, ["root", "root/a_b", "root/a_b_1", "root/a_b/a_b"]);
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].contains("`a_b` → `a_b_1`"), "{notes:?}");
    }

    fn channel(property: Property, interpolation: Interpolation, times: &[f32], values: &[f32]) -> Channel {
        Channel { node: 0, property, interpolation, times: times.to_vec(), values: values.to_vec() }
    }

    #[test]
    fn a_channel_sampled_at_every_key_of_the_animation_keeps_its_curve_and_its_steps() {
        let linear = channel(Property::Translation, Interpolation::Linear, &[0.0, 1.0], &[0., 0., 0., 2., 4., 6.]);
        let step = channel(Property::Scale, Interpolation::Step, &[0.5, 1.5], &[1., 1., 1., 3., 3., 3.]);
        let timeline = Timeline::of(&[linear.clone(), step.clone()]);
        assert_eq!(timeline.times, [0.0, 0.5, 1.0, 1.5 - STEP_LEAD, 1.5]);
        let at = |values: &[f32], k: usize| values[3 * k];
        let sampled = timeline.sampled(&linear);
        // Held before the first key and after the last, linear between: the same curve through more points.
        assert_eq!([0, 1, 2, 3, 4].map(|k| at(&sampled, k)), [0.0, 1.0, 2.0, 2.0, 2.0]);
        let sampled = timeline.sampled(&step);
        assert_eq!([0, 1, 2, 3, 4].map(|k| at(&sampled, k)), [1.0, 1.0, 1.0, 1.0, 3.0], "held until just before");
    }

    #[test]
    fn rotations_sampled_between_keys_lie_on_the_keys_arc() {
        let turn = |degrees: f32| Quat::from_rotation_z(degrees.to_radians()).to_array();
        let values: Vec<f32> = [turn(0.0), turn(90.0)].concat();
        let rotation = channel(Property::Rotation, Interpolation::Linear, &[0.0, 1.0], &values);
        let other = channel(Property::Translation, Interpolation::Linear, &[0.0, 0.25, 1.0], &[0.0; 9]);
        let sampled = Timeline::of(&[rotation.clone(), other]).sampled(&rotation);
        let at_quarter = Quat::from_slice(&sampled[4..8]);
        assert!(at_quarter.abs_diff_eq(Quat::from_rotation_z(22.5f32.to_radians()), 1e-6), "{at_quarter}");
    }

    #[test]
    fn half_precision_scales_move_no_joints_origin() {
        // A chain whose scales half precision cannot hold (1.3, 0.77, 2.9…), each joint turned and offset: the
        // origins composed from the translations written and the rounded scales are the baked ones.
        let joints: Vec<(Option<usize>, Vec3, Quat, Vec3)> = vec![
            (None, Vec3::new(0.1, 1.0, 0.0), Quat::from_rotation_y(0.3), Vec3::new(1.3, 0.77, 1.0)),
            (Some(0), Vec3::new(0.0, 0.9, 0.1), Quat::from_rotation_x(0.7), Vec3::new(2.9, 1.0, 0.333)),
            (Some(1), Vec3::new(0.2, 0.6, -0.3), Quat::from_rotation_z(-1.1), Vec3::new(1.0, 1.7, 0.61)),
            (Some(2), Vec3::new(0.0, 0.5, 0.0), Quat::IDENTITY, Vec3::ONE),
        ];
        let mut chain = HalfChain::new(joints.len());
        let (mut baked, mut played): (Vec<DMat4>, Vec<DMat4>) = (Vec::new(), Vec::new());
        for (n, &(parent, t, q, s)) in joints.iter().enumerate() {
            let (written, half) = chain.add(n, parent, t, q, s, true);
            let rounded = Vec3::from_array(half.map(|h| h.to_f32()));
            assert!(s == Vec3::ONE || rounded != s, "the scale rounds");
            let matrix =
                |t: Vec3, s: Vec3| DMat4::from_scale_rotation_translation(s.as_dvec3(), q.as_dquat(), t.as_dvec3());
            let (b, p) = (matrix(t, s), matrix(written, rounded));
            baked.push(parent.map_or(b, |p| baked[p] * b));
            played.push(parent.map_or(p, |q| played[q] * p));
        }
        for (b, p) in baked.iter().zip(&played) {
            let apart = (b.w_axis - p.w_axis).truncate().length();
            assert!(apart < 1e-6, "origins {apart} apart");
        }
    }

    #[test]
    fn time_codes_fall_on_frames_that_single_precision_only_missed() {
        let clock = Clock { codes_per_second: 30.0, delay: 0.5, span: (0.0, 1.5) };
        assert_eq!(time_code(f64::from(17.0f32 / 30.0), &clock), 2.0, "(17/30 − 0.5) s at 30 codes a second");
        assert_eq!(time_code(f64::from(0.5f32 + 1.0 / 60.0), &clock), 0.5, "a key halfway stays halfway");
        assert_eq!(time_code(0.0, &clock), -15.0, "before the clip's own start: its own clock");
    }
}
