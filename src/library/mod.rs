//! A studio's export library as one scan: which files it covers (folders walked, globs expanded, lists read), in an
//! order that does not depend on the file system or thread timing.

mod inputs;

pub use inputs::{Filter, InputProblem, Inputs, collect};
