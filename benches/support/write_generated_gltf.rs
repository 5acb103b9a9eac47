//! Writes the generated glTF of the loading benchmarks (`generated_gltf.rs`) into a folder, as
//! `generated_200x6000.glb` and `generated_200x6000.gltf` (the same document with its buffer in base64), for
//! tools outside this crate to load (`benches/compare_assimp.sh` times `assimp info` on them).
//!
//! `cargo run --release --locked --example write_generated_gltf -- FOLDER`

#[path = "generated_gltf.rs"]
mod generated_gltf;

use std::path::PathBuf;

fn main() -> std::io::Result<()> {
    let folder = PathBuf::from(std::env::args_os().nth(1).unwrap_or_else(|| "target".into()));
    std::fs::create_dir_all(&folder)?;
    for (extension, bytes) in [("glb", generated_gltf::glb()), ("gltf", generated_gltf::gltf_embedded())] {
        let path = folder.join(format!("generated_200x6000.{extension}"));
        std::fs::write(&path, bytes)?;
        println!("{}", path.display());
    }
    Ok(())
}
