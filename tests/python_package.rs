//! The Python package (`python/`): its pytest suite (`python/tests`) run with the virtual
//! environment `bash python/setup.sh` makes (`target/pyenv`, or `$SHOAL_PYENV`), after
//! `maturin develop` brings the package up to date with this code (into `target/python`, or
//! `$SHOAL_PY_TARGET`: a target folder of its own, since this test runs while cargo holds the lock
//! of its own). The tests compare with the `shoal` binary cargo built (`SHOAL_BIN`). Under CI
//! (`CI` set) a missing environment is a failure; locally the test skips with a visible message.

mod prereq;

use prereq::{repo, run_tool};

use std::path::{Path, PathBuf};
use std::process::Command;

/// A folder given by the environment variable `var`, else `default` under the repository.
fn folder(var: &str, default: &str) -> PathBuf {
    std::env::var_os(var)
        .map(PathBuf::from)
        .map(|p| if p.is_absolute() { p } else { repo().join(p) })
        .unwrap_or_else(|| repo().join(default))
}

/// The virtual environment's interpreter, when it has what the tests need.
fn python(venv: &Path) -> Result<PathBuf, String> {
    let python = venv.join("bin/python");
    let check = Command::new(&python)
        .args([
            "-c",
            "import maturin, pytest, pyarrow, pandas, dask.distributed",
        ])
        .output();
    match check {
        Ok(o) if o.status.success() => Ok(python),
        Ok(o) => Err(format!(
            "{} lacks a test requirement: {}",
            venv.display(),
            String::from_utf8_lossy(&o.stderr).trim()
        )),
        Err(e) => Err(format!("no Python at {}: {e}", python.display())),
    }
}

#[test]
fn python_package_tests_pass() {
    let venv = folder("SHOAL_PYENV", "target/pyenv");
    let python = match python(&venv) {
        Ok(p) => p,
        Err(why) => {
            let setup = "bash python/setup.sh";
            prereq::may_run(
                "python_package_tests_pass",
                "Python package test",
                &[format!("its environment ({why})")],
                setup,
            );
            return;
        }
    };
    run_tool(
        "maturin develop",
        Command::new(&python)
            .args([
                "-m",
                "maturin",
                "develop",
                "--profile",
                "dev",
                "--manifest-path",
            ])
            .arg(repo().join("python/Cargo.toml"))
            .env("VIRTUAL_ENV", &venv)
            .env(
                "CARGO_TARGET_DIR",
                folder("SHOAL_PY_TARGET", "target/python"),
            ),
    );
    run_tool(
        "pytest python/tests",
        Command::new(&python)
            .args([
                "-m",
                "pytest",
                "python/tests",
                "-q",
                "-p",
                "no:cacheprovider",
            ])
            .env("SHOAL_BIN", env!("CARGO_BIN_EXE_shoal")),
    );
}
