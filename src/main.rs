use std::process::ExitCode;

fn main() -> ExitCode {
    bonescope::cli::main()
}
