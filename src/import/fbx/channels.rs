//! A node's local transform straight from its animated channels, where ufbx's evaluation reduces to them.
//!
//! `ufbx_evaluate_transform` looks up each of the node's ten transform properties (translation, rotation, scale,
//! pre- and post-rotation, pivots, offsets, rotation order) among all its properties and the layer's animated ones
//! at every call, and that lookup was most of its time. For a node with nothing between its channels and its
//! transform — no pivot, offset, pre- or post-rotation (none set, none animated), no unit or axis adjustment, no
//! scale helper, no connected property — in a stack of one layer, ufbx's composition
//! `T·Roff·Rp·Rpre·R·Rpost⁻¹·Rp⁻¹·Soff·Sp·S·Sp⁻¹` is just translation, the rotation of the Euler angles, and scale.
//! [`Channels`] finds the three channels once and evaluates them with ufbx's own curve and Euler functions, so the
//! result is ufbx's to the bit (a test checks every such node of every shared file against ufbx); other nodes go
//! through ufbx.

/// The vectors besides the three channels that enter a node's transform (ufbx's `ufbxi_transform_props_all`, less
/// the rotation order, which is read from the node).
const OTHER_VECTORS: [&str; 6] =
    ["PreRotation", "PostRotation", "RotationPivot", "ScalingPivot", "RotationOffset", "ScalingOffset"];

/// One of a node's channels in a stack: animated in its layer, or the node's own value throughout.
enum Channel<'a> {
    Animated(&'a ufbx::AnimValue),
    Still(ufbx::Vec3),
}

impl Channel<'_> {
    fn at(&self, time: f64) -> ufbx::Vec3 {
        match self {
            Channel::Animated(value) => ufbx::evaluate_anim_value_vec3(value, time),
            Channel::Still(value) => *value,
        }
    }
}

/// The translation, Euler rotation and scale channels of a node whose transform is made of them alone.
pub(super) struct Channels<'a> {
    translation: Channel<'a>,
    rotation: Channel<'a>,
    scale: Channel<'a>,
    order: ufbx::RotationOrder,
}

impl<'a> Channels<'a> {
    /// The node's channels in `stack`, when its transform is made of them alone (see the module's documentation).
    pub fn of(node: &'a ufbx::Node, stack: &'a ufbx::AnimStack) -> Option<Self> {
        let layers = &stack.anim.layers;
        let layer = match layers.len() {
            1 => &layers[0],
            _ => return None,
        };
        let props = &node.element.props;
        let adjusted = node.has_adjust_transform || node.adjust_mirror_axis != ufbx::MirrorAxis::None;
        let animated = |name| ufbx::find_anim_prop(layer, &node.element, name).is_some();
        let other = |name| animated(name) || ufbx::find_prop(props, name).is_some_and(|p| !is_zero(vector(p)));
        if node.is_root
            || adjusted
            || !evaluated_from_own_properties(node)
            || animated("RotationOrder")
            || OTHER_VECTORS.into_iter().any(other)
        {
            return None;
        }
        // As ufbx evaluates a property: the layer's curves when the node's property is marked animated, else its value.
        let channel = |name, default: f64| match ufbx::find_prop(props, name) {
            Some(prop) if prop.flags.has_any(ufbx::PropFlags::ANIMATED) => {
                ufbx::find_anim_prop(layer, &node.element, name)
                    .map_or(Channel::Still(vector(prop)), |animated| Channel::Animated(&animated.anim_value))
            }
            Some(prop) => Channel::Still(vector(prop)),
            None => Channel::Still(ufbx::Vec3 { x: default, y: default, z: default }),
        };
        Some(Channels {
            translation: channel("Lcl Translation", 0.0),
            rotation: channel("Lcl Rotation", 0.0),
            scale: channel("Lcl Scaling", 1.0),
            // ufbx applies the rotation order only in the node's rotation space ("RotationActive").
            order: if node.use_rotation_space { node.rotation_order } else { ufbx::RotationOrder::Xyz },
        })
    }

    /// The node's local transform at `time`, as ufbx composes it.
    pub fn at(&self, time: f64) -> ufbx::Transform {
        let (translation, angles, scale) = (self.translation.at(time), self.rotation.at(time), self.scale.at(time));
        let rotation = if is_zero(angles) {
            ufbx::Quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }
        } else {
            ufbx::euler_to_quat(angles, self.order)
        };
        // ufbx scales the zero offset of the (zero) pivots and adds them before the translation: `0·s + 0 + t`, which
        // turns a −0 translation into +0 and a non-finite scale into a non-finite translation, as ufbx does.
        let offset = |s: f64, t: f64| (0.0 * s + 0.0) + t;
        ufbx::Transform {
            translation: ufbx::Vec3 {
                x: offset(scale.x, translation.x),
                y: offset(scale.y, translation.y),
                z: offset(scale.z, translation.z),
            },
            rotation,
            scale,
        }
    }
}

