#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image (written by `grader
# package gradescope`; docs/INSTRUCTORS.md). It installs Rust if the image has none (the only step
# that needs the network), points cargo at the vendored crates, builds the grader, and grades the
# solution once so that every dependency of a graded build is compiled before the first student.
# Every path is below $AUTOGRADER_ROOT (default /autograder), so a dry run can unpack elsewhere.
set -euo pipefail
ROOT="${AUTOGRADER_ROOT:-/autograder}"
SRC="$ROOT/source"

# Rust goes under /usr/local, readable by all: graded builds run as a user of their own, which
# cannot read rustup's default under /root (docs/THREAT_MODEL.md, "The user wall"). A toolchain
# already in the image is used where it is (under /root, builds stay root inside the other walls).
export PATH="$PATH:$HOME/.cargo/bin"
if ! command -v cargo > /dev/null && [ ! -x /usr/local/cargo/bin/cargo ]; then
    echo "setup: installing Rust (rustup, minimal profile) under /usr/local"
    apt-get update -q
    apt-get install -y -q --no-install-recommends curl ca-certificates gcc libc6-dev
    export CARGO_HOME=/usr/local/cargo RUSTUP_HOME=/usr/local/rustup
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal --no-modify-path
    chmod -R a+rX "$CARGO_HOME" "$RUSTUP_HOME"
fi
if [ -x /usr/local/cargo/bin/cargo ]; then
    export CARGO_HOME=/usr/local/cargo RUSTUP_HOME=/usr/local/rustup PATH="/usr/local/cargo/bin:$PATH"
fi

# Crates come from vendor/, never from the network; the graded builds (scratch copies of this
# tree, .cargo/ included) read the same configuration.
cat >> "$SRC/raylab/.cargo/config.toml" << CONFIG

# Added by setup.sh: the crates vendored by \`grader package gradescope\`.
[source.crates-io]
replace-with = "vendored"

[source.vendored]
directory = "$SRC/vendor"

[net]
offline = true
CONFIG

cd "$SRC/raylab"
echo "setup: building the grader"
cargo build --release --locked --package raylab-grade --bin grader
target="${CARGO_TARGET_DIR:-$SRC/raylab/target}"
echo "setup: grading the solution once, to compile the graded build's dependencies"
"$target/release/grader" submission . --root . --work "$ROOT/work" > "$ROOT/work-setup.log" 2>&1 || {
    tail -20 "$ROOT/work-setup.log"
    echo "setup: grading the solution failed"
    exit 1
}
echo "setup: ready"
