//! The pose-dump reader on arbitrary bytes (JSON or CSV): it must return a result, never panic, hang or allocate
//! without bound.
#![no_main]

use std::path::Path;

use bonescope::import::{Format, Options, load_bytes_as};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = load_bytes_as(Format::PoseDump, Path::new("/nonexistent/fuzz-input.dump.json"), data, &Options::default());
});
