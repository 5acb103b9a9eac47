//! Writes the generated glTF of the benchmarks (`generated_gltf.rs`) into a folder, as `generated_200x6000.glb` and
//! `generated_200x6000.gltf` (the same document with its buffer in base64; the loading benchmarks' rig) and
//! `generated_limbs_200x6000.glb` (every limb squashing: `explain`'s production clip), for tools outside this
//! crate to load (`benches/compare_assimp.sh` times `assimp info` on them) and the CLI's figures.
//!
//! `cargo run --release --locked --example write_generated_gltf -- FOLDER`

#[path = "generated_gltf.rs"]
mod generated_gltf;

use std::path::PathBuf;

fn main() -> std::io::Result<()> {
    let folder = PathBuf::from(std::env::args_os().nth(1).unwrap_or_else(|| "target".into()));
    std::fs::create_dir_all(&folder)?;
    use generated_gltf::Squashes;
    let files = [
        (Squashes::Sparse, "glb", generated_gltf::glb(Squashes::Sparse)),
        (Squashes::Sparse, "gltf", generated_gltf::gltf_embedded(Squashes::Sparse)),
        (Squashes::EveryLimb, "glb", generated_gltf::glb(Squashes::EveryLimb)),
    ];
    for (squashes, extension, bytes) in files {
        let path = folder.join(format!("{}.{extension}", squashes.file_stem()));
        std::fs::write(&path, bytes)?;
        println!("{}", path.display());
    }
    Ok(())
}
