//! The fbx parser on arbitrary bytes: it must return a result, never panic, hang or allocate without bound.
#![no_main]

use std::path::Path;

use bonescope::import::{Format, Options, load_bytes_as};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // A path in no real folder: nothing is read from disk (a glTF's external buffers are not found).
    let _ = load_bytes_as(Format::Fbx, Path::new("/nonexistent/fuzz-input.fbx"), data, &Options::default());
});
