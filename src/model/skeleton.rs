//! The bone hierarchy: flat arrays ordered parents-first, addressed by index.

use super::{InheritMode, ModeChoice, Transform};

/// One bone (every node of the source scene becomes one).
#[derive(Clone, Debug, PartialEq)]
pub struct Bone {
    pub name: String,
    /// The node's index in the source file.
    pub node: usize,
    /// Index of the parent bone; always smaller than this bone's own index.
    pub parent: Option<usize>,
    /// The local transform when no clip animates the bone.
    pub rest: Transform,
    /// The mode the file declares (`full` where the format has no such notion).
    pub inherit: InheritMode,
    /// What the node is: a joint of the figure or something the file carries beside it.
    pub role: NodeRole,
}

impl Bone {
    /// A joint under `parent` that inherits fully, of node 0: what hand-built rigs start from (other fields by struct
    /// update).
    pub fn joint(name: impl Into<String>, parent: Option<usize>, rest: Transform) -> Bone {
        Bone { name: name.into(), node: 0, parent, rest, inherit: InheritMode::Full, role: NodeRole::Joint }
    }

    /// The name a reader gives node `node` of a file that names it not: `node7`, an identifier the command line's
    /// options and `diff`'s pairing can use.
    pub fn unnamed(node: usize) -> String {
        format!("node{node}")
    }

    /// The name for people: a node its file leaves unnamed reads "(node 7)", so that it is not taken for a name the
    /// file gave.
    pub fn shown_name(&self) -> std::borrow::Cow<'_, str> {
        if self.name.is_empty() || self.name == Bone::unnamed(self.node) {
            format!("(node {})", self.node).into()
        } else {
            self.name.as_str().into()
        }
    }
}

/// What a node of the source scene is. Files carry more than the character: DCC exports keep their cameras (3ds Max
/// writes six "Producer" cameras 150 m out), lights, camera targets, IK effectors and meshes as nodes beside the
/// joints. Those are listed apart, neither drawn as bones nor framed by default (see [`NodeRole::is_figure`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum NodeRole {
    /// A joint of the skeleton (an FBX limb node or skin cluster's bone, a glTF skin joint or animated node, a BVH
    /// joint), or a node joints hang from (a null above the hips moves the whole figure).
    #[default]
    Joint,
    /// The tip of a chain: a BVH `End Site`, where its parent's bone ends; no bone of its own starts there.
    EndSite,
    /// A node that shows a mesh and is no joint.
    Mesh,
    Camera,
    Light,
    /// Any other node: an FBX null or marker (a camera's target, an IK effector), a glTF node with no part in a
    /// skin or the animation and none below a joint.
    Helper,
}

impl NodeRole {
    /// Whether the node belongs to the figure: the joints and their tips, which are drawn as bones and framed.
    pub fn is_figure(self) -> bool {
        matches!(self, NodeRole::Joint | NodeRole::EndSite)
    }

    /// The role in a word, for lists.
    pub fn label(self) -> &'static str {
        match self {
            NodeRole::Joint => "joint",
            NodeRole::EndSite => "end site",
            NodeRole::Mesh => "mesh",
            NodeRole::Camera => "camera",
            NodeRole::Light => "light",
            NodeRole::Helper => "helper",
        }
    }
}

/// Bones in parents-first order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skeleton {
    bones: Vec<Bone>,
    /// [`Skeleton::figure`], found once: the roles do not change after [`Skeleton::new`].
    figure: Vec<bool>,
    /// Per bone, whether the file made it something else than a joint and [`Skeleton::new`] made it one.
    promoted: Vec<bool>,
    /// The file's own unit and axes in bonescope's space ([`Skeleton::placement`]), and what follows from it, found
    /// once when it is set: [`Skeleton::placed_by`] and [`Skeleton::length_scales`].
    placement: Placement,
    placed_by: Vec<Option<usize>>,
    length_scales: Vec<f64>,
}

/// Where a file's space sits in bonescope's (Y-up metres): the conversion of its unit and axes, above every root,
/// and the conversion nodes at the top of its hierarchy. Both stand outside the rig: every inheritance mode is
/// evaluated in the file's own space, where no bone's parent carries them, and the result is then placed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Placement {
    /// A similarity about the origin (a rotation between axes times a uniform scale between units): identity where
    /// the file is already in Y-up metres or is read in its own space.
    pub conversion: glam::DMat4,
    /// Per bone, whether it is a conversion node ([`crate::model::Rig::conversion_nodes`]); empty for none.
    pub conversion_nodes: Vec<bool>,
}

impl Placement {
    /// Whether every bone is placed as it is.
    pub fn is_identity(&self) -> bool {
        self.conversion == glam::DMat4::IDENTITY && !self.conversion_nodes.contains(&true)
    }

