#!/usr/bin/env bash
# The Python package's test environment: a virtual environment (target/pyenv, or $SHOAL_PYENV)
# with the test requirements pinned in python/requirements-test.txt, and the package built into
# it by maturin with cargo's dev profile (the tests run small scenarios; a release build of the
# engine takes minutes more) into its own target folder (target/python, or $SHOAL_PY_TARGET), so
# that it never waits on the lock of a `cargo test` build. `cargo test --test python_package`
# runs the tests (python/tests) with it, rebuilding the package first when the code changed.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${SHOAL_PYENV:-target/pyenv}"
if [ ! -x "$venv/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt
VIRTUAL_ENV="$(cd "$venv" && pwd)" CARGO_TARGET_DIR="${SHOAL_PY_TARGET:-target/python}" \
    "$venv/bin/maturin" develop --profile dev --manifest-path python/Cargo.toml