/// Whether `ufbx_evaluate_transform` of `node` depends on time only through the node's own animated properties: none
/// of its properties takes its value from a connection, and no scale helper (whose scale ufbx evaluates too) is
/// involved.
pub(super) fn evaluated_from_own_properties(node: &ufbx::Node) -> bool {
    let connected = node.element.props.props.iter().any(|p| p.flags.has_any(ufbx::PropFlags::CONNECTED));
    let parent_helpers =
        node.parent.as_ref().is_some_and(|p| p.scale_helper.is_some() || p.inherit_scale_node.is_some());
    !connected && !parent_helpers && node.scale_helper.is_none() && !node.is_scale_helper
}

/// A property's value as a vector (ufbx's `value_vec3`, the first three components of `value_vec4`).
fn vector(prop: &ufbx::Prop) -> ufbx::Vec3 {
    let v = prop.value_vec4;
    ufbx::Vec3 { x: v.x, y: v.y, z: v.z }
}

/// Whether every component is zero (ufbx's `ufbxi_is_vec3_zero`).
fn is_zero(v: ufbx::Vec3) -> bool {
    v.x == 0.0 && v.y == 0.0 && v.z == 0.0
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::import::Options;

    /// Times to compare at: every key of the node's channels and 64 times across the stack, beyond both ends too.
    fn times(node: &ufbx::Node, stack: &ufbx::AnimStack) -> Vec<f64> {
        let (begin, end) = (stack.time_begin, stack.time_end);
        let span = (0..=64).map(|k| begin - 0.5 + f64::from(k) / 64.0 * (end - begin + 1.0));
        let props = stack.layers.iter().flat_map(|layer| ufbx::find_anim_props(layer, &node.element));
        let keys = props.flat_map(|p| p.anim_value.curves.iter().flatten().flat_map(|c| c.keyframes.iter()));
        span.chain(keys.map(|k| k.time)).filter(|t| t.is_finite()).collect()
    }

    fn same(a: ufbx::Vec3, b: ufbx::Vec3) -> bool {
        [a.x, a.y, a.z].map(f64::to_bits) == [b.x, b.y, b.z].map(f64::to_bits)
    }

    #[test]
    fn channels_give_ufbx_transforms_to_the_bit() {
        let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets");
        let folders = ["blender", "fbx-proanimationbank", "fbx-ufbx-data", "fbx-ufbx-corpus"];
        let files = folders.iter().flat_map(|f| walkdir::WalkDir::new(assets.join(f))).filter_map(Result::ok);
        let (mut nodes, mut compared) = (0, 0);
        for file in files.filter(|f| f.path().extension().is_some_and(|e| e.eq_ignore_ascii_case("fbx"))) {
            let bytes = std::fs::read(file.path()).expect("a shared file");
            let Ok(scene) = ufbx::load_memory(&bytes, super::super::ufbx_load_opts(&Options::default(), bytes.len()))
            else {
                continue;
            };
            for stack in scene.anim_stacks.iter() {
                for node in scene.nodes.iter() {
                    let Some(channels) = Channels::of(node, stack) else { continue };
                    nodes += 1;
                    for time in times(node, stack) {
                        let (ours, ufbx) = (channels.at(time), ufbx::evaluate_transform(&stack.anim, node, time));
                        let (q, r) = (ours.rotation, ufbx.rotation);
                        let rotation = [q.x, q.y, q.z, q.w].map(f64::to_bits) == [r.x, r.y, r.z, r.w].map(f64::to_bits);
                        assert!(
                            same(ours.translation, ufbx.translation) && rotation && same(ours.scale, ufbx.scale),
                            "{}: node `{}` at {time}: {ours:?} against ufbx's {ufbx:?}",
                            file.path().display(),
                            &*node.element.name
                        );
                        compared += 1;
                    }
                }
            }
        }
        // 995 nodes of stacks at 225,478 times when written: most nodes of most files qualify.
        assert!(nodes > 900 && compared > 200_000, "{nodes} nodes, {compared} times");
        eprintln!("{nodes} nodes compared at {compared} times");
    }
}
