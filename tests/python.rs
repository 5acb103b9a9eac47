//! The Python module (`python/`): its wheel built with maturin, installed into a fresh virtual environment, and
//! `python/tests` run there with pytest against this build's command line, scipy's polar decomposition and, where
//! `BONESCOPE_BLENDER_PYTHON` names Blender's Python, Blender's own pose matrices. `BONESCOPE_PYTHON` names a Python
//! with maturin (`.ci/run` makes one, pinned, in `target/py-venv`); without it the test says it is skipped.

use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn the_wheel_installs_and_says_what_the_command_line_says() {
    let Some(python) = std::env::var_os("BONESCOPE_PYTHON") else {
        eprintln!("skipped: BONESCOPE_PYTHON names no Python with maturin (.ci/run makes target/py-venv)");
        return;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scratch = Path::new(env!("CARGO_TARGET_TMPDIR")).join("python");
    let _ = std::fs::remove_dir_all(&scratch);
    let wheel = build_wheel(&python, root, &scratch.join("wheels"));
    let venv = scratch.join("venv");
    run(Command::new(&python).args(["-m", "venv"]).arg(&venv), "making a fresh virtual environment");
    let venv_python = venv.join("bin/python");
    let requirements = root.join("python/tests/requirements.txt");
    let mut install = Command::new(&venv_python);
    install.args(["-m", "pip", "install", "-q", "-r"]).arg(&requirements).arg(&wheel);
    run(&mut install, "installing the wheel and the tests' requirements");
    let pytest = Command::new(&venv_python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(root.join("python/tests"))
        .env("BONESCOPE_BIN", env!("CARGO_BIN_EXE_bonescope"))
        .env("BONESCOPE_ASSETS", root.join("../shared/assets"))
        .env("BONESCOPE_WHEEL", &wheel)
        .env("BONESCOPE_README", root.join("README.md"))
        .current_dir(&scratch)
        .output()
        .expect("pytest runs");
    let said = format!("{}{}", String::from_utf8_lossy(&pytest.stdout), String::from_utf8_lossy(&pytest.stderr));
    assert!(pytest.status.success(), "pytest python/tests failed:\n{said}");
    println!("{said}");
}

/// The abi3 wheel of `python/`, built with its own lock file into `out` (its build kept in `target/python`).
fn build_wheel(python: &std::ffi::OsStr, root: &Path, out: &Path) -> PathBuf {
    let mut build = Command::new(python);
    build.args(["-m", "maturin", "build", "--release", "--locked", "-m"]).arg(root.join("python/Cargo.toml"));
    build.arg("-o").arg(out).env("CARGO_TARGET_DIR", root.join("target/python"));
    run(&mut build, "building the wheel with maturin");
    let wheels: Vec<PathBuf> = std::fs::read_dir(out).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(
        matches!(wheels.as_slice(), [one] if one.to_string_lossy().contains("-cp39-abi3-")),
        "one abi3 wheel for CPython 3.9 and later: {wheels:?}"
    );
    wheels.into_iter().next().unwrap()
}

/// Runs `command`, failing the test with its output when it fails.
fn run(command: &mut Command, what: &str) {
    let output = command.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        output.status.success(),
        "{what} failed:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}
