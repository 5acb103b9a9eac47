//! Which bone, mesh and clip of one file is which of another's.
//!
//! Bones are matched by name in four passes, each over what the earlier ones left: the user's explicit pairs
//! (`--map a=b`), exact names, names compared without case and without a namespace prefix (`mixamorig:Hips`,
//! `Armature|Hips` and `hips` are one name), then names as USD must spell them, every character that is not a
//! letter, digit or `_` made `_` (Blender's `Bone.001` is `Bone_001` in its USD export). A mesh object (a node a
//! mesh hangs on) pairs only with a mesh object: Blender names one parented to a bone after the bone, and the mesh
//! is not the joint. Repeated names pair up in file order. The node of a skinned mesh is no bone either: its vertices follow
//! the skin's joints, wherever the exporter put the node (Blender's glb puts it at the armature, its FBX where the
//! object stood), so it is left out, and so is the other file's node of its name, and the skin is compared instead. The helper nodes a bake inserts
//! (`<name>.stretch`, whose child is the bone `<name>`) are not bones of the rig and are left out of both sides, and
//! so are conversion nodes ([`Rig::conversion_nodes`]): whatever their names, they only state a file's axes and
//! unit, which the bones below them already carry into model space.

use std::collections::{HashMap, HashSet, VecDeque};

use super::DiffError;
use crate::eval::Evaluation;
use crate::model::{Clip, Mesh, Rig, Skeleton, UpAxis};

/// The suffix of the helper node a bake puts above a stretched bone.
pub const HELPER_SUFFIX: &str = ".stretch";

/// Bones of two skeletons paired up.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BoneMatching {
    /// `(bone in A, bone in B)`, in A's bone order.
    pub pairs: Vec<(usize, usize)>,
    /// Bones of A with no partner, in bone order (helper nodes not included).
    pub only_a: Vec<usize>,
    pub only_b: Vec<usize>,
    /// How many helper nodes were left out, on both sides together.
    pub helpers: usize,
    /// The conversion nodes of each side, left out, in bone order.
    pub conversion_a: Vec<usize>,
    pub conversion_b: Vec<usize>,
    /// The nodes of each side's skinned meshes, left out, in bone order.
    pub skinned_a: Vec<usize>,
    pub skinned_b: Vec<usize>,
}

/// For each bone, whether it is a mesh object: a leaf a mesh hangs on (a skinned one only where `skinned`). A node
/// with bones below it is the skeleton's, whatever it carries.
fn mesh_nodes(rig: &Rig, skinned: bool) -> Vec<bool> {
    let mut nodes = vec![false; rig.skeleton.len()];
    for mesh in rig.meshes.iter().filter(|m| !skinned || m.skin.is_some()) {
        if let Some(node) = nodes.get_mut(mesh.bone) {
            *node = true;
        }
    }
    for parent in rig.skeleton.bones().iter().filter_map(|b| b.parent) {
        nodes[parent] = false;
    }
    nodes
}

/// For each bone of `rig`, whether it is left out as a skinned mesh's node: it is one, or `other` has one of its
/// name (which of the two files skins there, its skin is compared, not the node).
fn skinned_nodes(rig: &Rig, other: &Rig) -> Vec<bool> {
    let (own, theirs) = (mesh_nodes(rig, true), mesh_nodes(other, true));
    let names: HashSet<&str> =
        other.skeleton.bones().iter().zip(theirs).filter(|(_, s)| *s).map(|(b, _)| b.name.as_str()).collect();
    rig.skeleton.bones().iter().zip(own).map(|(bone, own)| own || names.contains(bone.name.as_str())).collect()
}

/// For each bone, whether it is a bake's helper node: named `<name>.stretch` with a child named `<name>`.
pub fn helpers(skeleton: &Skeleton) -> Vec<bool> {
    let bones = skeleton.bones();
    let mut helper = vec![false; bones.len()];
    for bone in bones {
        if let Some(p) = bone.parent
            && bones[p].name.strip_suffix(HELPER_SUFFIX) == Some(bone.name.as_str())
        {
            helper[p] = true;
        }
    }
    helper
}

/// The name without case and without a namespace prefix (everything up to the last `:` or `|`).
pub fn loose_name(name: &str) -> String {
    name.rsplit([':', '|']).next().unwrap_or(name).to_lowercase()
}

