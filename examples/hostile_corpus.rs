//! Writes the hostile corpus of `tests/hostile.rs` into a folder, for measuring it outside the tests
//! (BENCHMARKS.md, "Hostile and huge files"): `cargo run --release --example hostile_corpus -- DIR [--huge]`
//! writes every case (with `--huge` only the huge ones) into `DIR/<case>/`, and a well-formed `DIR/good/walk.glb`
//! to scan beside them; it prints each case's name, category, expectation and main file.

#[path = "../tests/hostile/corpus.rs"]
mod corpus;
#[path = "../tests/hostile/gltf.rs"]
mod gltf;
#[path = "../tests/hostile/usd.rs"]
mod usd;

use std::path::Path;

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let Some(dir) = args.next() else {
        eprintln!("usage: hostile_corpus DIR [--huge]");
        std::process::exit(2);
    };
    let dir = Path::new(&dir);
    let huge_only = args.next().as_deref() == Some("--huge");
    for case in corpus::all().into_iter().filter(|c| c.huge || !huge_only) {
        let file = case.write(dir);
        println!("{}\t{}\t{:?}\t{}", case.name, case.category, case.expect, file.display());
    }
    std::fs::create_dir_all(dir.join("good"))?;
    std::fs::write(dir.join("good/walk.glb"), corpus::good_gltf())
}
