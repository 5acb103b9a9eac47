//! The USD reader on arbitrary bytes (a text, binary or packaged layer): it must return a result, never panic, hang
//! or allocate without bound.
#![no_main]

use std::path::Path;

use bonescope::import::{Format, Options, load_bytes_as};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Written alone into a folder of its own: any layer it names is not found.
    let _ = load_bytes_as(Format::Usd, Path::new("/nonexistent/fuzz-input.usd"), data, &Options::default());
});
