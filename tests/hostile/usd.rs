//! The hostile corpus's USD cases: text and binary layers that nest, loop, reach outside their folder, claim more
//! than they hold or name joints with control codes.

use std::path::Path;

use super::corpus::{Case, EVIL, Entry, Expect};

/// A skeleton of `joints` joints, the first the parent of the others, bound to an animation whose translation
/// samples lie at the time codes `codes`, as a text layer.
fn skeleton(joints: usize, codes: &[f64]) -> String {
    let names: Vec<String> =
        (0..joints).map(|j| if j == 0 { "\"j0\"".to_owned() } else { format!("\"j0/j{j}\"") }).collect();
    let rest = vec!["((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 1, 0, 1))"; joints].join(", ");
    let samples: Vec<String> = codes
        .iter()
        .enumerate()
        .map(|(k, code)| format!("{code}: [{}]", vec![format!("(0, {k}, 0)"); joints].join(", ")))
        .collect();
    format!(
        "#usda 1.0\ndef Skeleton \"Rig\" (\n    prepend apiSchemas = [\"SkelBindingAPI\"]\n)\n{{\n    \
         uniform token[] joints = [{names}]\n    uniform matrix4d[] restTransforms = [{rest}]\n    \
         rel skel:animationSource = </Rig/Anim>\n    def SkelAnimation \"Anim\"\n    {{\n        \
         uniform token[] joints = [{names}]\n        float3[] translations.timeSamples = {{ {samples} }}\n    }}\n}}\n",
        names = names.join(", "),
        samples = samples.join(", ")
    )
}

/// `depth` prims, each the only child of the one before.
fn nested(depth: usize) -> Vec<u8> {
    format!("#usda 1.0\n{}{}", "def Xform \"x\" {\n".repeat(depth), "}\n".repeat(depth)).into_bytes()
}

/// A text layer of sublayers, or of a prim referencing `reference`.
fn layer_with(sublayers: &[&str], reference: Option<&str>) -> Vec<u8> {
    let layers: Vec<String> = sublayers.iter().map(|s| format!("@{s}@")).collect();
    let mut text = format!("#usda 1.0\n(\n    subLayers = [{}]\n)\n", layers.join(", "));
    if let Some(reference) = reference {
        text.push_str(&format!("def \"Shot\" (\n    prepend references = {reference}\n)\n{{\n}}\n"));
    }
    text.into_bytes()
}

/// A prim with an attribute of a type USD does not know (`flaot[]`) holding `value`.
fn unknown_type(value: &str) -> Vec<u8> {
    format!("#usda 1.0\ndef Xform \"x\" {{\n    flaot[] weights = {value}\n}}\n").into_bytes()
}

/// Blender's binary export of the stretchy arm cut to `fraction` of its length.
fn cut_crate(fraction: f64) -> Vec<u8> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/blender/stretchy_full.usdc");
    let bytes = std::fs::read(file).expect("the shared assets beside the checkout");
    bytes[..(bytes.len() as f64 * fraction) as usize].to_vec()
}

/// `EVIL` written as a USD string's escapes.
fn escaped_evil() -> String {
    EVIL.chars().map(|c| if c.is_control() { format!("\\x{:02x}", c as u32) } else { c.to_string() }).collect()
}

pub fn cases() -> Vec<Case> {
    let evil_names = skeleton(2, &[0.0, 1.0]).replace("\"j0\"", &format!("\"{}\"", escaped_evil()));
    let evil_names = evil_names.replace("\"j0/j1\"", &format!("\"{}/j1\"", escaped_evil()));
    vec![
        // 1. Memory: samples a trillion time codes apart would be a trillion frames.
        Case::new(
            "usd_far_samples",
            1,
            "a.usda",
            skeleton(3, &[0.0, 1e12]).into_bytes(),
            Expect::Refused("--max-memory"),
        ),
        Case::new("usd_many_joints", 1, "a.usda", skeleton(100_000, &[0.0, 1.0]).into_bytes(), Expect::LoadsOrBudget)
            .huge(),
        // 2. Time: composing a prim costs the cube of its depth; a text parser recurses per bracket.
        Case::new("usd_deep_prims", 2, "a.usda", nested(200), Expect::Refused("nested deeper")),
        Case::new("usd_deep_text", 2, "a.usda", nested(100_000), Expect::Refused("nested deeper")),
        Case::new("usd_sublayer_cycle", 2, "a.usda", layer_with(&["./b.usda"], None), Expect::Loads(""))
            .with("b.usda", Entry::File(layer_with(&["./a.usda"], None))),
        Case::new("usd_self_reference", 2, "a.usda", layer_with(&[], Some("</Shot>")), Expect::Loads("")),
        // 4. Malformed.
        Case::new("usd_cut_crate", 4, "a.usdc", cut_crate(0.5), Expect::Refused("a.usdc")),
        Case::new("usd_crate_header", 4, "a.usdc", cut_crate(0.001), Expect::Refused("a.usdc")),
        Case::new("usda_unclosed", 4, "a.usda", b"#usda 1.0\ndef Xform \"x\" {\n".to_vec(), Expect::Refused("a.usda")),
        // A type USD does not know: its value passed over, with a note; never closed, the layer is refused.
        Case::new("usda_unknown_type", 4, "a.usda", unknown_type("[(1, -inf), [2]]"), Expect::Loads("flaot[]")),
        Case::new("usda_unknown_type_unclosed", 4, "a.usda", unknown_type("[(1, [2]"), Expect::Refused("a.usda")),
        // 5. Control characters in joint names.
        Case::new("usd_names", 5, "a.usda", evil_names.into_bytes(), Expect::Loads("")),
        // 6. Outside the folder (the corpus's `outside/secret.bin`): a reference, a sublayer through a link; a pipe,
        // a device.
        Case::new(
            "usd_reference_out",
            6,
            "a.usda",
            layer_with(&[], Some("@../outside/secret.bin@")),
            Expect::Loads(""),
        ),
        Case::new("usd_sublayer_link_out", 6, "a.usda", layer_with(&["./link.usda"], None), Expect::Loads(""))
            .with("link.usda", Entry::Symlink("../outside/secret.bin".into())),
        Case::new("usd_sublayer_fifo", 6, "a.usda", layer_with(&["./fifo.usda"], None), Expect::Loads(""))
            .with("fifo.usda", Entry::Fifo),
        Case::new("usd_sublayer_dev_zero", 6, "a.usda", layer_with(&["./zero.usda"], None), Expect::Loads(""))
            .with("zero.usda", Entry::Symlink("/dev/zero".into())),
    ]
}