/// The loose name as a USD identifier spells it ([`usd_identifier`]).
pub fn usd_name(name: &str) -> String {
    usd_identifier(&loose_name(name))
}

/// `name` spelt as a USD identifier (`[A-Za-z_][A-Za-z0-9_]*`): every character but an ASCII letter, a digit or `_`
/// made `_`, and `_` before a leading digit (or for no name at all). USD exporters spell names so (Blender's
/// `Bone.001` is `Bone_001`), and so does a bake to USD.
pub fn usd_identifier(name: &str) -> String {
    let spelt: String = name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    match spelt.chars().next() {
        Some(c) if !c.is_ascii_digit() => spelt,
        _ => format!("_{spelt}"),
    }
}

/// Pairs the bones of `a` and `b` by name (see the module's documentation).
pub fn match_bones(a: &Rig, b: &Rig) -> BoneMatching {
    Unmatched::new(a, b).by_name()
}

/// [`match_bones`] after the explicit `(name in A, name in B)` pairs of `map`; a pair that names no bone (or one
/// already taken) is an error naming it.
pub fn match_bones_mapped(a: &Rig, b: &Rig, map: &[(String, String)]) -> Result<BoneMatching, DiffError> {
    let mut unmatched = Unmatched::new(a, b);
    for (name_a, name_b) in map {
        let no_bone =
            |name: &str, file| DiffError::NoBone { map: format!("{name_a}={name_b}"), name: name.to_owned(), file };
        let i = take(&mut unmatched.left_a, &a.skeleton, name_a).ok_or_else(|| no_bone(name_a, "first"))?;
        let j = take(&mut unmatched.left_b, &b.skeleton, name_b).ok_or_else(|| no_bone(name_b, "second"))?;
        unmatched.pairs.push((i, j));
    }
    Ok(unmatched.by_name())
}

/// The bone named `name` among those `left` (removed from them).
fn take(left: &mut Vec<usize>, skeleton: &Skeleton, name: &str) -> Option<usize> {
    let at = left.iter().position(|&i| skeleton.bone(i).name == name)?;
    Some(left.remove(at))
}

/// Two skeletons' bones while they are being paired: the pairs so far and the bones left on each side.
struct Unmatched<'s> {
    a: &'s Rig,
    b: &'s Rig,
    left_a: Vec<usize>,
    left_b: Vec<usize>,
    pairs: Vec<(usize, usize)>,
    helpers: usize,
    conversion_a: Vec<usize>,
    conversion_b: Vec<usize>,
    skinned_a: Vec<usize>,
    skinned_b: Vec<usize>,
}

impl<'s> Unmatched<'s> {
    /// Every bone of both but the helper, conversion and skinned meshes' nodes.
    fn new(a: &'s Rig, b: &'s Rig) -> Self {
        let (helpers_a, helpers_b) = (helpers(&a.skeleton), helpers(&b.skeleton));
        let helpers = [&helpers_a, &helpers_b].iter().map(|h| h.iter().filter(|&&h| h).count()).sum();
        // A conversion node the other file holds as a bone of the same name (its format knows no joints, and a
        // bake's node converted nothing there) is paired like any bone, unless its own file holds that bone too (a
        // USD bake's skeleton prim, named as the skeleton it baked).
        let (nodes_a, nodes_b) = (a.conversion_nodes(), b.conversion_nodes());
        let bone_named = |rig: &Rig, nodes: &[bool], name: &str| {
            rig.skeleton.bones().iter().zip(nodes).any(|(bone, &conversion)| !conversion && bone.name == name)
        };
        let apart = |rig: &Rig, nodes: &[bool], other: &Rig, other_nodes: &[bool]| -> Vec<bool> {
            let paired = |name: &str| bone_named(other, other_nodes, name) && !bone_named(rig, nodes, name);
            nodes.iter().zip(rig.skeleton.bones()).map(|(&c, bone)| c && !paired(&bone.name)).collect()
        };
        let (conversion_a, left_a) = split(&apart(a, &nodes_a, b, &nodes_b), &helpers_a);
        let (conversion_b, left_b) = split(&apart(b, &nodes_b, a, &nodes_a), &helpers_b);
        let (skinned_a, left_a) = apart_from(left_a, &skinned_nodes(a, b));
        let (skinned_b, left_b) = apart_from(left_b, &skinned_nodes(b, a));
        Unmatched { a, b, left_a, left_b, pairs: Vec::new(), helpers, conversion_a, conversion_b, skinned_a, skinned_b }
    }

