//! A studio's export library as one scan: which files it covers (folders walked, globs expanded, lists read), in an
//! order that does not depend on the file system or thread timing, and the reports CI systems read.

mod inputs;
mod junit;
mod merged;
pub mod page;
mod pool;
mod verdict;

pub use inputs::{Filter, Found, InputProblem, Inputs, collect};
pub use junit::{Case, junit, junit_of};
pub use merged::{merge, read_json_lines};
pub use pool::in_order;
pub use verdict::Verdict;
