//! Writes the generated glTF of the benchmarks (`generated_gltf.rs`) into a folder, as `generated_200x6000.glb` and
//! `generated_200x6000.gltf` (the same document with its buffer in base64; the loading benchmarks' rig) and
//! `generated_limbs_200x6000.glb` (every limb squashing: `explain`'s production clip; `generated_limbs_posed_…` the
//! same resting at its first frame, off its bind; `generated_sixth_200x6000.glb`, the sixth bone of every chain
//! squashing, a rig the explanation's speed was not tuned on), for tools outside this crate to load (`benches/compare_assimp.sh` times `assimp info` on them) and the CLI's figures.
//!
//! `cargo run --release --locked --example write_generated_gltf -- FOLDER`

#[path = "generated_gltf.rs"]
mod generated_gltf;

use std::path::PathBuf;

fn main() -> std::io::Result<()> {
    use generated_gltf::Squashes;
    let folder = PathBuf::from(std::env::args_os().nth(1).unwrap_or_else(|| "target".into()));
    std::fs::create_dir_all(&folder)?;
    let stem = Squashes::file_stem;
    let files = [
        (format!("{}.glb", stem(Squashes::Sparse)), generated_gltf::glb(Squashes::Sparse)),
        (format!("{}.gltf", stem(Squashes::Sparse)), generated_gltf::gltf_embedded(Squashes::Sparse)),
        (format!("{}.glb", stem(Squashes::EveryLimb)), generated_gltf::glb(Squashes::EveryLimb)),
        // Resting at the first frame, off its bind: `inspect`'s bind check searches the clip.
        ("generated_limbs_posed_200x6000.glb".to_owned(), generated_gltf::glb_posed(Squashes::EveryLimb)),
        // The sixth bone of every chain squashing: a rig `scan --explain`'s speed was not tuned on.
        (format!("{}.glb", stem(Squashes::SixthOfEveryChain)), generated_gltf::glb(Squashes::SixthOfEveryChain)),
    ];
    for (name, bytes) in files {
        let path = folder.join(name);
        std::fs::write(&path, bytes)?;
        println!("{}", path.display());
    }
    Ok(())
}