    /// The bones left paired by exact name, then by loose name, then as USD spells them, mesh objects with mesh
    /// objects.
    fn by_name(mut self) -> BoneMatching {
        let (a, b) = (&self.a.skeleton, &self.b.skeleton);
        let (meshes_a, meshes_b) = (mesh_nodes(self.a, false), mesh_nodes(self.b, false));
        for spelling in [str::to_owned, loose_name, usd_name] {
            let key_a = |i: usize| (meshes_a[i], spelling(&a.bone(i).name));
            let key_b = |j: usize| (meshes_b[j], spelling(&b.bone(j).name));
            pair_by_key(&mut self.left_a, &mut self.left_b, &mut self.pairs, key_a, key_b);
        }
        self.pairs.sort_unstable();
        BoneMatching {
            pairs: self.pairs,
            only_a: self.left_a,
            only_b: self.left_b,
            helpers: self.helpers,
            conversion_a: self.conversion_a,
            conversion_b: self.conversion_b,
            skinned_a: self.skinned_a,
            skinned_b: self.skinned_b,
        }
    }
}

/// The bones that are `conversion` nodes, and those to pair (neither conversion nor `helper` nodes).
fn split(conversion: &[bool], helper: &[bool]) -> (Vec<usize>, Vec<usize>) {
    let bones = 0..conversion.len();
    let (conversion, pair): (Vec<usize>, Vec<usize>) = bones.filter(|&i| !helper[i]).partition(|&i| conversion[i]);
    (conversion, pair)
}

/// The bones of `left` that are `flagged`, and the others.
fn apart_from(left: Vec<usize>, flagged: &[bool]) -> (Vec<usize>, Vec<usize>) {
    left.into_iter().partition(|&i| flagged[i])
}

/// Pairs the bones left on each side whose keys agree, the k-th of a key in A with the k-th in B, and removes them
/// from what is left.
fn pair_by_key<K: std::hash::Hash + Eq>(
    left_a: &mut Vec<usize>,
    left_b: &mut Vec<usize>,
    pairs: &mut Vec<(usize, usize)>,
    key_a: impl Fn(usize) -> K,
    key_b: impl Fn(usize) -> K,
) {
    let mut by_key: HashMap<K, VecDeque<usize>> = HashMap::new();
    for &j in left_b.iter() {
        by_key.entry(key_b(j)).or_default().push_back(j);
    }
    let mut matched_b = HashSet::new();
    left_a.retain(|&i| match by_key.get_mut(&key_a(i)).and_then(VecDeque::pop_front) {
        Some(j) => {
            pairs.push((i, j));
            matched_b.insert(j);
            false
        }
        None => true,
    });
    left_b.retain(|j| !matched_b.contains(j));
}

/// Meshes paired by name and vertex count (repeated names in file order): `(mesh in A, mesh in B)`.
pub fn match_meshes(a: &[Mesh], b: &[Mesh]) -> Vec<(usize, usize)> {
    let mut taken = vec![false; b.len()];
    let mut pairs = Vec::new();
    for (i, mesh) in a.iter().enumerate() {
        let partner = b.iter().enumerate().position(|(j, other)| {
            !taken[j] && other.name == mesh.name && other.positions.len() == mesh.positions.len()
        });
        if let Some(j) = partner {
            taken[j] = true;
            pairs.push((i, j));
        }
    }
    pairs
}

/// Clips paired by label (their name, or `animation N` for the N-th unnamed one, which is what a bake names it),
/// exactly, then as [`loose_name`] compares names (Blender's FBX names a take `Armature|walk`):
/// `(clip in A, clip in B)`, and the clips of each side left without a partner.
pub fn match_clips(a: &[Clip], b: &[Clip]) -> (Vec<(usize, usize)>, Vec<usize>, Vec<usize>) {
    let mut taken = vec![false; b.len()];
    let mut partner: Vec<Option<usize>> = vec![None; a.len()];
    for key in [Clip::label, |c: &Clip| loose_name(&c.label())] {
        for (i, clip) in a.iter().enumerate() {
            if partner[i].is_some() {
                continue;
            }
            let label = key(clip);
            if let Some(j) = (0..b.len()).find(|&j| !taken[j] && key(&b[j]) == label) {
                taken[j] = true;
                partner[i] = Some(j);
            }
        }
    }
    let pairs = partner.iter().enumerate().filter_map(|(i, j)| j.map(|j| (i, j))).collect();
    let only_a = (0..a.len()).filter(|&i| partner[i].is_none()).collect();
    let only_b = (0..b.len()).filter(|&j| !taken[j]).collect();
    (pairs, only_a, only_b)
}