    /// Whether `bone` is a conversion node.
    pub fn is_conversion(&self, bone: usize) -> bool {
        self.conversion_nodes.get(bone).copied().unwrap_or(false)
    }

    /// The uniform scale of the conversion above the roots: what it multiplies lengths by.
    pub fn conversion_scale(&self) -> f64 {
        uniform_scale(&self.conversion)
    }
}

/// How close to 1 a top-level node's model scale must be for its own scale to count as undoing the unit.
const UNIT_UNDONE: f64 = 1e-6;

/// The uniform scale of a similarity `m`: the cube root of its determinant's size.
fn uniform_scale(m: &glam::DMat4) -> f64 {
    m.determinant().abs().cbrt()
}

/// A bone list that is not in parents-first order.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("bone {bone} (`{name}`) has parent {parent}, which does not come before it")]
pub struct ParentOrderError {
    pub bone: usize,
    pub name: String,
    pub parent: usize,
}

impl Skeleton {
    /// Builds a skeleton, checking that every parent comes before its children. A node that figure bones hang from
    /// is a joint whatever the file made of it: its transform moves them.
    pub fn new(mut bones: Vec<Bone>) -> Result<Self, ParentOrderError> {
        for (index, bone) in bones.iter().enumerate() {
            if let Some(parent) = bone.parent.filter(|&p| p >= index) {
                return Err(ParentOrderError { bone: index, name: bone.name.clone(), parent });
            }
        }
        // Children come after their parents: walking backwards reaches every descendant before its ancestors.
        let mut promoted = vec![false; bones.len()];
        for index in (0..bones.len()).rev() {
            if let Some(parent) = bones[index].parent
                && bones[index].role.is_figure()
                && !bones[parent].role.is_figure()
            {
                bones[parent].role = NodeRole::Joint;
                promoted[parent] = true;
            }
        }
        let figure: Vec<bool> = bones.iter().map(|b| b.role.is_figure()).collect();
        let figure = if figure.contains(&true) { figure } else { vec![true; figure.len()] };
        let length_scales = vec![1.0; bones.len()];
        Ok(Skeleton { bones, figure, promoted, placement: Placement::default(), placed_by: Vec::new(), length_scales })
    }

    /// The same bones placed by `placement` (its conversion nodes, where given, one flag per bone).
    pub fn placed(mut self, placement: Placement) -> Self {
        debug_assert!(placement.conversion_nodes.is_empty() || placement.conversion_nodes.len() == self.len());
        self.placement = placement;
        self.placed_by = if self.placement.is_identity() { Vec::new() } else { self.find_placed_by() };
        self.length_scales = self.find_length_scales();
        self
    }

    /// Where the file's space sits in bonescope's.
    pub fn placement(&self) -> &Placement {
        &self.placement
    }

    /// Per bone, the conversion node that places it (itself for a conversion node), or `None` for the skeleton's
    /// conversion; empty where nothing is placed.
    pub fn placed_by(&self) -> &[Option<usize>] {
        &self.placed_by
    }

    /// Per bone, the uniform scale of the conversion above it at rest (1 where none): what its model matrix's scale
    /// factors are divided by to be the ones the file's author set, in the file's unit. A top-level node whose own
    /// uniform scale undoes the unit (its model scale is 1: Blender's FBX exporter writes every object of a scene
    /// in metres so, ×100 in a file in centimetres) is read in metres as written, with everything below it: that
    /// scale is the unit's, not its author's, as Blender's importer and the scene's glTF export say.
    pub fn length_scales(&self) -> &[f64] {
        &self.length_scales
    }

    fn find_placed_by(&self) -> Vec<Option<usize>> {
        let mut placed_by: Vec<Option<usize>> = Vec::with_capacity(self.len());
        for (i, bone) in self.bones.iter().enumerate() {
            let own = self.placement.is_conversion(i).then_some(i);
            placed_by.push(own.or_else(|| bone.parent.and_then(|p| placed_by[p])));
        }
        placed_by
    }

    fn find_length_scales(&self) -> Vec<f64> {
        if self.placement.is_identity() {
            return vec![1.0; self.len()];
        }
        let rest = self.rest_model_matrices();
        let mut tops: Vec<usize> = Vec::with_capacity(self.len());
        for (i, bone) in self.bones.iter().enumerate() {
            tops.push(bone.parent.map_or(i, |p| tops[p]));
        }
        let unit = |i: usize| {
            let undone = (uniform_scale(&rest[tops[i]]) - 1.0).abs() < UNIT_UNDONE;
            if undone { 1.0 } else { self.placement.conversion_scale() }
        };
        let above = |i: usize, bone: Option<usize>| bone.map_or_else(|| unit(i), |b| uniform_scale(&rest[b]));
        (0..self.len())
            .map(|i| match self.placed_by[i] {
                Some(node) if node == i => above(i, self.bones[i].parent),
                node => above(i, node),
            })
            .collect()
    }

