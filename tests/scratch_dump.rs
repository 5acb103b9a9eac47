#[test]
fn dump() {
    for f in ["/tmp/m.usda", "/tmp/m.usdc"] {
        let stage = openusd::usd::Stage::open(f).unwrap();
        let prim = stage.prim("/Root/Skeleton");
        eprintln!("{f}: {:?}", prim.custom_data());
        let rig = bonescope::import::load(std::path::Path::new(f)).unwrap();
        for b in 0..3 { eprintln!("  {} {:?} conv={}", rig.skeleton.bone(b).name, rig.skeleton.bone(b).role, rig.skeleton.placement().is_conversion(b)); }
    }
}