/// The axes two rigs stand along, `[A's, B's]`, where they differ: one file's skeleton lies down beside the
/// other's (a Z-up BVH beside its Y-up glTF), and every distance between them would measure the turn, not the
/// motion. Each figure is looked at as it plays ([`standing`]). `None` where they agree or either figure stands
/// along neither Y nor Z clearly.
pub fn standing_apart((a, clip_a): (&Rig, Option<usize>), (b, clip_b): (&Rig, Option<usize>)) -> Option<[UpAxis; 2]> {
    let (a, b) = (standing(a, clip_a)?, standing(b, clip_b)?);
    (a != b).then_some([a, b])
}

/// The axis a rig's figure stands along as it plays, at the start of `clip` (its rest pose for `None`): a rest pose
/// may lie otherwise than every frame (Blender's FBX rests its bones as they were edited, along Z). `None` where it
/// stands along neither Y nor Z clearly.
pub fn standing(rig: &Rig, clip: Option<usize>) -> Option<UpAxis> {
    let figure = rig.skeleton.figure();
    let playing = Evaluation::declared(rig, clip.and_then(|c| rig.clips.get(c)));
    let model = playing.pose_at(playing.span().start).model.model;
    let heads = model.into_iter().enumerate().filter(|&(i, _)| figure[i]);
    UpAxis::standing(heads.map(|(_, m)| m.w_axis.truncate()))
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::model::{Bone, Mesh, NodeRole, Skin, Transform, named_skeleton};

    /// A rig of bones named and parented, each a step along X from its parent (so that none is a conversion node).
    fn rig(bones: &[(&str, Option<usize>)]) -> Rig {
        let step = Transform::from_trs(DVec3::X, DQuat::IDENTITY, DVec3::ONE);
        let moved = named_skeleton(bones).bones().iter().map(|b| Bone { rest: step, ..b.clone() }).collect();
        Rig { skeleton: Skeleton::new(moved).unwrap(), ..Rig::default() }
    }

    #[test]
    fn exact_then_loose_then_mapped() {
        let a = rig(&[("Hips", None), ("mixamorig:Spine", Some(0)), ("Armature|Head", Some(1)), ("Tail", None)]);
        let b = rig(&[("hips", None), ("Hips", None), ("spine", Some(1)), ("HEAD", Some(2)), ("Cape", None)]);
        let m = match_bones(&a, &b);
        assert_eq!(m.pairs, [(0, 1), (1, 2), (2, 3)], "exact `Hips` wins over the loose `hips`");
        assert_eq!((m.only_a, m.only_b), (vec![3], vec![0, 4]));
        let mapped = match_bones_mapped(&a, &b, &[("Tail".into(), "Cape".into())]).unwrap();
        assert!(mapped.pairs.contains(&(3, 4)));
        let error = match_bones_mapped(&a, &b, &[("Nope".into(), "Cape".into())]).unwrap_err();
        assert_eq!(error.to_string(), "--map Nope=Cape: no unmatched bone `Nope` in the first file");
    }

    #[test]
    fn repeated_names_pair_in_order_and_helpers_are_left_out() {
        let a = rig(&[("root", None), ("joint", Some(0)), ("joint", Some(1))]);
        let b = rig(&[("root", None), ("joint.stretch", Some(0)), ("joint", Some(1)), ("joint", Some(2))]);
        let m = match_bones(&a, &b);
        assert_eq!(m.pairs, [(0, 0), (1, 2), (2, 3)]);
        assert_eq!(m.helpers, 1);
        assert!(m.only_a.is_empty() && m.only_b.is_empty());
        // A bone merely named like a helper, without the matching child, is a bone.
        let lone = named_skeleton(&[("arm.stretch", None), ("hand", Some(0))]);
        assert_eq!(helpers(&lone), [false, false]);
    }

    #[test]
    fn conversion_nodes_are_left_out_whatever_their_names() {
        // A: an armature turned −90° about X above the hips (Blender's FBX); B: a `Scene` node at identity above
        // them (a glTF exporter's). Neither is compared, and neither is a bone without a partner.
        let mut a = rig(&[("Armature", None), ("hips", Some(0)), ("spine", Some(1))]);
        let mut b = rig(&[("Scene", None), ("hips", Some(0)), ("spine", Some(1))]);
        let turned = Transform::from_trs(DVec3::ZERO, DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2), DVec3::ONE);
        for (rig, rest) in [(&mut a, turned), (&mut b, Transform::IDENTITY)] {
            let bones = rig.skeleton.bones().iter().enumerate();
            // The top node is an armature object or a null, not a joint.
            let top = |bone: &Bone| Bone { rest, role: NodeRole::Helper, ..bone.clone() };
            let bones = bones.map(|(i, bone)| if i == 0 { top(bone) } else { bone.clone() });
            rig.skeleton = Skeleton::new(bones.collect()).unwrap();
        }
        let m = match_bones(&a, &b);
        assert_eq!(m.pairs, [(1, 1), (2, 2)]);
        assert_eq!((m.conversion_a, m.conversion_b), (vec![0], vec![0]));
        assert!(m.only_a.is_empty() && m.only_b.is_empty());
    }

    #[test]
    fn clips_pair_by_label_then_loosely() {
        let clip = |index: usize, name: Option<&str>| Clip::new(index, name.map(str::to_owned), vec![], vec![]);
        let a = [clip(0, Some("walk")), clip(1, Some("run")), clip(2, None)];
        let b =
            [clip(0, Some("Armature|run")), clip(1, Some("walk")), clip(2, Some("animation 2")), clip(3, Some("jog"))];
        let (pairs, only_a, only_b) = match_clips(&a, &b);
        assert_eq!(pairs, [(0, 1), (1, 0), (2, 2)]);
        assert!(only_a.is_empty());
        assert_eq!(only_b, [3]);
    }

    #[test]
    fn joints_pair_with_joints_and_meshes_with_meshes_each_once() {
        // Blender's glb and FBX both name a mesh object parented to the bone `Foot.L` after it; a skinned mesh's
        // node is left out, and so is the other file's node of its name, wherever it stands.
        let with_mesh = |parents: [Option<usize>; 4], object: usize, skinned: Option<usize>| {
            let names = ["Hips", "Foot.L", "Foot.L", "Body"];
            let mut r = rig(&names.into_iter().zip(parents).collect::<Vec<_>>());
            let skin = Skin { joints: vec![0], ..Skin::default() };
            r.skins = vec![skin];
            let mesh =
                |bone: usize, skin: Option<usize>| Mesh { name: names[bone].into(), bone, skin, ..Mesh::default() };
            r.meshes =
                [Some(mesh(object, None)), skinned.map(|bone| mesh(bone, Some(0)))].into_iter().flatten().collect();
            r
        };
        // A: the joint, then the mesh object hanging from it, the skinned body; B: the mesh object first, beside the
        // joint, and the body a plain node.
        let a = with_mesh([None, Some(0), Some(1), None], 2, Some(3));
        let b = with_mesh([None, Some(0), Some(0), None], 1, None);
        let m = match_bones(&a, &b);
        assert_eq!(m.pairs, [(0, 0), (1, 2), (2, 1)], "the joint with the joint, the mesh with the mesh");
        assert!(m.only_a.is_empty() && m.only_b.is_empty(), "{m:?}");
        assert_eq!((m.skinned_a, m.skinned_b), (vec![3], vec![3]));
    }

    #[test]
    fn usd_spelling_pairs_last() {
        let a = rig(&[("Bone", None), ("Bone.001", Some(0)), ("2nd-arm", Some(1)), ("Bone_001", None)]);
        let b = rig(&[("Bone", None), ("Bone_001", Some(0)), ("_2nd_arm", Some(1)), ("Bone_001", None)]);
        let m = match_bones(&a, &b);
        assert_eq!(m.pairs, [(0, 0), (1, 3), (2, 2), (3, 1)], "the exact `Bone_001` first, then the spellings");
        assert_eq!(usd_name("mixamorig:Left Hand.001"), "left_hand_001");
        assert_eq!(usd_name("3d"), "_3d");
    }

    #[test]
    fn loose_names() {
        assert_eq!(loose_name("mixamorig:LeftArm"), "leftarm");
        assert_eq!(loose_name("Armature|Bone.001"), "bone.001");
        assert_eq!(loose_name("a:b|C"), "c");
    }
}