    pub fn len(&self) -> usize {
        self.bones.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bones.is_empty()
    }

    pub fn bones(&self) -> &[Bone] {
        &self.bones
    }

    pub fn bone(&self, index: usize) -> &Bone {
        &self.bones[index]
    }

    pub fn parent(&self, index: usize) -> Option<usize> {
        self.bones[index].parent
    }

    /// The first bone with this exact name, else the first whose [`path`](Skeleton::path) ends with `name` at a
    /// `/` (`upper_arm/forearm`, or USD's joint path `hips/spine`): where names repeat (`Left/Hand`,
    /// `Right/Hand`), the path says which.
    pub fn find(&self, name: &str) -> Option<usize> {
        let by_name = self.bones.iter().position(|b| b.name == name);
        by_name.or_else(|| {
            let tail = name.trim_start_matches('/');
            (!tail.is_empty() && tail.contains('/')).then(|| {
                let ends = |path: String| path == tail || path.ends_with(&format!("/{tail}"));
                (0..self.bones.len()).find(|&b| ends(self.path(b)))
            })?
        })
    }

    /// The names from the root down to `bone`, joined by `/` (`hips/spine/chest`).
    pub fn path(&self, bone: usize) -> String {
        let mut names = vec![self.bones[bone].name.as_str()];
        let mut current = self.bones[bone].parent;
        while let Some(parent) = current {
            names.push(&self.bones[parent].name);
            current = self.bones[parent].parent;
        }
        names.reverse();
        names.join("/")
    }

    /// The bone that came from source node `node`.
    pub fn find_node(&self, node: usize) -> Option<usize> {
        self.bones.iter().position(|b| b.node == node)
    }

    /// The modes the file declares, one per bone.
    pub fn declared_modes(&self) -> Vec<InheritMode> {
        self.bones.iter().map(|b| b.inherit).collect()
    }

    /// The mode `choice` gives each bone.
    pub fn modes(&self, choice: ModeChoice) -> Vec<InheritMode> {
        self.bones.iter().map(|b| choice.mode_for(b.inherit)).collect()
    }

    /// Per bone, whether it belongs to the figure ([`NodeRole::is_figure`]); every bone when none does (a file of
    /// nulls or of rigid meshes has nothing else to show).
    pub fn figure(&self) -> &[bool] {
        &self.figure
    }

    /// Whether the file itself made `bone` a joint or an end site (rather than a node joints hang from, made a
    /// joint by [`Skeleton::new`]).
    pub fn declared_figure(&self, bone: usize) -> bool {
        self.bones[bone].role.is_figure() && !self.promoted[bone]
    }

    /// Per bone, whether it is of the character: of the figure and not a conversion node (which stands outside the
    /// rig, however many bones hang from it).
    pub fn character(&self) -> Vec<bool> {
        self.figure.iter().enumerate().map(|(i, &figure)| figure && !self.placement.is_conversion(i)).collect()
    }

    /// The rest pose, one local transform per bone.
    pub fn rest_pose(&self) -> Vec<Transform> {
        self.bones.iter().map(|b| b.rest).collect()
    }

    /// Model matrices of the rest pose with plain (full) inheritance, placed (under full inheritance a conversion
    /// node is an ordinary parent).
    pub fn rest_model_matrices(&self) -> Vec<glam::DMat4> {
        let mut model: Vec<glam::DMat4> = Vec::with_capacity(self.bones.len());
        for bone in &self.bones {
            let local = bone.rest.matrix();
            model.push(bone.parent.map_or(self.placement.conversion * local, |p| model[p] * local));
        }
        model
    }

    /// Number of ancestors of each bone (0 for roots).
    pub fn depths(&self) -> Vec<usize> {
        let mut depths = Vec::with_capacity(self.bones.len());
        for bone in &self.bones {
            depths.push(bone.parent.map_or(0, |p| depths[p] + 1));
        }
        depths
    }

    /// `bone` and its ancestors, the root first and `bone` last.
    pub fn chain(&self, bone: usize) -> Vec<usize> {
        let mut chain: Vec<usize> = std::iter::successors(Some(bone), |&b| self.bones[b].parent).collect();
        chain.reverse();
        chain
    }

    /// `bones` (those in range) and every ancestor of each, once each, parents first.
    pub fn with_ancestors(&self, bones: &[usize]) -> Vec<usize> {
        let mut wanted = vec![false; self.len()];
        for &bone in bones.iter().filter(|&&b| b < self.len()) {
            let mut next = Some(bone);
            while let Some(b) = next.filter(|&b| !wanted[b]) {
                wanted[b] = true;
                next = self.parent(b);
            }
        }
        (0..self.len()).filter(|&b| wanted[b]).collect()
    }

    /// `top` and every bone below it, in bone order.
    pub fn subtree(&self, top: usize) -> Vec<usize> {
        // Parents come first, so one pass in order finds them all.
        let mut inside = vec![false; self.bones.len()];
        let mut bones = Vec::new();
        for b in top..self.bones.len() {
            inside[b] = b == top || self.bones[b].parent.is_some_and(|p| inside[p]);
            if inside[b] {
                bones.push(b);
            }
        }
        bones
    }

    /// Whether `bone` is `ancestor` or lies below it.
    pub fn is_in_subtree(&self, bone: usize, ancestor: usize) -> bool {
        let mut current = Some(bone);
        while let Some(b) = current {
            if b == ancestor {
                return true;
            }
            current = self.bones[b].parent;
        }
        false
    }
}

/// Skeletons for tests: bones named and parented, at rest at the origin, fully inheriting.
#[cfg(test)]
pub(crate) fn named(bones: &[(&str, Option<usize>)]) -> Skeleton {
    let bone = |(name, parent): &(&str, Option<usize>)| Bone {
        name: (*name).to_owned(),
        node: 0,
        parent: *parent,
        rest: Transform::IDENTITY,
        inherit: InheritMode::Full,
        role: NodeRole::Joint,
    };
    Skeleton::new(bones.iter().map(bone).collect()).expect("parents first")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bone(name: &str, parent: Option<usize>) -> Bone {
        Bone {
            name: name.into(),
            node: 0,
            parent,
            rest: Transform::IDENTITY,
            inherit: InheritMode::Full,
            role: NodeRole::Joint,
        }
    }

    #[test]
    fn rejects_children_before_parents() {
        let err = Skeleton::new(vec![bone("a", Some(1)), bone("b", None)]).unwrap_err();
        assert_eq!(err.bone, 0);
        assert!(Skeleton::new(vec![bone("a", Some(0))]).is_err(), "a bone cannot be its own parent");
    }

    #[test]
    fn depths_and_subtrees() {
        let s = Skeleton::new(vec![bone("root", None), bone("a", Some(0)), bone("b", Some(1)), bone("c", Some(0))])
            .unwrap();
        assert_eq!(s.depths(), vec![0, 1, 2, 1]);
        assert!(s.is_in_subtree(2, 1) && s.is_in_subtree(2, 0) && !s.is_in_subtree(3, 1));
        assert_eq!(s.find("c"), Some(3));
    }

    #[test]
    fn a_path_finds_a_bone_whose_name_repeats() {
        // Skel → Left → Hand, Skel → Right → Hand (USD names joints by path; their last elements may repeat).
        let s = named(&[("Skel", None), ("Left", Some(0)), ("Hand", Some(1)), ("Right", Some(0)), ("Hand", Some(3))]);
        assert_eq!(s.path(4), "Skel/Right/Hand");
        assert_eq!(s.find("Hand"), Some(2), "a name: the first");
        assert_eq!(s.find("Right/Hand"), Some(4));
        assert_eq!(s.find("Skel/Right/Hand"), Some(4));
        assert_eq!(s.find("/Skel/Left/Hand"), Some(2));
        assert_eq!(s.find("ight/Hand"), None, "a path matches whole names");
        assert_eq!(s.find("Up/Hand"), None);
    }

    #[test]
    fn nodes_that_joints_hang_from_are_joints_and_the_rest_keep_their_role() {
        // scene (null) → armature (null) → hips (joint) → tip (end site); scene → camera → target (null);
        // scene → body (mesh).
        let with_role = |name: &str, parent: Option<usize>, role: NodeRole| Bone { role, ..bone(name, parent) };
        let s = Skeleton::new(vec![
            with_role("scene", None, NodeRole::Helper),
            with_role("armature", Some(0), NodeRole::Helper),
            with_role("hips", Some(1), NodeRole::Joint),
            with_role("tip", Some(2), NodeRole::EndSite),
            with_role("camera", Some(0), NodeRole::Camera),
            with_role("target", Some(4), NodeRole::Helper),
            with_role("body", Some(0), NodeRole::Mesh),
        ])
        .unwrap();
        let roles: Vec<NodeRole> = s.bones().iter().map(|b| b.role).collect();
        use NodeRole::*;
        assert_eq!(roles, [Joint, Joint, Joint, EndSite, Camera, Helper, Mesh]);
        assert_eq!(s.figure(), [true, true, true, true, false, false, false]);
        // Nothing of the figure: every node is shown rather than none.
        let nulls = Skeleton::new(vec![with_role("a", None, Helper), with_role("b", Some(0), Mesh)]).unwrap();
        assert_eq!(nulls.figure(), [true, true]);
    }
}
